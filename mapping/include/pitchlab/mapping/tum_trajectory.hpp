#pragma once
// Trajectories in the TUM RGB-D benchmark's text format, so users can run their usual
// trajectory-evaluation tools (evo, the TUM scripts) on ours: one pose per line,
//   timestamp tx ty tz qx qy qz qw
// stamp [s], position [m], unit quaternion (Hamilton, scalar last); lines starting with '#' are
// comments.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// One pose of a trajectory with its time.
struct StampedPose {
  double stamp_s = 0;                                            ///< [s]
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  ///< [m]
};

/// The text of a TUM file: a '#' header naming the columns, then one line per pose; every number
/// is written with the fewest digits that read back to the same double, quaternions with qw >= 0.
/// Errors: a non-finite or non-rigid pose, stamps not strictly increasing (an evaluator associates
/// poses by time).
[[nodiscard]] Result<std::string> FormatTumTrajectory(const std::vector<StampedPose>& poses);

/// Parses TUM text (`source` names it in errors, e.g. the file's path). Errors name the line: not
/// 8 numbers, a non-finite number, a quaternion whose norm is more than 1e-3 from 1 (others are
/// normalised), a stamp not after the previous line's.
[[nodiscard]] Result<std::vector<StampedPose>> ParseTumTrajectory(const std::string& text,
                                                                  const std::string& source);

/// Writes FormatTumTrajectory's text to `path` atomically (a temporary beside it, then renamed):
/// on any error the file is left as it was.
[[nodiscard]] Result<void> WriteTumTrajectory(const std::string& path,
                                              const std::vector<StampedPose>& poses);

/// Reads and parses the file at `path`. Errors: unreadable, or as ParseTumTrajectory.
[[nodiscard]] Result<std::vector<StampedPose>> ReadTumTrajectory(const std::string& path);

}  // namespace pitchlab::mapping
