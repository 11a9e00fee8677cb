#include "target_memo.hpp"

#include <algorithm>

namespace pitchlab::mapping::internal {

// Their radius is half the features' by default: on an index of cells as wide as the features' a
// query scanned about twice the points it needed.
Normals FeatureNormals(const PointCloud& cloud, const VoxelHashIndex& feature_index, float r_normal,
                       float r_feature, const Eigen::Vector3f& sensor) {
  if (r_normal >= r_feature) return EstimateNormals(cloud, feature_index, r_normal, sensor);
  return EstimateNormals(cloud, VoxelHashIndex(cloud, r_normal), r_normal, sensor);
}

const CloudStatistics& TargetMemo::Statistics(const Eigen::Vector3f& sensor) {
  if (statistics_sensor_ != sensor) {
    statistics_ = MeasureCloud(cloud_, sensor);
    statistics_sensor_ = sensor;
  }
  return statistics_;
}

const TargetMemo::Voxels& TargetMemo::VoxelGrids(const RegistrationConfig& config) {
  if (!voxels_ || voxels_->icp_voxel_m != config.icp_voxel_m ||
      voxels_->feature_voxel_m != config.feature_voxel_m) {
    Voxels v;
    v.icp_voxel_m = config.icp_voxel_m;
    v.feature_voxel_m = config.feature_voxel_m;
    v.icp = VoxelDownsample(cloud_, config.icp_voxel_m);
    v.features = VoxelDownsample(v.icp, config.feature_voxel_m);
    voxels_ = std::move(v);
    icp_.reset();  // made from the grids above
    features_.reset();
  }
  return *voxels_;
}

const TargetMemo::Icp& TargetMemo::IcpParts(const RegistrationConfig& config, float fine_cell,
                                            double coarse_cell, const Eigen::Vector3f& sensor) {
  const Voxels& v = VoxelGrids(config);
  const float normal_radius = static_cast<float>(config.icp_normal_radius_m);
  if (!icp_ || icp_->icp_voxel_m != v.icp_voxel_m || icp_->fine_cell != fine_cell ||
      icp_->coarse_cell != coarse_cell || icp_->normal_radius != normal_radius ||
      icp_->sensor != sensor) {
    Icp p;
    p.icp_voxel_m = v.icp_voxel_m;
    p.fine_cell = fine_cell;
    p.coarse_cell = coarse_cell;
    p.normal_radius = normal_radius;
    p.sensor = sensor;
    p.fine = std::make_unique<VoxelHashIndex>(v.icp, fine_cell);
    p.coarse = std::make_unique<VoxelHashIndex>(v.icp, coarse_cell);
    p.normals = EstimateNormals(v.icp, *p.fine, normal_radius, sensor);
    icp_ = std::move(p);
  }
  return *icp_;
}

const TargetMemo::Features& TargetMemo::FeatureParts(const RegistrationConfig& config,
                                                     const Eigen::Vector3f& sensor) {
  const Voxels& v = VoxelGrids(config);
  const float r_normal = static_cast<float>(config.normal_radius_m);
  const float r_feature = static_cast<float>(config.feature_radius_m);
  if (!features_ || features_->icp_voxel_m != v.icp_voxel_m ||
      features_->feature_voxel_m != v.feature_voxel_m || features_->normal_radius != r_normal ||
      features_->feature_radius != r_feature ||
      features_->max_feature_points != config.max_feature_points ||
      features_->max_neighbors != config.max_neighbors || features_->sensor != sensor) {
    Features f;
    f.icp_voxel_m = v.icp_voxel_m;
    f.feature_voxel_m = v.feature_voxel_m;
    f.normal_radius = r_normal;
    f.feature_radius = r_feature;
    f.max_feature_points = config.max_feature_points;
    f.max_neighbors = config.max_neighbors;
    f.sensor = sensor;
    f.index = std::make_unique<VoxelHashIndex>(v.features, std::max(r_normal, r_feature));
    f.normals = FeatureNormals(v.features, *f.index, r_normal, r_feature, sensor);
    f.keys = EvenIndices(v.features.size(), config.max_feature_points);
    for (int i : f.keys) f.key_points.push_back(v.features[i]);
    f.fpfh = ComputeFpfh(v.features, f.normals, *f.index, r_feature, config.max_neighbors, f.keys);
    features_ = std::move(f);
  }
  return *features_;
}

}  // namespace pitchlab::mapping::internal
