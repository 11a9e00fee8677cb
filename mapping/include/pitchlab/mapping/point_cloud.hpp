#pragma once
// The cloud type of the mapping module's public API: points only, no PCL in the headers (PCL is
// used inside mapping/src; its headers dominate compile time).

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pitchlab/sensors/scan3d.hpp"

namespace pitchlab::mapping {

/// Points of one frame [m]; which frame is said by the variable name (`cloud_base`, `map_cloud`).
using PointCloud = std::vector<Eigen::Vector3f>;

/// The points of `scan` in base_link [m] (ring, beam, stamp dropped).
PointCloud CloudFromScan(const sensors::Scan3D& scan);

/// `T_target_source * p` for every p of `cloud_source`.
PointCloud TransformCloud(const PointCloud& cloud_source, const Eigen::Isometry3d& T_target_source);

/// One point per occupied voxel of edge `voxel_size_m` [m]: the centroid of its points. Points
/// that are not finite are dropped. `voxel_size_m` <= 0 returns the finite points unchanged.
PointCloud VoxelDownsample(const PointCloud& cloud, double voxel_size_m);

}  // namespace pitchlab::mapping
