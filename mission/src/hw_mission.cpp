#include "hw_backend.hpp"

#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "pitchlab/mission/app_config.hpp"
#include "cli_args.hpp"
#include "pitchlab/hw/stop_request.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "pitchlab/worlds/world_metadata.hpp"
#include "pitchlab/mission/run_config.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/run_outputs.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kDefaultMapSize_m = 60.0;
constexpr double kMapMargin_m = 1.0;  // around a world's bounds, as in the simulated run

YAML::Node LoadYaml(const std::string& text, const std::string& source) {
  try {
    return text.empty() ? YAML::Node() : YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": not valid YAML: " + e.what());
  }
}

// One `hw.<device>` map read key by key into typed fields; unknown keys and wrong types throw.
class SectionReader {
 public:
  SectionReader(const YAML::Node& node, std::string source, std::string where)
      : node_(node), source_(std::move(source)), where_(std::move(where)) {
    if (node_ && !node_.IsMap()) throw Error("", "must be a map");
  }
  SectionReader& Int(const std::string& key, int& field) { return Field(key, field); }
  SectionReader& Double(const std::string& key, double& field) { return Field(key, field); }
  SectionReader& Bool(const std::string& key, bool& field) { return Field(key, field); }
  SectionReader& String(const std::string& key, std::string& field) { return Field(key, field); }
  /// Throws on a key no Int/Double/Bool/String call named.
  void Finish() const {
    if (!node_) return;
    for (const auto& kv : node_) {
      const std::string key = kv.first.as<std::string>();
      if (!known_.count(key)) {
        std::string names;
        for (const std::string& k : order_) names += (names.empty() ? "" : ", ") + k;
        throw Error(key, "is not a known setting (" + names + ")");
      }
    }
  }

 private:
  template <typename T>
  SectionReader& Field(const std::string& key, T& field) {
    known_.insert(key);
    order_.push_back(key);
    if (!node_ || !node_[key]) return *this;
    try {
      field = node_[key].as<T>();
    } catch (const YAML::Exception&) {
      throw Error(key, "= '" + YAML::Dump(node_[key]) + "' has the wrong type");
    }
    return *this;
  }
  std::invalid_argument Error(const std::string& key, const std::string& what) const {
    return std::invalid_argument(source_ + ": " + where_ + (key.empty() ? "" : "." + key) + " " +
                                 what);
  }

  YAML::Node node_;
  std::string source_, where_;
  std::set<std::string> known_;
  std::vector<std::string> order_;
};

template <typename Config>
void Validated(const Config& config, const std::string& source) {
  try {
    config.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + ": hw." + e.what());
  }
}

void RequireDevice(const std::string& device, const std::string& source, const std::string& where) {
  if (device.empty()) {
    throw std::invalid_argument(source + ": hw." + where +
                                ".device is required with backend: hw (a serial device path)");
  }
}

std::string DefaultOut(std::uint64_t seed) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  return "runs/hw-s" + std::to_string(seed) + "-" + stamp;
}

