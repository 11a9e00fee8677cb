#pragma once
// The merged map cloud (DESIGN.md pipeline step 3): one centroid per voxel of the points of every
// merged scan. Optionally keeps each scan's voxel-downsampled cloud in its base_link with its
// pose, so the map can be rebuilt at new poses after a pose-graph optimisation (issue 20).

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// A voxel map of merged scans.
class ScanVoxelMap {
 public:
  /// Voxel edge `voxel_m` [m] (> 0, else throws std::invalid_argument); `keep_scans`: keep each
  /// scan for Repose.
  ScanVoxelMap(double voxel_m, bool keep_scans);

  /// Voxel-downsamples `cloud_base` (points in its base_link [m]), moves it to `T_map_base` and
  /// adds it to the map.
  void Add(const PointCloud& cloud_base, const Eigen::Isometry3d& T_map_base);
  /// Rebuilds the map with scan i at T_map_base[i], as if they had been added there in order.
  /// Errors: the scans were not kept, or not one pose per scan.
  [[nodiscard]] Result<void> Repose(const std::vector<Eigen::Isometry3d>& T_map_base);

  /// Every voxel's centroid in `map` [m].
  PointCloud Cloud() const;
  /// The centroids within `radius_m` (horizontally) of the origin of `frame`, in `frame` [m].
  PointCloud Around(const Eigen::Isometry3d& T_map_frame, double radius_m) const;
  std::size_t scan_count() const { return scan_count_; }

 private:
  struct Voxel {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::uint32_t count = 0;
  };
  void Insert(const PointCloud& cloud_base, const Eigen::Isometry3d& T_map_base);

  double voxel_m_;
  bool keep_scans_;
  std::unordered_map<std::uint64_t, Voxel> voxels_;
  std::vector<PointCloud> scans_;  // voxel-downsampled, in base_link, when kept
  std::size_t scan_count_ = 0;
};

}  // namespace pitchlab::mapping
