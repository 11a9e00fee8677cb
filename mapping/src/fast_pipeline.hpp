#pragma once
// Our own implementation of the registration stages (backend "fast"): PCA normals, FPFH,
// correspondence RANSAC with edge prerejection, point-to-plane ICP with Levenberg-Marquardt.

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration_config.hpp"
#include "voxel_hash.hpp"

namespace pitchlab::mapping {

class LazySeenSpace;
using Normals = std::vector<Eigen::Vector3f>;  // NaN where a point has too few neighbours
using FeatureMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Scatter matrix (sum of outer products about their mean) of the points `indices` of `cloud`.
Eigen::Matrix3d Scatter(const PointCloud& cloud, const std::vector<int>& indices);

/// PCA normals over `radius_m`, oriented towards `viewpoint` (the sensor, in the cloud's frame).
Normals EstimateNormals(const PointCloud& cloud, const VoxelHashIndex& index, float radius_m,
                        const Eigen::Vector3f& viewpoint);

/// EstimateNormals' normals of a cloud, each made when first asked for: ICP reads only the target
/// points nearest the source's, on a map often a fraction of them. Holds the cloud and the index
/// by reference. Make is not thread-safe (one registration at a time asks); it makes the missing
/// normals on the machine's cores, each as EstimateNormals makes it, bit for bit.
class LazyNormals {
 public:
  LazyNormals(const PointCloud& cloud, const VoxelHashIndex& index, float radius_m,
              const Eigen::Vector3f& viewpoint);
  /// Makes the normals of `indices` (points of the cloud; negative ones are skipped) not made yet.
  void Make(const std::vector<int>& indices) const;
  /// Point i's normal (NaN where it has too few neighbours); i must have been made.
  const Eigen::Vector3f& operator[](int i) const { return normals_[i]; }
  /// How many normals were made so far.
  std::size_t made() const { return made_count_; }

 private:
  const PointCloud& cloud_;
  const VoxelHashIndex& index_;
  float radius_m_;
  Eigen::Vector3f viewpoint_;
  mutable Normals normals_;
  mutable std::vector<std::uint8_t> made_;
  mutable std::vector<int> missing_;  // Make's buffer
  mutable std::size_t made_count_ = 0;
};

/// FPFH (Rusu 2009, as pcl::FPFHEstimation): one 33-bin row per keypoint (an index into `cloud`,
/// whose points all serve as neighbours); zero rows without normals.
FeatureMatrix ComputeFpfh(const PointCloud& cloud, const Normals& normals,
                          const VoxelHashIndex& index, float radius_m, int max_neighbors,
                          const std::vector<int>& keypoints);

namespace internal {
/// std::atan2(y, x) within 5e-6 rad (measured: 2.4e-6) where max(|x|, |y|) >= 1e-20, with atan2's
/// quadrants and signs (atan2(+-0, -1) = +-pi, atan2(+-0, 1) = +-0). A polynomial without
/// branches: several times cheaper than atan2f.
float ApproxAtan2(float y, float x);
/// FPFH's bin (one of 11 over [-pi, pi]) of std::atan2(y, x), always the bin atan2's own value
/// gives; atan2 is called only for angles within 3e-4 rad of an edge between two bins.
int AngleBinOfAtan2(float y, float x);
}  // namespace internal

struct Correspondence {
  int source, target;
};
/// Mutual nearest neighbours in feature space (rows with all zeros are skipped).
std::vector<Correspondence> MatchFeatures(const FeatureMatrix& source, const FeatureMatrix& target);

/// Region the answer must fall in (the geometric constraint around the odometry prior).
struct PriorRegion {
  Eigen::Isometry3d T_target_source;
  double translation_m, rotation_rad;
  bool Contains(const Eigen::Isometry3d& T) const;
};

/// One pose hypothesis of the sample consensus and the correspondences agreeing with it.
struct SacHypothesis {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  int inliers = 0;
};

struct SacResult {
  bool found = false;
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  int inliers = 0;
  /// The runners-up: distinct poses (farther apart than ICP's capture range) with at least
  /// sac_min_inliers agreeing correspondences, best first, at most sac_hypotheses - 1. In repeated
  /// structure (desk rows, doors along a hall) the true pose is often among them, not the best.
  std::vector<SacHypothesis> alternatives;
};
/// RANSAC over correspondences: 3-point samples, edge-length prerejection, inlier count, refit.
/// Keeps the sac_hypotheses best distinct poses (see SacResult::alternatives).
SacResult SampleConsensus(const PointCloud& source, const PointCloud& target,
                          const std::vector<Correspondence>& corrs,
                          const RegistrationConfig& config,
                          const std::optional<PriorRegion>& region);

/// The target side of ICP: points, normals, a hash for the widest gate and a fine one for the
/// final gates (queries with a radius <= fine_cell_m use `fine`).
struct IcpTarget {
  const PointCloud& points;
  const LazyNormals& normals;
  const VoxelHashIndex& coarse;
  const VoxelHashIndex& fine;
  float fine_cell_m;
  /// What the scan taken at the target frame's origin saw through (registration's free-space
  /// evidence); null: nothing known.
  const LazySeenSpace* seen = nullptr;
  /// What the scan of the source being registered saw through, in the source's frame: the same
  /// evidence the other way (the target's points placed by the inverse pose); null: nothing known.
  const LazySeenSpace* source_seen = nullptr;
};

struct IcpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  int iterations = 0;
  double rmse_m = 0, fitness_m2 = 0, inlier_ratio = 0, degeneracy = 0;
  /// Sum of J J^T over the inlier pairs, J = d(residual)/d(omega, v) = (p x n, n): the
  /// point-to-plane Gauss-Newton Hessian of a perturbation T <- Exp(omega, v) T in the target
  /// frame (rotation first) [unitless / m / m^2 blocks]; divided by the residual's variance it is
  /// the pose's information.
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  int inliers = 0;  ///< inlier pairs the scores were computed over [1]
};

