#include "target_memo.hpp"

#include <algorithm>

namespace pitchlab::mapping::internal {
namespace {

// The normals FPFH is computed from: within `r_normal`, on `feature_index` when its cells are as
// wide (r_normal >= r_feature), else on an index of their own radius. Their radius is half the
// features' by default: on an index of cells as wide as the features' a query scanned about twice
// the points it needed.
Normals FeatureNormals(const PointCloud& cloud, const VoxelHashIndex& feature_index, float r_normal,
                       float r_feature, const Eigen::Vector3f& sensor) {
  if (r_normal >= r_feature) return EstimateNormals(cloud, feature_index, r_normal, sensor);
  return EstimateNormals(cloud, VoxelHashIndex(cloud, r_normal), r_normal, sensor);
}

}  // namespace

IcpCells IcpCellsOf(const RegistrationConfig& config) {
  const float fine = static_cast<float>(
      std::max({config.icp_min_distance_m, config.inlier_distance_m, config.icp_normal_radius_m}));
  return {fine, std::max<double>(fine, config.icp_max_distance_m)};
}

FeatureSide FeatureGeometry(const PointCloud& cloud, const RegistrationConfig& config,
                            const Eigen::Vector3f& sensor) {
  const float r_normal = static_cast<float>(config.normal_radius_m);
  const float r_feature = static_cast<float>(config.feature_radius_m);
  FeatureSide side;
  side.index = std::make_unique<VoxelHashIndex>(cloud, std::max(r_normal, r_feature));
  side.normals = FeatureNormals(cloud, *side.index, r_normal, r_feature, sensor);
  return side;
}

void AddFeatures(FeatureSide& side, const PointCloud& cloud, const RegistrationConfig& config) {
  side.keys = EvenIndices(cloud.size(), config.max_feature_points);
  side.key_points.clear();
  for (int i : side.keys) side.key_points.push_back(cloud[i]);
  side.fpfh = ComputeFpfh(cloud, side.normals, *side.index,
                          static_cast<float>(config.feature_radius_m), config.max_neighbors,
                          side.keys);
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

const TargetMemo::Icp& TargetMemo::IcpParts(const RegistrationConfig& config,
                                            const Eigen::Vector3f& sensor) {
  const Voxels& v = VoxelGrids(config);
  const IcpCells cells = IcpCellsOf(config);
  const float normal_radius = static_cast<float>(config.icp_normal_radius_m);
  if (!icp_ || icp_->icp_voxel_m != v.icp_voxel_m || icp_->cells.fine != cells.fine ||
      icp_->cells.coarse != cells.coarse || icp_->normal_radius != normal_radius ||
      icp_->sensor != sensor) {
    Icp p;
    p.icp_voxel_m = v.icp_voxel_m;
    p.cells = cells;
    p.normal_radius = normal_radius;
    p.sensor = sensor;
    p.fine = std::make_unique<VoxelHashIndex>(v.icp, cells.fine);
    p.coarse = std::make_unique<VoxelHashIndex>(v.icp, cells.coarse);
    p.normals = std::make_unique<LazyNormals>(v.icp, *p.fine, normal_radius, sensor);
    icp_ = std::move(p);
  }
  return *icp_;
}

const FeatureSide& TargetMemo::FeatureParts(const RegistrationConfig& config,
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
    f.side = FeatureGeometry(v.features, config, sensor);
    AddFeatures(f.side, v.features, config);
    features_ = std::move(f);
  }
  return features_->side;
}

}  // namespace pitchlab::mapping::internal
