#pragma once
// The point clouds commands take as input: any format sensors::ReadCloudFile reads, with the
// sensor origin a user can give on the command line (--sensor-origin x,y,z).

#include <optional>
#include <string>
#include <utility>

#include <Eigen/Core>

#include "cli_args.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::apps {

/// --help text of the --sensor-origin option.
constexpr const char* kSensorOriginHelp =
    "where the sensor stood, in the cloud's own frame [m] (free space is carved along the rays "
    "from it); overrides the file's. Default: the file's, else the frame's origin (with a warning)";

/// Reads `path` with sensors::ReadCloudFile; throws std::runtime_error with the reader's message
/// (naming the file) on failure. `sensor_origin_override` [m, the points' frame] replaces the
/// file's origin; when neither gives one, prints one warning line to stderr and assumes (0,0,0).
sensors::Scan3D LoadInputCloud(const std::string& path,
                               const std::optional<Eigen::Vector3d>& sensor_origin_override);

/// "0.1,0,0.54" -> (0.1, 0, 0.54) [m]; CliError naming --sensor-origin unless three finite numbers.
Eigen::Vector3d ParseSensorOrigin(const std::string& text);

/// --prior-error's "metres,degrees" when given, else nullopt; CliError unless both are finite and
/// >= 0.
std::optional<std::pair<double, double>> PriorErrorOption(const CliArgs& args);

/// --sensor-origin's value when given (ParseSensorOrigin), else nullopt.
std::optional<Eigen::Vector3d> SensorOriginOption(const CliArgs& args);

}  // namespace pitchlab::apps