worlds::WorldMetadata LoadMetadata(const std::filesystem::path& world) {
  char error[1000] = "";
  mjModel* model = mj_loadXML(world.string().c_str(), nullptr, error, sizeof(error));
  if (model == nullptr)
    throw std::runtime_error("cannot load world '" + world.string() + "': " + error);
  const worlds::WorldMetadata meta = worlds::ReadWorldMetadata(model);
  mj_deleteModel(model);
  return meta;
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

// The mission's goal, map area and geodetic origin from --world / --goal / run.map_size_m.
struct Frame {
  std::string world = "hardware", world_file;
  Eigen::Vector2d goal{0, 0};
  mapping::GridGeometry map_area;
  std::optional<mapping::GeodeticOrigin> origin;
};

Frame MissionFrame(const CliArgs& args, const Eigen::Vector3d& start, double cell_m,
                   std::optional<double> map_size_m) {
  Frame f;
  std::optional<Eigen::Vector2d> default_goal;
  if (args.Has("world")) {
    f.world = args.Get("world");
    f.world_file = worlds::ResolveWorld(f.world, WorldsDir()).string();
    const worlds::WorldMetadata meta = LoadMetadata(f.world_file);
    const worlds::Bounds2d& b = meta.bounds;
    f.map_area = mapping::GridGeometry::Covering(Eigen::Vector2d(b.x_min_m, b.y_min_m),
                                                 Eigen::Vector2d(b.x_max_m, b.y_max_m), cell_m,
                                                 kMapMargin_m);
    if (meta.default_goal)
      default_goal = Eigen::Vector2d(meta.default_goal->x_m, meta.default_goal->y_m);
    if (meta.geodetic_origin) {
      f.origin = mapping::GeodeticOrigin{meta.geodetic_origin->latitude_deg,
                                         meta.geodetic_origin->longitude_deg,
                                         meta.geodetic_origin->height_m};
    }
  } else {
    const double half = 0.5 * map_size_m.value_or(kDefaultMapSize_m);
    f.map_area = mapping::GridGeometry::Covering(start.head<2>().array() - half,
                                                 start.head<2>().array() + half, cell_m);
  }
  if (args.Has("goal")) {
    const std::vector<double> g = args.GetNumbers("goal", 2);
    f.goal = Eigen::Vector2d(g[0], g[1]);
  } else if (default_goal) {
    f.goal = *default_goal;
  } else {
    throw CliError("a hardware run needs --goal x,y (or a --world with a default goal)");
  }
  const mapping::GridGeometry& a = f.map_area;
  for (const auto& [name, p] :
       {std::pair{"start", Eigen::Vector2d(start.head<2>())}, std::pair{"goal", f.goal}}) {
    if (p.x() < a.x_min_m || p.x() > a.x_max_m() || p.y() < a.y_min_m || p.y() > a.y_max_m()) {
      throw std::runtime_error(std::string(name) + " (" + std::to_string(p.x()) + ", " +
                               std::to_string(p.y()) + ") is off the map: it spans x " +
                               std::to_string(a.x_min_m) + " .. " + std::to_string(a.x_max_m()) +
                               ", y " + std::to_string(a.y_min_m) + " .. " +
                               std::to_string(a.y_max_m()));
    }
  }
  return f;
}

}  // namespace

Backend ParseBackend(const std::string& yaml_text, const std::string& source) {
  const YAML::Node root = LoadYaml(yaml_text, source);
  if (!root.IsMap() || !root["backend"]) return Backend::kSim;
  const YAML::Node node = root["backend"];
  const std::string value = node.IsScalar() ? node.as<std::string>() : YAML::Dump(node);
  if (value == "sim") return Backend::kSim;
  if (value == "hw") return Backend::kHw;
  throw std::invalid_argument(source + ": backend = '" + value + "' is not a backend (sim, hw)");
}

Backend SelectedBackend(int argc, char** argv) {
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
    if (*backend == "sim") return Backend::kSim;
    if (*backend == "hw") return Backend::kHw;
    throw CliError("--backend '" + *backend + "' is not a backend (sim, hw)");
  }
  if (!config) return Backend::kSim;
  std::string text;
  try {
    text = mission::ReadBinaryFile(*config);
  } catch (const std::exception&) {
    return Backend::kSim;  // the run reports the unreadable file as for any config
  }
  return ParseBackend(text, *config);
}

hw::HwRigConfig ParseHwRigConfig(const std::string& yaml_text, const std::string& source,
                                 const sensors::SensorConfig& sensors, bool need_base) {
  hw::HwRigConfig c;
  c.lms200.lms = sensors.lms200;
  c.pitch_unit.unit = sensors.pitch_unit;
  c.pattern = sensors.scan;
  c.mount = sensors.mount;
  const YAML::Node root = LoadYaml(yaml_text, source);
  const YAML::Node hw = root.IsMap() ? root["hw"] : YAML::Node();
  if (!hw) throw std::invalid_argument(source + ": backend hw needs an `hw` section (devices)");
  if (!hw.IsMap()) throw std::invalid_argument(source + ": 'hw' must be a map");
  for (const auto& kv : hw) {
    const std::string key = kv.first.as<std::string>();
    if (key != "lms200" && key != "pitch_unit" && key != "base") {
      throw std::invalid_argument(source + ": hw." + key +
                                  " is not a device (lms200, pitch_unit, base)");
    }
  }
  SectionReader(hw["lms200"], source, "hw.lms200")
      .String("device", c.lms200.device)
      .Int("baud", c.lms200.lms.baud)
      .Int("reply_timeout_ms", c.lms200.reply_timeout_ms)
      .Int("retries", c.lms200.retries)
      .Int("reconnects", c.lms200.reconnects)
      .Bool("continuous", c.lms200.continuous)
      .Finish();
  SectionReader(hw["pitch_unit"], source, "hw.pitch_unit")
      .String("device", c.pitch_unit.device)
      .Int("baud", c.pitch_unit.baud)
      .Int("reply_timeout_ms", c.pitch_unit.reply_timeout_ms)
      .Int("retries", c.pitch_unit.retries)
      .Int("poll_period_ms", c.pitch_unit.poll_period_ms)
      .Finish();
  RequireDevice(c.lms200.device, source, "lms200");
  RequireDevice(c.pitch_unit.device, source, "pitch_unit");
  Validated(c.lms200, source);
  Validated(c.pitch_unit, source);
  if (hw["base"] || need_base) {
    hw::P2osDriverConfig base;
    SectionReader(hw["base"], source, "hw.base")
        .String("device", base.device)
        .Int("baud", base.baud)
        .Double("max_v_mps", base.max_v_mps)
        .Double("max_omega_rps", base.max_omega_rps)
        .Int("sip_timeout_ms", base.sip_timeout_ms)
        .Int("sync_attempts", base.sync_attempts)
        .Finish();
    RequireDevice(base.device, source, "base");
    Validated(base, source);
    c.base = base;
  }
  return c;
}

