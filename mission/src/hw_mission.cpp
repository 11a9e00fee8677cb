#include "pitchlab/mission/hw_mission.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "pitchlab/hw/stop_request.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/sim_mission.hpp"
#include "pitchlab/sensors/number_text.hpp"
#include "pitchlab/worlds/world_metadata.hpp"

namespace pitchlab::mission {
namespace {

// The map without a world: a square this wide around the start, unless run.map_size_m says [m].
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

// What the run folder says about a hardware run besides the mission's result.
RunContext HwContext(const HwMissionSpec& spec, const HwMissionFrame& frame,
                     const RunSettings& settings) {
  RunContext context;
  context.world = frame.world;
  context.world_file = frame.world_file;
  context.robot = spec.config.rig.robot.model == sim::P3Model::kP3AT ? "p3at" : "p3dx";
  context.seed = spec.config.seed;
  context.start = spec.start;
  context.goal = frame.goal;
  context.geodetic_origin = frame.origin;
  context.config_yaml =
      AppConfigToYaml(spec.config) + RunSettingsToYaml(settings) + HwRigConfigToYaml(spec.devices);
  context.planner = MissionPlanner(settings.mission);
  context.layers = settings.mission.layers;
  context.loop_closure = settings.mission.registration.loop_closure.enabled;
  return context;
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

HwMissionFrame FrameHwMission(const HwMissionSpec& spec) {
  HwMissionFrame f;
  const double cell_m = spec.settings.cell_m;
  std::optional<Eigen::Vector2d> default_goal;
  if (!spec.world_file.empty()) {
    f.world = spec.world_name.empty() ? spec.world_file.stem().string() : spec.world_name;
    f.world_file = spec.world_file.string();
    const worlds::WorldMetadata meta = LoadWorldMetadata(spec.world_file);
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
    f.world = spec.world_name.empty() ? "hardware" : spec.world_name;
    const double half = 0.5 * spec.settings.map_size_m.value_or(kDefaultMapSize_m);
    f.map_area = mapping::GridGeometry::Covering(spec.start.head<2>().array() - half,
                                                 spec.start.head<2>().array() + half, cell_m);
  }
  if (spec.goal_m) {
    f.goal = *spec.goal_m;
  } else if (default_goal) {
    f.goal = *default_goal;
  } else {
    throw std::invalid_argument("a hardware run needs a goal (or a world with a default goal)");
  }
  const mapping::GridGeometry& a = f.map_area;
  for (const auto& [name, p] :
       {std::pair{"start", Eigen::Vector2d(spec.start.head<2>())}, std::pair{"goal", f.goal}}) {
    if (p.x() < a.x_min_m || p.x() > a.x_max_m() || p.y() < a.y_min_m || p.y() > a.y_max_m()) {
      throw std::runtime_error(std::string(name) + " (" + NumberText(p.x()) + ", " +
                               NumberText(p.y()) + ") is off the map: it spans x " +
                               NumberText(a.x_min_m) + " .. " + NumberText(a.x_max_m()) +
                               ", y " + NumberText(a.y_min_m) + " .. " +
                               NumberText(a.y_max_m()));
    }
  }
  return f;
}

HwMissionOutcome RunHwMission(const HwMissionSpec& spec, const std::filesystem::path& out,
                              const HwMissionObserver& observer) {
  const auto wall_start = std::chrono::steady_clock::now();
  if (!spec.devices.base) {
    throw std::invalid_argument("backend hw: a mission needs a base (hw.base.device)");
  }
  const HwMissionFrame frame = FrameHwMission(spec);
  RunSettings settings = spec.settings;
  MissionConfig& mission = settings.mission;
  mission.goal_m = frame.goal;
  mission.mount = spec.config.rig.robot.mount;
  mission.beam_divergence_rad = spec.config.rig.lms200.beam_divergence_deg * M_PI / 180.0;
  mission.map_area = frame.map_area;

  HwMissionOutcome run;
  // A stop request from here on: the drivers see it within one read timeout, the mission ends,
  // the drivers' destructors stop the base (zero speed, motors off) and the LMS200 output, and
  // the staging folder is removed uncommitted: no half-written run folder.
  RunFolder folder(out);
  run.folder = folder.final_path();
  if (observer.on_setup) {
    observer.on_setup("opening " + spec.devices.lms200.device + ", " +
                      spec.devices.pitch_unit.device + ", " + spec.devices.base->device);
  }
  HwBackend backend;
  try {
    backend = StartHwBackend(spec.devices);
  } catch (const std::runtime_error&) {
    if (!hw::StopRequested()) throw;
    run.interrupted = "while opening the devices";
    return run;
  }
  backend.probes.interrupted = hw::StopRequested;
  Eigen::Isometry3d T_world_start = Eigen::Isometry3d::Identity();  // base_link on the ground
  T_world_start.translation() << spec.start.x(), spec.start.y(), 0.0;
  T_world_start.rotate(Eigen::AngleAxisd(spec.start.z(), Eigen::Vector3d::UnitZ()));

  MissionObserver mission_observer;
  const std::string world_stem =
      frame.world_file.empty() ? std::string() : spec.world_file.stem().string();
  mission_observer.on_stop = [&](const StopRecord& stop, const MissionResult& so_far) {
    WriteStopOutputs(folder, stop, so_far, frame.origin, world_stem);
  };
  mission_observer.on_progress = observer.on_progress;
  run.result = RunMission(*backend.rig, *backend.rig->base(), T_world_start, mission,
                          backend.probes, mission_observer);
  if (hw::StopRequested()) {
    backend.rig.reset();  // the destructors put the devices in a safe state now
    run.interrupted = "after " + std::to_string(run.result.stops.size()) + " stops";
    return run;
  }

  run.context = HwContext(spec, frame, settings);
  run.context.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  WriteFinalOutputs(folder, run.context, run.result, std::nullopt, nullptr);
  backend.rig.reset();
  if (hw::StopRequested()) {
    run.interrupted = "while writing the run folder";
    return run;
  }
  folder.Commit();
  run.metrics = RunMetrics(run.context, run.result, std::nullopt);
  return run;
}
}  // namespace pitchlab::mission