/// Directions the scene constrains weakly (orthonormal unit vectors in the target frame, weakest
/// first).
struct Weakness {
  std::vector<Eigen::Vector3d> translations;   ///< e.g. along a corridor; along and up a wall
  std::vector<Eigen::Vector3d> rotation_axes;  ///< e.g. yaw on an open plane
  /// Of each direction, its eigenvalue / the strongest of its kind [1].
  std::vector<double> translation_ratios, rotation_ratios;
  bool any() const { return !translations.empty() || !rotation_axes.empty(); }
};

/// The gate ICP ends at (PointToPlaneLm): icp_min_distance_m, or the inlier band (inlier_distance_m)
/// when that is narrower [m].
inline double InlierBand(const RegistrationConfig& config) {
  return std::min(config.icp_min_distance_m, config.inlier_distance_m);
}

/// ICP's robust kernel (PointToPlaneLm), both of scale 2 cm at the robot's scale (length_scale).
/// Huber: every pair keeps a constant pull (the scale also at least a fifth of the gate), which
/// finding the basin needs while the pose is still far off. Cauchy: a pair r off pulls as
/// c^2 / r beyond the scale, for the final fit at the inlier band, where a pair several
/// centimetres off lies on another surface (fast_pipeline.cpp).
enum class IcpKernel { kHuber, kCauchy };

/// Point-to-plane ICP, each iteration a Levenberg-Marquardt step on fixed correspondences; stops
/// when the relative error change < epsilon or after icp_max_iterations. The `frozen` directions
/// are kept at the initial guess (solution remapping).
IcpResult PointToPlaneLm(const IcpTarget& target, const PointCloud& source,
                         const Eigen::Isometry3d& init, const RegistrationConfig& config,
                         const Weakness& frozen, IcpKernel kernel = IcpKernel::kHuber);

/// Scores `T` without moving it: inliers within inlier_distance_m, RMS point-to-plane error, and
/// the weakest/strongest eigenvalue ratio of the translation constraint (sum of n n^T).
IcpResult Evaluate(const IcpTarget& target, const PointCloud& source, const Eigen::Isometry3d& T,
                   const RegistrationConfig& config);

/// The translation directions and rotation axes the target constrains weakly at `T`: the
/// eigenvectors of each 3x3 constraint block whose eigenvalue is below `ratio` x the block's
/// largest, at most `max_per_kind` of each, weakest first.
Weakness WeakDirections(const IcpTarget& target, const PointCloud& source,
                        const Eigen::Isometry3d& T, const RegistrationConfig& config, double ratio,
                        int max_per_kind);

/// Evenly spaced indices into a cloud of `size` points, at most `max_points` of them.
std::vector<int> EvenIndices(std::size_t size, int max_points);
/// The points at EvenIndices.
PointCloud EvenSubsample(const PointCloud& cloud, int max_points);

}  // namespace pitchlab::mapping
