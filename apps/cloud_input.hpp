#pragma once
// The point clouds commands take as input: any format sensors::ReadCloudFile reads, with the
// sensor origin a user can give on the command line (--sensor-origin x,y,z).

#include <optional>
#include <string>
#include <utility>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::apps {

/// --help text of the --sensor-origin option.
constexpr const char* kSensorOriginHelp =
    "where the sensor stood, in the cloud's own frame [m] (free space is carved along the rays "
    "from it); overrides the file's. Default: the file's, else the frame's origin (with a warning)";

/// --help text of the --as-recorded flag.
constexpr const char* kAsRecordedHelp =
    "keep a nodding scan's lines at the pitch the file recorded. By default each line of a scan "
    "that pitches about its frame's y axis (3DTK's) and crossed the floor within 4 m is turned "
    "onto that floor: a servo's pitch errors (the 3DTK rig's: 0.9 deg RMS) otherwise make the "
    "floor a washboard of steps; see mapping/README.md, Line pitch";

/// Reads `path` with sensors::ReadCloudFile; throws std::runtime_error with the reader's message
/// (naming the file) on failure. `sensor_origin_override` [m, the points' frame] replaces the
/// file's origin; when neither gives one, prints one warning line to stderr and assumes (0,0,0).
/// With `set_lines_right`, a nodding scan's lines are turned onto the floor they crossed
/// (mapping::RectifyLinePitch, in the scan's own frame) and one line says so on stderr;
/// `line_pitch`, when given, receives what was done as JSON (mission::LinePitchJson).
sensors::Scan3D LoadInputCloud(const std::string& path,
                               const std::optional<Eigen::Vector3d>& sensor_origin_override,
                               bool set_lines_right = false,
                               nlohmann::json* line_pitch = nullptr);

/// "0.1,0,0.54" -> (0.1, 0, 0.54) [m]; CliError naming --sensor-origin unless three finite numbers.
Eigen::Vector3d ParseSensorOrigin(const std::string& text);

/// --prior-error's "metres,degrees" when given, else nullopt; CliError unless both are finite and
/// >= 0.
std::optional<std::pair<double, double>> PriorErrorOption(const CliArgs& args);

/// --sensor-origin's value when given (ParseSensorOrigin), else nullopt.
std::optional<Eigen::Vector3d> SensorOriginOption(const CliArgs& args);

}  // namespace pitchlab::apps
