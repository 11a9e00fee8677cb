#pragma once
// MapBuilder's loop closure (issue 20): the pose graph of the merged scans, each scan's copy kept
// for loop registration, and the loop search after each merge: candidates from the graph,
// registration against the candidate's own scan with the graph's relative pose as the guess
// (bounded by the graph's uncertainty), and the graph's chi-square test on the edge.

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mapping/map_builder.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/pose_graph.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// The weight of a registration's edge: the inverse of its covariance (the information where the
/// fit determined every direction, the guess's bound along a direction kept at it) times
/// `scale`. Error: a covariance that is not symmetric positive definite (no ICP result scored).
[[nodiscard]] Result<Matrix6d> EdgeInformation(const RegistrationResult& registration,
                                               double scale);

/// The settings a loop registration runs with: `sequential`'s, but no direction the scans leave
/// free is kept at the guess (carry_max_m = carry_max_deg = 0): the guess is the graph's own
/// relative pose, and a loop edge must measure it independently; and min_inlier_ratio no lower
/// than the pairwise default (loop_closer.cpp says why).
RegistrationConfig LoopRegistrationConfig(RegistrationConfig sequential);

/// Whether a loop registration that took its guess's path (no features confirmed it) found a
/// minimum of the fit, not the guess: ICP started from `found`'s pose moved a step each way along
/// the direction the fit holds weakest (the step: `bound_m` and `bound_deg`, the graph's bounds
/// on the relative pose, at least an ICP voxel and a degree) must succeed and end within half a
/// step of it. ICP from the graph's guess along a weakly held direction (a corridor's axis seen
/// over a few door jambs) barely moves: its pose repeats the graph's, the chi-square test finds
/// nothing to object to, and the edge locks the graph's error in (office round trip seed 10: a
/// loop 0.13 m off along the corridor, chi-square rise 2.4). Errors: Register's.
[[nodiscard]] Result<bool> SameMinimumFromAside(const PointCloud& target, const PointCloud& source,
                                                const RegistrationPrior& prior,
                                                const RegistrationConfig& config,
                                                const RegistrationResult& found, double bound_m,
                                                double bound_deg);

class LoopCloser {
 public:
  /// `config` validated by the caller; `sensor_base`: where the laser sits in each base_link.
  LoopCloser(const LoopClosureConfig& config, const RegistrationConfig& registration,
             const std::optional<Eigen::Vector3f>& sensor_base);

  /// The first merged scan: node 0, the map's origin. Error: not the first.
  [[nodiscard]] Result<void> AddFirst(const PointCloud& cloud_base, std::size_t scan_index);
  /// A merged scan: its node at `T_map_base`, its sequential edge from the previous node
  /// (`sequential` registered it), then the loop search; fills step's loop fields. Errors: the
  /// registration's covariance unusable, the graph failing.
  [[nodiscard]] Result<void> AddMerged(const PointCloud& cloud_base, std::size_t scan_index,
                                       const Eigen::Isometry3d& T_map_base,
                                       const RegistrationResult& sequential, MergeStep& step);

  /// Every node's pose, in merge order.
  std::vector<Eigen::Isometry3d> Poses() const { return graph_.Poses(); }
  const LoopClosureCounts& counts() const { return counts_; }
  const std::vector<LoopClosure>& accepted() const { return accepted_; }

 private:
  // How far the graph's relative heading between nodes a < b may be off [deg]: the rotation
  // variances of the sequential edges between them add (loops only shrink it).
  double RotationBoundDeg(int a, int b) const;
  bool Overlaps(int node, const LoopCandidate& candidate) const;
  [[nodiscard]] Result<void> TryLoop(int node, const LoopCandidate& candidate, MergeStep& step);

  LoopClosureConfig config_;
  RegistrationConfig registration_;
  std::optional<Eigen::Vector3f> sensor_base_;
  PoseGraph graph_;
  std::vector<PointCloud> scans_;          // per node: the scan at scan_voxel_m, in base_link
  std::vector<std::size_t> scan_indices_;  // per node: its position in the sequence
  std::vector<double> rotation_variance_;  // per node: its sequential edge's, largest [rad^2]
  LoopClosureCounts counts_;
  std::vector<LoopClosure> accepted_;
};

}  // namespace pitchlab::mapping
