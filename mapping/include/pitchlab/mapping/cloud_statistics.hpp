#pragma once
// What a cloud says about its own scale and noise: the quantities registration's `auto` settings
// are derived from (mapping/README.md, "Settings that follow the data").

#include <cstddef>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::mapping {

/// Measured properties of one cloud. Every length scales with the cloud: a scene scaled by s
/// measures s times each length.
struct CloudStatistics {
  std::size_t points = 0;       ///< finite points [1]
  double median_range_m = 0;    ///< median distance of the points from the sensor [m]
  double spacing_m = 0;         ///< median distance of a point to its nearest neighbour [m]
  /// Median over sampled points of the RMS distance of their neighbourhood (the 16 nearest points
  /// within 4 spacings) to its own best-fit plane: the range noise as point-to-plane ICP sees it
  /// (incidence and the range unit's quantization included), robust to edges and corners, which
  /// are a minority of any scan's neighbourhoods [m].
  double noise_m = 0;
  std::size_t noise_samples = 0;  ///< neighbourhoods the noise was measured on [1]
};

/// Measures `cloud` (points [m]) seen from `sensor` (in the cloud's frame). Non-finite points are
/// skipped. A cloud with fewer than 20 finite points gives zeros apart from `points`. Deterministic.
CloudStatistics MeasureCloud(const PointCloud& cloud, const Eigen::Vector3f& sensor);

/// The share of `source`'s points that `T_target_source` puts within `distance_m` of a point of
/// `target`, at full resolution: how well a pose fits as the scans measured it (every point
/// counts once), the figure real_eval and the real-data tests compare a result with a reference
/// pose by. 0 for an empty source. Non-finite points count as not within.
double ShareWithin(const PointCloud& target, const PointCloud& source,
                   const Eigen::Isometry3d& T_target_source, double distance_m);

}  // namespace pitchlab::mapping
