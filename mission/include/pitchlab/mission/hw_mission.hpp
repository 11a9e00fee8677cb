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
//     poll_period_ms base: {device: /dev/ttyS0, baud: 9600}         # + max_v_mps, max_omega_rps,
//                                                    #   sip_timeout_ms, sync_attempts
//   run: {map_size_m: 60}   # the map: a square this wide around the start (without --world)

#include <memory>
#include <optional>
#include <string>

#include "pitchlab/mission/mission.hpp"
#include "pitchlab/hw/hw_rig.hpp"
#include "pitchlab/sensors/sensor_config.hpp"

namespace pitchlab::apps {

enum class Backend { kSim, kHw };

/// The config's `backend` ("sim" or "hw"; absent: sim). Throws std::invalid_argument naming
/// `source` and the value otherwise.
Backend ParseBackend(const std::string& yaml_text, const std::string& source);

/// The backend `pitchlab run` was asked for: `--backend` if given, else the `--config` file's
/// `backend`. Throws CliError on a bad --backend and std::invalid_argument on a bad config.
Backend SelectedBackend(int argc, char** argv);

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
  mission::MissionProbes probes;            ///< steady clock only: no truth, no attitude sensor
};

/// Opens and initialises every device (the steady clock stamps lines, odometry and the mission).
/// Throws std::runtime_error naming the device that failed.
HwBackend StartHwBackend(const hw::HwRigConfig& config);

/// `pitchlab run --backend hw`: the whole run (arguments after "run"); exit code as RunRun.
int RunHwMission(int argc, char** argv);

}  // namespace pitchlab::apps
