#pragma once
// The run configuration a user gives with --config FILE: one YAML document whose sections belong
// to the modules (lms200, pitch_unit, scan, mount: sensors; robot, odometry, imu: sim), plus the
// seed.

#include <cstdint>
#include <optional>
#include <string>

#include "pitchlab/sensors/sensor_config.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mission {

struct AppConfig {
  std::uint64_t seed = 1;  ///< one seed for every random source of a run
  sensors::SensorConfig sensors;
  sim::SimRigConfig rig;                     ///< assembled from the above
  std::string source = "built-in defaults";  ///< file it came from
};

/// Loads `path` (nullopt: the defaults). Throws std::invalid_argument naming the file, field and
/// value: unreadable file, bad YAML, unknown section or key, invalid value.
AppConfig LoadAppConfig(const std::optional<std::string>& path);

/// The configuration actually used, as YAML that LoadAppConfig reads back.
std::string AppConfigToYaml(const AppConfig& config);

}  // namespace pitchlab::mission
