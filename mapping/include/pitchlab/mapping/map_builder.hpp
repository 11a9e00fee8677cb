#pragma once
// Incremental merging of a scan sequence into one map cloud (DESIGN.md pipeline step 3): each new
// scan is registered against the map around the last pose (scan-to-map), merged only when the
// registration succeeded, and the map is kept voxel-downsampled.

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Settings of MapBuilder.
struct MapConfig {
  double map_voxel_m = 0.1;          ///< map cloud voxel edge (centroid per voxel) [m]
  double local_map_radius_m = 40.0;  ///< map points this close to the last pose are the target [m]
  RegistrationConfig registration;   ///< pairwise settings used for scan-to-map
  /// Where the laser (its mirror at zero pitch) sits in each scan's base_link [m]: normals face it
  /// and free space lies between it and the returns. Unset: at base_link's origin.
  std::optional<Eigen::Vector3f> sensor_base;

  /// Throws std::invalid_argument naming the field and value.
  void Validate() const;
};

/// One pose of the estimated trajectory.
struct TrajectoryPose {
  std::size_t scan_index = 0;  ///< position of the scan in the sequence given to Add
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();
};

/// What Add did with one scan.
struct MergeStep {
  std::size_t scan_index = 0;
  bool merged = false;              ///< false: registration failed, map unchanged
  RegistrationResult registration;  ///< T_target_source is T_last_base (target = last pose)
  Eigen::Isometry3d T_map_base = Eigen::Isometry3d::Identity();  ///< estimate (when merged)
};

/// Builds the map in the frame `map` = base_link of the first scan.
class MapBuilder {
 public:
  explicit MapBuilder(const MapConfig& config);  ///< validates; throws std::invalid_argument

  /// Registers `cloud_base` (points in its base_link [m]) against the map and merges it when the
  /// registration succeeds. `odometry_T_map_base`: odometry's guess of its pose, when known;
  /// `odometry_uncertainty`: how far that guess may be off the motion since the last merged scan
  /// (see RegistrationPrior); `measured_tilt`: that guess's roll and pitch were measured, up
  /// given in `map` (see RegistrationPrior::tilt). Errors: bad input (see Register). A failed
  /// registration is a step with merged == false.
  [[nodiscard]] Result<MergeStep> Add(
      const PointCloud& cloud_base,
      const std::optional<Eigen::Isometry3d>& odometry_T_map_base = {},
      const std::optional<GuessUncertainty>& odometry_uncertainty = {},
      const std::optional<MeasuredTilt>& measured_tilt = {});

  /// The merged map in `map` [m], one centroid per voxel.
  PointCloud MapCloud() const;
  /// T_map_base of every merged scan, in order.
  const std::vector<TrajectoryPose>& trajectory() const { return trajectory_; }
  std::size_t scans_seen() const { return scans_seen_; }

 private:
  struct Voxel {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::uint32_t count = 0;
  };
  void Insert(const PointCloud& cloud_map);
  PointCloud LocalTarget(const Eigen::Isometry3d& T_map_last) const;

  MapConfig config_;
  std::unordered_map<std::uint64_t, Voxel> voxels_;
  std::vector<TrajectoryPose> trajectory_;
  PointCloud last_scan_;  // the last merged scan in its base_link: the registration's view
  std::optional<Eigen::Isometry3d> last_motion_;  // T_prev_last of the last two merged scans
  std::size_t scans_seen_ = 0;
};

}  // namespace pitchlab::mapping
