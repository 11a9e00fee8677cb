#include "hw_run.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli_args.hpp"
#include "pitchlab/hw/stop_request.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/sim_mission.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

std::string DefaultOut(std::uint64_t seed) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  return "runs/hw-s" + std::to_string(seed) + "-" + stamp;
}

CliArgs HwRunArgs() {
  CliArgs args("run --backend hw",
               "The closed-loop stop-scan-go mission on the real robot (or its emulators): the\n"
               "same loop as in simulation over the LMS200, pitch-unit and P2OS drivers named in\n"
               "the config's `hw` section. No ground truth: no scoring. Writes the run folder.");
  args.Option("backend", "sim|hw", "hw here (overrides the config's backend)")
      .Option("config", "FILE.yaml", "configuration with the `hw` section (see hw/README.md)")
      .Option("world", "NAME|FILE.xml",
              "a world whose bounds (and default goal, geodetic origin) frame the map")
      .Option("start", "x,y,yaw", "the robot's pose in the map frame: m, m, deg", "0,0,0")
      .Option("goal", "x,y", "goal in metres (default: the --world's default goal)")
      .Option("robot", "p3at|p3dx", "robot model (planner limits), overrides robot.model")
      .Option("seed", "N", "seed of every random source, overrides the config's seed")
      .Option("out", "DIR", "run folder to create (default: runs/hw-s<seed>-<time>)")
      .Flag("json", "print metrics.json on stdout at the end")
      .Flag("quiet", "no progress on stderr");
  return args;
}

// The run's spec from the arguments and the config file: sensor sections, run settings, devices.
mission::HwMissionSpec HwSpec(const CliArgs& args) {
  mission::HwMissionSpec spec;
  spec.config =
      mission::LoadAppConfig(args.Has("config") ? std::optional(args.Get("config")) : std::nullopt);
  if (args.Has("seed")) {
    const std::vector<double> seed = args.GetNumbers("seed", 1);
    if (seed[0] < 0 || seed[0] != std::floor(seed[0]))
      throw CliError("--seed must be an integer >= 0");
    spec.config.seed = static_cast<std::uint64_t>(seed[0]);
  }
  if (args.Has("robot")) spec.config.rig.robot.model = ParseRobotModel(args.Get("robot"));
  const std::string text =
      args.Has("config") ? mission::ReadBinaryFile(args.Get("config")) : std::string();
  spec.settings = mission::ParseRunSettings(text, spec.config.source, spec.config.rig.robot.model);
  spec.devices = mission::ParseHwRigConfig(text, spec.config.source, spec.config.sensors);
  const std::vector<double> s = args.GetNumbers("start", 3);
  spec.start = Eigen::Vector3d(s[0], s[1], s[2] * kDegToRad);
  if (args.Has("world")) {
    spec.world_name = args.Get("world");
    spec.world_file = worlds::ResolveWorld(spec.world_name, WorldsDir());
  }
  if (args.Has("goal")) {
    const std::vector<double> g = args.GetNumbers("goal", 2);
    spec.goal_m = Eigen::Vector2d(g[0], g[1]);
  } else if (spec.world_file.empty() || !mission::LoadWorldMetadata(spec.world_file).default_goal) {
    throw CliError("a hardware run needs --goal x,y (or a --world with a default goal)");
  }
  return spec;
}

}  // namespace

mission::Backend SelectedBackend(int argc, char** argv) {
  std::optional<std::string> backend, config;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    for (auto [name, value] : {std::pair{"--backend", &backend}, std::pair{"--config", &config}}) {
      const std::string prefix = std::string(name) + "=";
      if (arg == name && i + 1 < argc) *value = argv[i + 1];
      if (arg.rfind(prefix, 0) == 0) *value = arg.substr(prefix.size());
    }
  }
  if (backend) {
    if (*backend == "sim") return mission::Backend::kSim;
    if (*backend == "hw") return mission::Backend::kHw;
    throw CliError("--backend '" + *backend + "' is not a backend (sim, hw)");
  }
  if (!config) return mission::Backend::kSim;
  std::string text;
  try {
    text = mission::ReadBinaryFile(*config);
  } catch (const std::exception&) {
    return mission::Backend::kSim;  // the run reports the unreadable file as for any config
  }
  return mission::ParseBackend(text, *config);
}

int RunHwRun(int argc, char** argv) {
  const auto wall_start = std::chrono::steady_clock::now();
  CliArgs args = HwRunArgs();
  if (!args.Parse(argc, argv)) return 0;
  const bool quiet = args.Flagged("quiet");
  const mission::HwMissionSpec spec = HwSpec(args);
  const std::string out = args.Has("out") ? args.Get("out") : DefaultOut(spec.config.seed);

  // Ctrl-C / SIGTERM: the drivers see the flag, the run ends with the devices safe (RunHwMission).
  hw::InstallStopSignalHandlers();
  mission::HwMissionObserver observer;
  if (!quiet) {
    observer.on_setup = [](const std::string& text) {
      std::fprintf(stderr, "run: %s\n", text.c_str());
    };
    observer.on_progress = [wall_start](const std::string& text) {
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      std::fprintf(stderr, "run: %s | wall %.1f s\n", text.c_str(), wall);
    };
  }
  const mission::HwMissionOutcome run = mission::RunHwMission(spec, out, observer);
  if (run.interrupted) {
    std::fprintf(stderr,
                 "run (hw): %s %s: base stopped and motors disabled, LMS200 output stopped; "
                 "no run folder written (%s)\n",
                 hw::StopReason().c_str(), run.interrupted->c_str(), run.folder.string().c_str());
    return hw::StopExitCode();
  }
  if (args.Flagged("json")) std::cout << run.metrics.dump(2) << "\n";
  std::fprintf(stderr, "run (hw): %s: %s after %zu stops, %.1f s; run folder: %s\n",
               run.result.success ? "success" : "FAILED", run.result.reason.c_str(),
               run.result.stops.size(), run.context.wall_time_s, run.folder.string().c_str());
  return run.result.success ? 0 : 1;
}

}  // namespace pitchlab::apps
