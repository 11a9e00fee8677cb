// `pitchlab run`: the arguments of a closed-loop run in a simulated world and its progress lines.
// The run itself (ground truth, mission, scoring, run folder) is mission::RunSimMission.

#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>

#include "cli_args.hpp"
#include "commands.hpp"
#include "hw_run.hpp"
#include "interrupt.hpp"
#include "output_paths.hpp"
#include "pitchlab/mission/sim_mission.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "progress.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

CliArgs RunArgs() {
  CliArgs args("run",
               "Closed-loop stop-scan-go mission in a simulated world: scan, register against\n"
               "the map (odometry as prior), update the elevation map, plan to the goal, drive a\n"
               "prefix of the path, repeat until the goal. Scored against ground truth; writes a\n"
               "run folder with scans, maps, paths, trajectories, metrics.json and report.html.");
  args.Option("world", "NAME|FILE.xml",
              "built-in world (" + BuiltinWorldNames() + ") or any MJCF file", "terrain")
      .Option("start", "x,y,yaw", "start pose: metres, metres, degrees (default: the world's)")
      .Option("goal", "x,y", "goal in metres (default: the world's default goal)")
      .Option("via", "x,y[;x,y...]",
              "waypoints in metres to drive through, in order, before the goal")
      .Flag("round-trip",
            "to the goal (given or the world's default) and back to the start: success is back "
            "within the goal tolerance of the start after reaching the goal")
      .Option("robot", "p3at|p3dx", "robot model, overrides the config's robot.model")
      .Option("seed", "N", "seed of every random source, overrides the config's seed")
      .Option("config", "FILE.yaml", "configuration (see README)")
      .Option("out", "DIR", "run folder to create (default: runs/<world>-s<seed>-<time>)")
      .Option("backend", "sim|hw",
              "sim (default) or hw: the real devices of the config's `hw` "
              "section (`run --backend hw --help`), overrides the config's backend")
      .Option("truth-cache", "DIR",
              "keep the ground truth's elevation map in DIR and reuse it in later runs of the "
              "same world, start and map grid by this same pitchlab executable (bench gives "
              "its runs OUT/truth): the true surface is ray cast once per world, not per seed")
      .Flag("json", "print metrics.json on stdout at the end")
      .Flag("quiet", "no progress on stderr");
  return args;
}

// --via's points, each within the world's bounds (a user's typing mistake: exit 2, before the
// ground truth is computed).
std::vector<Eigen::Vector2d> Waypoints(const CliArgs& args, const worlds::WorldMetadata& meta) {
  std::vector<Eigen::Vector2d> via;
  const worlds::Bounds2d& b = meta.bounds;
  for (const auto& [x, y] : args.GetPoints("via")) {
    if (x < b.x_min_m || x > b.x_max_m || y < b.y_min_m || y > b.y_max_m) {
      char text[200];
      std::snprintf(text, sizeof(text),
                    "--via: waypoint %zu (%g, %g) is off the map: the world spans x %g .. %g, "
                    "y %g .. %g",
                    via.size() + 1, x, y, b.x_min_m, b.x_max_m, b.y_min_m, b.y_max_m);
      throw CliError(text);
    }
    via.emplace_back(x, y);
  }
  return via;
}

std::string DefaultOut(const std::string& world, std::uint64_t seed) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  const std::string name = std::filesystem::path(world).stem().string();
  return "runs/" + name + "-s" + std::to_string(seed) + "-" + stamp;
}

// Progress on stderr as the run goes: set-up steps, then the mission's lines with the simulated
// and the wall clock (the true map is made beside the mission).
mission::SimMissionObserver ProgressLines(std::chrono::steady_clock::time_point wall_start) {
  mission::SimMissionObserver observer;
  observer.on_setup = [](const std::string& text) {
    std::fprintf(stderr, "run: %s\n", text.c_str());
  };
  observer.on_progress = [wall_start](const std::string& text, double sim_s) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    std::fprintf(stderr, "run: %s | sim %.0f s, wall %.1f s (%.0fx real time)\n", text.c_str(),
                 sim_s, wall, wall > 0 ? sim_s / wall : 0.0);
  };
  return observer;
}

}  // namespace

int RunRun(int argc, char** argv) {
  // backend: hw (config or --backend): the same mission over the hardware drivers.
  if (SelectedBackend(argc, argv) == mission::Backend::kHw) return RunHwRun(argc, argv);
  InstallInterruptCleanup("pitchlab run");  // first: before any thread starts
  const auto wall_start = std::chrono::steady_clock::now();
  CliArgs args = RunArgs();
  if (!args.Parse(argc, argv)) return 0;

  mission::SimMissionSpec spec = mission::LoadSimMissionSpec(
      args.Has("config") ? std::optional(args.Get("config")) : std::nullopt,
      args.Has("seed") ? std::optional(args.GetWholeNumber("seed")) : std::nullopt,
      args.Has("robot") ? std::optional(ParseRobotModel(args.Get("robot"))) : std::nullopt);
  const std::string world = args.Get("world");
  const std::string out = args.Has("out") ? args.Get("out") : DefaultOut(world, spec.config.seed);
  CheckNewFolder("out", out);  // before the work, not after a 50-second run
  const std::filesystem::path world_path = worlds::ResolveWorld(world, WorldsDir());
  spec.world_file = world_path;
  spec.world_name = world;
  if (args.Has("start")) {
    const std::vector<double> s = args.GetNumbers("start", 3);
    spec.start = Eigen::Vector3d(s[0], s[1], s[2] * kDegToRad);
  }
  if (args.Has("goal")) {
    const std::vector<double> g = args.GetNumbers("goal", 2);
    spec.goal_m = Eigen::Vector2d(g[0], g[1]);
  } else if (!mission::LoadWorldMetadata(world_path).default_goal) {
    throw CliError("world '" + world + "' names no default goal: give --goal x,y");
  }
  if (args.Has("via")) spec.via_m = Waypoints(args, mission::LoadWorldMetadata(world_path));
  spec.round_trip = args.Flagged("round-trip");
  if (args.Has("truth-cache")) spec.truth_cache_dir = args.Get("truth-cache");

  const mission::SimMissionOutcome run = mission::RunSimMission(
      spec, out, args.Flagged("quiet") ? mission::SimMissionObserver{} : ProgressLines(wall_start));
  if (args.Flagged("json")) std::cout << run.metrics.dump(2) << "\n";
  std::fprintf(stderr, "run: %s: %s after %zu stops, %.0f s simulated in %.1f s; report: %s\n",
               run.result.success ? "success" : "FAILED", run.result.reason.c_str(),
               run.result.stops.size(), run.result.end_s - run.result.start_s,
               run.context.wall_time_s, (run.folder / "report.html").string().c_str());
  // The truth's verdict beside the mission's: the robot cannot know it drove too near a hazard.
  for (const std::string& finding : run.safety) {
    std::fprintf(stderr, "run: unsafe: %s\n", finding.c_str());
  }
  return run.result.success ? 0 : 1;
}

}  // namespace pitchlab::apps
