#pragma once
// Levelling a map frame by its ground: where nothing measured the attitude (no inclinometer, no
// IMU), the floor the robot stood on at its first scan is the best level there is. A robust plane
// fit of the floor around the sensor gives its normal; the rotation that turns that normal onto z
// levels the frame. It assumes the first scan stood on level ground: on a slope it levels the slope.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Which points may be floor, and how the fit searches.
struct GroundLevelConfig {
  /// Horizontal distance from the sensor of the candidate points [m]. Inside 0.5 m the robot's
  /// own body; beyond 4 m a nodding scan's floor lines lie ~0.4 m apart and thin out (line
  /// spacing on the floor grows with r^2 / sensor height), while walls and furniture grow.
  double min_radius_m = 0.5;
  double max_radius_m = 4.0;
  /// Planes tilted more than this from the frame's z are not the floor: the attitude of a scanner
  /// mounted on a ground robot is off by a few degrees (the 3DTK corridor: 3-5 deg), a wall by 90.
  double max_tilt_rad = 0.3490658504;  // 20 deg
  /// The fraction of the candidates the best hypothesis must fit best (least quantile of squares):
  /// the floor within 4 m is most of what lies below a laser mounted ~0.5 m up; 30 % leaves room
  /// for walls, furniture and legs below the sensor.
  double quantile = 0.3;
  /// The fit's samples are cells of this size, one median height each: the floor counts by its
  /// area, not by the points a nodding scan piles up near the sensor [m].
  double cell_m = 0.1;
  int hypotheses = 400;      ///< random 3-point planes tried (fixed seed: deterministic) [1]
  std::uint32_t seed = 1;    ///< of the hypothesis sampler
  std::size_t min_points = 50;  ///< fewer floor cells: no levelling (an error) [1]
};

/// The floor plane found and the rotation that levels it.
struct GroundLevel {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< floor's up normal, input frame [1]
  double offset_m = 0;       ///< plane normal . p = offset_m [m]
  double tilt_rad = 0;       ///< angle of the normal from the input frame's z: the tilt removed
  double residual_m = 0;     ///< RMS distance of the inlier cells from the plane [m]
  double threshold_m = 0;    ///< inlier distance, 3x the residual (the final iteration's) [m]
  std::size_t inliers = 0;   ///< floor cells of the final fit [1]
  std::size_t candidates = 0;  ///< cells considered [1]
  double sensor_height_m = 0;  ///< the sensor above the floor plane [m]
  /// Rotation (about the input frame's origin) that turns `normal` onto z: the smallest one, so
  /// the heading is kept.
  Eigen::Matrix3d R_level = Eigen::Matrix3d::Identity();
};

/// Fits the floor under and around `sensor_m` among `points_m` (same frame): candidates are the
/// points below the sensor within the radius band; random 3-point planes whose tilt is within
/// max_tilt_rad and below the sensor are scored by the `quantile`-th smallest absolute distance of
/// the candidates (no threshold to guess); the best is refined by total least squares on the
/// points within 3 sigma, sigma the RMS distance of the current inliers (started from the
/// quantile's Gaussian equivalent), until the inliers stop changing. Fails (kFailed) with fewer
/// than min_points candidates or inliers, naming the count.
[[nodiscard]] Result<GroundLevel> FitGroundLevel(const std::vector<Eigen::Vector3f>& points_m,
                                                 const Eigen::Vector3f& sensor_m,
                                                 const GroundLevelConfig& config = {});

}  // namespace pitchlab::mapping
