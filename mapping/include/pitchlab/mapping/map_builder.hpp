#pragma once
// Incremental merging of a scan sequence into one map cloud (DESIGN.md pipeline step 3): each new
// scan is registered against the map around the last pose (scan-to-map), merged only when the
// registration succeeded, and the map is kept voxel-downsampled. With loop closure on (issue 20)
// the merged scans are also nodes of a pose graph: after each merge, earlier scans the robot may
// be back at are registered against the new one, a loop edge is kept only when the graph agrees
// with it (a chi-square test), and the trajectory and the map follow the optimised poses.

#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/pose_graph.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mapping/scan_voxel_map.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

class LoopCloser;  // mapping/src/loop_closer.hpp

/// Loop closure in MapBuilder. Off by default: MapBuilder then merges exactly as without it.
struct LoopClosureConfig {
  bool enabled = false;
  /// Which earlier scans are registered against a new one (PoseGraph::LoopCandidates): within
  /// 8 m (the LMS200's mm-mode range) given the graph's uncertainty at 99.9 %, and at least
  /// `min_travel_m` back along the trajectory (see kLoopMinTravelM).
  LoopCandidateQuery candidates{8.0, 0.999, kLoopMinTravelM};
  /// Registrations per merged scan [1], >= 1: the nearest candidates whose scans, at the graph's
  /// relative pose, share at least the registration's min_inlier_ratio of the new scan's points
  /// (voxels of twice the ICP voxel plus the graph's bound: below that share the registration's
  /// inlier test refuses even the true pose). Each costs a pairwise registration (0.1-0.3 s CPU,
  /// mapping/README.md); 2 leaves a second chance where the nearest one fails.
  int max_registrations = 2;
  /// Voxel edge of the copy of each merged scan kept for loop registration [m], > 0. Beams 0.5 deg
  /// apart and lines 0.45 deg apart are more than 2 cm apart beyond ~2.5 m, so 2 cm thins only the
  /// dense near field, where a nodding scan piles its points, and keeps the noise the
  /// registration measures (cloud_statistics.hpp) in every patch beyond.
  double scan_voxel_m = 0.02;
  /// Factor on each edge's information (the inverse of the registration's covariance) [1], in
  /// (0, 1]. The point-to-plane information assumes independent residuals; they are not (a
  /// scan's calibration bends it as a whole, neighbouring voxels share errors), so it is
  /// over-confident. See kEdgeInformationScale for the measurement behind the default.
  double information_scale = kEdgeInformationScale;
  PoseGraphConfig graph;  ///< kernel and acceptance gate of the loop edges

  /// Earlier scans fewer metres back along the estimated trajectory are no loop candidates [m].
  /// Their points dominate the local map the new scan was just registered against (scan-to-map),
  /// so a loop edge to them would count that registration's information twice and the graph
  /// would over-trust it. 3 m: two to three stops of the simulated routes (1-1.5 m apart).
  static constexpr double kLoopMinTravelM = 3.0;
  /// Measured by benchmarks/loop_closure_eval (office and urban routes back to their start,
  /// the default SimRig): the true error e of each edge scored under its own unscaled
  /// information, chi2 = e^T C^-1 e, which averages 6 (its degrees of freedom) when C is right.
  /// Sequential (scan-to-map) edges without loop closure: urban mean 61, median 43 (12 edges);
  /// office mean 112, median 24 (18 edges, one at 1340); loop edges: urban mean 15, office 48
  /// (9 each). The information is over-confident by 10-20x
  /// on the sequential edges, 2.5-8x on the loop edges: 0.1 takes the sequential ones to their
  /// mean where they are most regular (urban) and leaves the loop edges looser than the truth,
  /// so a true loop is not refused for the registrations' over-confidence. Real scans are
  /// worse (mapping/README.md: the corridor pair's information claims 0.04 deg where the fit is
  /// 0.8 deg off, ~400x in chi2): measure them with loop_closure_eval's method before trusting
  /// this default there.
  static constexpr double kEdgeInformationScale = 0.1;

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// Settings of MapBuilder.
struct MapConfig {
  double map_voxel_m = 0.1;          ///< map cloud voxel edge (centroid per voxel) [m]
  double local_map_radius_m = 40.0;  ///< map points this close to the last pose are the target [m]
  /// Pairwise settings used for scan-to-map. A length_scale left auto is resolved once, by the
  /// first scan, for the whole map (one map, one scale: a later scan alone can read a decade off).
  RegistrationConfig registration;
  /// Where the laser (its mirror at zero pitch) sits in each scan's base_link [m]: normals face it
  /// and free space lies between it and the returns. Unset: at base_link's origin.
  std::optional<Eigen::Vector3f> sensor_base;
  LoopClosureConfig loop_closure;  ///< off by default

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// One pose of the estimated trajectory.
struct TrajectoryPose {
  std::size_t scan_index = 0;  ///< position of the scan in the sequence given to Add
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
};

/// One loop closure tried after a merge: the new scan registered against an earlier one.
struct LoopAttempt {
  std::size_t target_scan_index = 0;  ///< the earlier scan (its position in the sequence)
  LoopCandidate candidate;            ///< its node, distance and the graph's uncertainty
  RegistrationResult registration;    ///< T_target_source: the new scan in the earlier one's frame
  bool tested = false;                ///< the registration succeeded, so the graph's test ran
  LoopDecision decision;              ///< the test's verdict (when tested)
};

/// A loop edge the pose graph accepted.
struct LoopClosure {
  std::size_t from_scan_index = 0;  ///< the earlier scan (the registration's target)
  std::size_t to_scan_index = 0;    ///< the scan that came back (its source)
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  ///< measured
  double chi2_increase = 0;                                     ///< LoopDecision::chi2_increase [1]
};

/// Loop closures over the whole sequence.
struct LoopClosureCounts {
  std::size_t registered = 0;           ///< candidates registered against a new scan
  std::size_t registration_failed = 0;  ///< ... whose registration did not succeed
  std::size_t accepted = 0;             ///< loop edges the graph's test accepted
  std::size_t rejected = 0;             ///< ... and refused
};

/// What Add did with one scan.
struct MergeStep {
  std::size_t scan_index = 0;
  bool merged = false;              ///< false: registration failed, map unchanged
  RegistrationResult registration;  ///< T_target_source is T_last_base (target = last pose)
  /// Estimate (when merged), as it stood right after the merge: a loop closed in this step may
  /// have moved it since (trajectory() has the latest).
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
  std::vector<LoopAttempt> loop_attempts;  ///< loop closure on: the candidates registered
  std::size_t loops_accepted = 0;          ///< of those, accepted by the graph's test
  std::size_t loops_rejected = 0;          ///< ... and refused by it
  bool reposed = false;  ///< the optimisation moved earlier poses: trajectory and map follow
};

/// Builds the map in the frame `map` = base_link of the first scan.
class MapBuilder {
 public:
  explicit MapBuilder(const MapConfig& config);  ///< validates; throws std::invalid_argument