std::string HwRigConfigToYaml(const hw::HwRigConfig& c) {
  std::ostringstream os;
  os.precision(17);
  os << "backend: hw\nhw:\n"
     << "  lms200:\n"
     << "    device: " << YAML::Dump(YAML::Node(c.lms200.device)) << "\n"
     << "    baud: " << c.lms200.lms.baud << "\n"
     << "    reply_timeout_ms: " << c.lms200.reply_timeout_ms << "\n"
     << "    retries: " << c.lms200.retries << "\n"
     << "    reconnects: " << c.lms200.reconnects << "\n"
     << "    continuous: " << (c.lms200.continuous ? "true" : "false") << "\n"
     << "  pitch_unit:\n"
     << "    device: " << YAML::Dump(YAML::Node(c.pitch_unit.device)) << "\n"
     << "    baud: " << c.pitch_unit.baud << "\n"
     << "    reply_timeout_ms: " << c.pitch_unit.reply_timeout_ms << "\n"
     << "    retries: " << c.pitch_unit.retries << "\n"
     << "    poll_period_ms: " << c.pitch_unit.poll_period_ms << "\n";
  if (c.base) {
    os << "  base:\n"
       << "    device: " << YAML::Dump(YAML::Node(c.base->device)) << "\n"
       << "    baud: " << c.base->baud << "\n"
       << "    max_v_mps: " << c.base->max_v_mps << "\n"
       << "    max_omega_rps: " << c.base->max_omega_rps << "\n"
       << "    sip_timeout_ms: " << c.base->sip_timeout_ms << "\n"
       << "    sync_attempts: " << c.base->sync_attempts << "\n";
  }
  return os.str();
}

HwBackend StartHwBackend(const hw::HwRigConfig& config) {
  // One steady clock for line stamps, odometry and the mission (DESIGN.md: one stamp clock).
  const auto t0 = std::chrono::steady_clock::now();
  hw::ClockFn clock = [t0] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  HwBackend backend;
  backend.rig = std::make_unique<hw::HwRig>(config, clock);
  if (backend.rig->base() == nullptr) {
    throw std::invalid_argument("backend hw: a mission needs a base (hw.base.device)");
  }
  backend.probes.now_s = clock;
  return backend;
}

