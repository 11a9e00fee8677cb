#pragma once
// The field's standard trajectory metrics (issue 20), as the TUM RGB-D benchmark defines them
// (Sturm et al., IROS 2012): absolute trajectory error without alignment (the start is known) and
// after a rigid (SE(3), no scale) Umeyama alignment, relative pose error per stop and per metre
// travelled, and the test that calls a loop closure wrong. Trajectories are T_map_base per stop,
// estimate and truth associated by index.

#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Absolute trajectory error: each estimated pose against the true one.
struct AbsoluteTrajectoryError {
  int poses = 0;                 ///< poses compared [1]
  double rmse_m = 0;             ///< RMS of the position errors [m]
  double max_m = 0;              ///< largest position error [m]
  double rotation_rmse_deg = 0;  ///< RMS of the rotation angles of R_true^T R_est [deg]
  /// The alignment applied to the estimate before comparing (truth ~ T_truth_estimate * estimate):
  /// identity without alignment.
  Eigen::Isometry3d T_truth_estimate = Eigen::Isometry3d::Identity();
};

/// Relative pose error over pairs of poses: E = (T_true_i^-1 T_true_j)^-1 (T_est_i^-1 T_est_j).
struct RelativePoseError {
  int pairs = 0;                 ///< pairs compared [1]
  double translation_rmse = 0;   ///< RMS of |translation of E| [m] (per metre: [m/m])
  double translation_max = 0;    ///< [m] (per metre: [m/m])
  double rotation_rmse_deg = 0;  ///< RMS of the angle of E [deg] (per metre: [deg/m])
  double rotation_max_deg = 0;   ///< [deg] (per metre: [deg/m])
};

/// ATE with no alignment: the estimate's map frame is the truth's (the start is known). Errors:
/// sizes differ, no poses, non-finite poses.
[[nodiscard]] Result<AbsoluteTrajectoryError> AbsoluteTrajectoryErrorUnaligned(
    const std::vector<Eigen::Isometry3d>& estimate, const std::vector<Eigen::Isometry3d>& truth);

/// ATE after the rigid transform that best maps the estimated positions onto the true ones
/// (Eigen::umeyama without scale); the rotation error includes that transform. With all positions
/// on one line the turn about it is arbitrary: the position errors are still the minimum. Errors:
/// as the unaligned one.
[[nodiscard]] Result<AbsoluteTrajectoryError> AbsoluteTrajectoryErrorAligned(
    const std::vector<Eigen::Isometry3d>& estimate, const std::vector<Eigen::Isometry3d>& truth);

/// RPE over consecutive stops (i, i + 1) [m], [deg]. Errors: as ATE, fewer than 2 poses.
[[nodiscard]] Result<RelativePoseError> RelativePoseErrorPerStop(
    const std::vector<Eigen::Isometry3d>& estimate, const std::vector<Eigen::Isometry3d>& truth);

/// RPE per metre: from every stop i to the first stop j whose true path from i (the sum of the
/// straight steps between stops) is at least `segment_m`, |translation of E| and its angle divided
/// by that path length [m/m], [deg/m]. Errors: as ATE, segment_m not finite and > 0, a true path
/// shorter than segment_m.
[[nodiscard]] Result<RelativePoseError> RelativePoseErrorPerMetre(
    const std::vector<Eigen::Isometry3d>& estimate, const std::vector<Eigen::Isometry3d>& truth,
    double segment_m);

/// A loop closure this far from the truth is wrong (issue 20) [m]: one cell of the elevation map,
/// which is what doubles a door jamb and closes a 1 m door.
inline constexpr double kWrongLoopTranslationM = 0.1;
/// ... or turned this far from it [deg]: 1 deg swings a point 6 m away (mid-range of the LMS200's
/// 8 m mm mode) by 0.105 m, one cell again.
inline constexpr double kWrongLoopRotationDeg = 1.0;

/// True when a loop edge's relative pose T_a_b is more than kWrongLoopTranslationM or
/// kWrongLoopRotationDeg off the true one.
bool IsWrongLoopClosure(const Eigen::Isometry3d& T_a_b_estimated,
                        const Eigen::Isometry3d& T_a_b_true);

}  // namespace pitchlab::mapping
