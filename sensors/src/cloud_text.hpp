#pragma once
// What the text readers (XYZ, 3DTK, ASCII PLY, the PCD header comments) share: splitting a line
// into fields, strict numbers, and a point with its range from the sensor.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::sensors::detail {

/// The fields of `line`, split at runs of spaces, tabs and commas; a trailing '\r' (a file written
/// on Windows) is dropped.
std::vector<std::string_view> SplitFields(std::string_view line);

/// The number `token` spells, all of it ("1.5", "-2e3", "+4"), in the C locale whatever the
/// user's; nullopt for anything else ("1.5m", "x", ""). "nan" and "inf" parse: callers reject them.
std::optional<double> ParseNumber(std::string_view token);

/// True when `line` holds nothing but blanks, or is a comment (its first non-blank is '#').
bool IsBlankOrComment(std::string_view line);

/// A point at `p_m` [m] whose range_m is its distance from `sensor_m`.
ScanPoint MakePoint(const Eigen::Vector3d& p_m, const Eigen::Vector3d& sensor_m);

/// `path` lower-cased after its last '.', with the dot (".PLY" -> ".ply"); "" without one.
std::string LowerExtension(const std::string& path);

}  // namespace pitchlab::sensors::detail