int RunHwMission(int argc, char** argv) {
  const auto wall_start = std::chrono::steady_clock::now();
  CliArgs args = HwRunArgs();
  if (!args.Parse(argc, argv)) return 0;
  const bool quiet = args.Flagged("quiet");

  mission::AppConfig config =
      mission::LoadAppConfig(args.Has("config") ? std::optional(args.Get("config")) : std::nullopt);
  if (args.Has("seed")) {
    const std::vector<double> seed = args.GetNumbers("seed", 1);
    if (seed[0] < 0 || seed[0] != std::floor(seed[0]))
      throw CliError("--seed must be an integer >= 0");
    config.seed = static_cast<std::uint64_t>(seed[0]);
  }
  if (args.Has("robot")) config.rig.robot.model = ParseRobotModel(args.Get("robot"));
  const std::string config_text =
      args.Has("config") ? mission::ReadBinaryFile(args.Get("config")) : std::string();
  mission::RunSettings settings = mission::ParseRunSettings(config_text, config.source, config.rig.robot.model);
  const hw::HwRigConfig hw_config = ParseHwRigConfig(config_text, config.source, config.sensors);

  const std::vector<double> s = args.GetNumbers("start", 3);
  const Eigen::Vector3d start(s[0], s[1], s[2] * kDegToRad);
  const Frame frame = MissionFrame(args, start, settings.cell_m, settings.map_size_m);
  mission::MissionConfig& mission = settings.mission;
  mission.goal_m = frame.goal;
  mission.mount = config.rig.robot.mount;
  mission.map_area = frame.map_area;

  mission::RunFolder folder(args.Has("out") ? args.Get("out") : DefaultOut(config.seed));
  // Ctrl-C / SIGTERM from here on: the drivers see the flag within one read timeout, the mission
  // ends, the drivers' destructors stop the base (zero speed, motors off) and the LMS200 output,
  // and the staging folder is removed uncommitted: no half-written run folder.
  hw::InstallStopSignalHandlers();
  const auto interrupted = [&](const std::string& during) {
    std::fprintf(stderr,
                 "run (hw): %s %s: base stopped and motors disabled, LMS200 output stopped; "
                 "no run folder written (%s)\n",
                 hw::StopReason().c_str(), during.c_str(), folder.final_path().string().c_str());
    return hw::StopExitCode();
  };
  if (!quiet)
    std::fprintf(stderr, "run: opening %s, %s, %s\n", hw_config.lms200.device.c_str(),
                 hw_config.pitch_unit.device.c_str(), hw_config.base->device.c_str());
  HwBackend backend;
  try {
    backend = StartHwBackend(hw_config);
  } catch (const std::runtime_error&) {
    if (hw::StopRequested()) return interrupted("while opening the devices");
    throw;
  }
  backend.probes.interrupted = hw::StopRequested;
  Eigen::Isometry3d T_world_start = Eigen::Isometry3d::Identity();  // base_link on the ground
  T_world_start.translation() << start.x(), start.y(), 0.0;
  T_world_start.rotate(Eigen::AngleAxisd(start.z(), Eigen::Vector3d::UnitZ()));

  mission::MissionObserver observer;
  observer.on_stop = [&](const mission::StopRecord& stop, const mission::MissionResult& so_far) {
    mission::WriteStopOutputs(folder, stop, so_far, frame.origin,
                     frame.world_file.empty()
                         ? std::string()
                         : std::filesystem::path(frame.world_file).stem().string());
  };
  observer.on_progress = [&](const std::string& text) {
    if (quiet) return;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    std::fprintf(stderr, "run: %s | wall %.1f s\n", text.c_str(), wall);
  };
  const mission::MissionResult result = mission::RunMission(*backend.rig, *backend.rig->base(), T_world_start,
                                          mission, backend.probes, observer);
  if (hw::StopRequested()) {
    backend.rig.reset();  // the destructors put the devices in a safe state now
    return interrupted("after " + std::to_string(result.stops.size()) + " stops");
  }

  mission::RunContext context;
  context.world = frame.world;
  context.world_file = frame.world_file;
  context.robot = config.rig.robot.model == sim::P3Model::kP3AT ? "p3at" : "p3dx";
  context.seed = config.seed;
  context.start = start;
  context.goal = frame.goal;
  context.geodetic_origin = frame.origin;
  context.config_yaml =
      mission::AppConfigToYaml(config) + mission::RunSettingsToYaml(settings) + HwRigConfigToYaml(hw_config);
  context.planner = mission::MissionPlanner(mission);
  context.layers = mission.layers;
  context.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  mission::WriteFinalOutputs(folder, context, result, std::nullopt, nullptr, std::nullopt);
  backend.rig.reset();
  if (hw::StopRequested()) return interrupted("while writing the run folder");
  folder.Commit();

  const nlohmann::json metrics = mission::RunMetrics(context, result, std::nullopt);
  if (args.Flagged("json")) std::cout << metrics.dump(2) << "\n";
  std::fprintf(stderr, "run (hw): %s: %s after %zu stops, %.1f s; run folder: %s\n",
               result.success ? "success" : "FAILED", result.reason.c_str(), result.stops.size(),
               context.wall_time_s, folder.final_path().string().c_str());
  return result.success ? 0 : 1;
}

}  // namespace pitchlab::apps