  /// Registers `cloud_base` (points in its base_link [m]) against the map and merges it when the
  /// registration succeeds. `odometry_T_map_base`: odometry's guess of its pose, when known;
  /// `odometry_uncertainty`: how far that guess may be off the motion since the last merged scan
  /// (see RegistrationPrior); `measured_tilt`: that guess's roll and pitch were measured, up
  /// given in `map` (see RegistrationPrior::tilt). Errors: bad input (see Register), the pose
  /// graph failing (loop closure on; the scan is merged all the same). A failed registration is
  /// a step with merged == false.
  [[nodiscard]] Result<MergeStep> Add(
      const PointCloud& cloud_base,
      const std::optional<Eigen::Isometry3d>& odometry_T_map_base = {},
      const std::optional<GuessUncertainty>& odometry_uncertainty = {},
      const std::optional<MeasuredTilt>& measured_tilt = {});

  /// Makes the next Add's registration target now, the map around the last merged pose, and
  /// what registration derives from it alone (RegistrationTarget::Prepare), its loops on the
  /// calling thread alone: for a caller with a core to spare before its next scan (a robot
  /// driving to its next stop). Add uses it while the map stays as it is, and gives the same
  /// result without it. Nothing to do before the first scan. No other call on this builder may
  /// run meanwhile.
  void PrepareNext();

  /// The merged map in `map` [m], one centroid per voxel.
  PointCloud MapCloud() const;
  /// T_map_base of every merged scan, in order (optimised, with loop closure on).
  const std::vector<TrajectoryPose>& trajectory() const { return trajectory_; }
  std::size_t scans_seen() const { return scans_seen_; }
  /// Loop closures tried, accepted and refused so far (zero with loop closure off).
  LoopClosureCounts loop_closures() const;
  /// The loop edges accepted so far, in order.
  std::vector<LoopClosure> accepted_loops() const;

  ~MapBuilder();
  MapBuilder(MapBuilder&&) noexcept;
  MapBuilder& operator=(MapBuilder&&) noexcept;

 private:
  Result<void> CloseLoops(const PointCloud& cloud_base, MergeStep& step);

  MapConfig config_;
  ScanVoxelMap map_;
  std::unique_ptr<LoopCloser> loops_;  // set when loop closure is on
  std::vector<TrajectoryPose> trajectory_;
  PointCloud last_scan_;  // the last merged scan in its base_link: the registration's view
  std::optional<Eigen::Isometry3d> last_motion_;  // T_prev_last of the last two merged scans
  std::size_t scans_seen_ = 0;
  // PrepareNext's target for the next Add; dropped whenever the map changes.
  std::unique_ptr<RegistrationTarget> next_target_;
};

}  // namespace pitchlab::mapping
