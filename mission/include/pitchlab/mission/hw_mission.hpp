#pragma once
// `backend: hw`: the closed-loop mission over the real devices (DESIGN.md, sim/hw seam). The
// config's `hw` section names the devices; the sensor sections (lms200, pitch_unit, scan, mount)
// shape the scan exactly as in simulation. No ground truth: no scoring, the steady clock, no
// attitude probe.
//
//   backend: hw
//   hw:
//     lms200: {device: /dev/ttyUSB0, baud: 500000}   # + reply_timeout_ms, retries, reconnects,
//                                                    #   continuous
//     pitch_unit: {device: /dev/ttyUSB1, baud: 38400}  # + reply_timeout_ms, retries,
//                                                      #   poll_period_ms
//     base: {device: /dev/ttyS0, baud: 9600}         # + max_v_mps, max_omega_rps,
//                                                    #   sip_timeout_ms, sync_attempts
//   run: {map_size_m: 60}   # the map: a square this wide around the start (without a world)

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pitchlab/hw/hw_rig.hpp"
#include "pitchlab/mission/app_config.hpp"
#include "pitchlab/mission/mission.hpp"
#include "pitchlab/mission/run_config.hpp"
#include "pitchlab/mission/run_outputs.hpp"
#include "pitchlab/sensors/sensor_config.hpp"

namespace pitchlab::mission {

/// Where a run's scans and motion come from: the simulator or the real devices.
enum class Backend { kSim, kHw };

/// The config's `backend` ("sim" or "hw"; absent: sim). Throws std::invalid_argument naming
/// `source` and the value otherwise.
Backend ParseBackend(const std::string& yaml_text, const std::string& source);

/// The `hw` section over `sensors` (variant, range mode, pitch unit, scan pattern, mount). A base
/// is required when `need_base`. Throws std::invalid_argument naming `source`, the field and the
/// value: missing device, unknown key, wrong type, invalid value.
hw::HwRigConfig ParseHwRigConfig(const std::string& yaml_text, const std::string& source,
                                 const sensors::SensorConfig& sensors, bool need_base = true);

/// `backend: hw` and the `hw` section as YAML, readable back by ParseHwRigConfig.
std::string HwRigConfigToYaml(const hw::HwRigConfig& config);

/// The devices of a hardware run and what the mission reads besides them.
struct HwBackend {
  std::unique_ptr<hw::HwRig> rig;  ///< scan source; rig->base() the MobileBase
  MissionProbes probes;            ///< steady clock only: no truth, no attitude sensor
};

/// Opens and initialises every device (the steady clock stamps lines, odometry and the mission).
/// Throws std::runtime_error naming the device that failed.
HwBackend StartHwBackend(const hw::HwRigConfig& config);

/// What a hardware run is made of.
struct HwMissionSpec {
  /// A world whose bounds frame the map (and give the default goal and geodetic origin); empty:
  /// a square of settings.map_size_m (60 m) around the start.
  std::filesystem::path world_file;
  std::string world_name;  ///< how the outputs name the world; empty: the file's stem, "hardware"
  Eigen::Vector3d start{0, 0, 0};         ///< the robot in the map frame: x [m], y [m], yaw [rad]
  std::optional<Eigen::Vector2d> goal_m;  ///< [m]; empty: the world's default goal
  AppConfig config;                       ///< sensor sections (shape the scan), robot model, seed
  RunSettings settings;                   ///< mission, planner, registration
  hw::HwRigConfig devices;                ///< the `hw` section (ParseHwRigConfig)
};

/// Progress of a hardware run, for a person watching; every callback may be empty.
struct HwMissionObserver {
  std::function<void(const std::string& text)> on_setup;     ///< opening the devices
  std::function<void(const std::string& text)> on_progress;  ///< the mission's (mission.hpp)
};

/// A hardware run that ended: finished, or stopped by hw::StopRequested (a signal).
struct HwMissionOutcome {
  MissionResult result;
  RunContext context;
  nlohmann::json metrics;        ///< metrics.json's content (no score: no ground truth)
  std::filesystem::path folder;  ///< the run folder, committed unless interrupted
  /// Set when a stop request ended the run: when it came ("while opening the devices", "after 3
  /// stops", "while writing the run folder"). The devices are safe (base stopped, motors off,
  /// LMS200 output stopped) and no run folder was written.
  std::optional<std::string> interrupted;
};

/// Where a hardware run's map lies and where it goes.
struct HwMissionFrame {
  std::string world, world_file;  ///< as the outputs name them ("hardware", "" without a world)
  Eigen::Vector2d goal{0, 0};     ///< [m]
  mapping::GridGeometry map_area;
  std::optional<mapping::GeodeticOrigin> origin;
};

/// The spec's frame, as RunHwMission takes it: the world's bounds (or the square around the
/// start) and the given or default goal. Throws std::invalid_argument when there is no goal and
/// std::runtime_error when the start or goal is off the map or the world cannot be loaded.
HwMissionFrame FrameHwMission(const HwMissionSpec& spec);

/// Opens the devices, runs the mission on them and writes the run folder `out` (run_outputs.hpp,
/// no truth). Polls hw::StopRequested: the caller installs its signal handlers
/// (hw::InstallStopSignalHandlers). Throws as FrameHwMission, std::runtime_error when `out` exists
/// or a device cannot be opened, std::invalid_argument without a base.
HwMissionOutcome RunHwMission(const HwMissionSpec& spec, const std::filesystem::path& out,
                              const HwMissionObserver& observer = {});

}  // namespace pitchlab::mission
