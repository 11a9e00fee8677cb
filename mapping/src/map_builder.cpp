#include "pitchlab/mapping/map_builder.hpp"

#include <stdexcept>
#include <string>

#include "voxel_hash.hpp"

namespace pitchlab::mapping {

void MapConfig::Validate() const {
  if (!(map_voxel_m > 0)) {
    throw std::invalid_argument("map.map_voxel_m = " + std::to_string(map_voxel_m) +
                                ": must be > 0");
  }
  if (!(local_map_radius_m > 0)) {
    throw std::invalid_argument("map.local_map_radius_m = " + std::to_string(local_map_radius_m) +
                                ": must be > 0");
  }
  registration.Validate();
}

MapBuilder::MapBuilder(const MapConfig& config) : config_(config) { config_.Validate(); }

void MapBuilder::Insert(const PointCloud& cloud_map) {
  const float inv = static_cast<float>(1.0 / config_.map_voxel_m);
  for (const Eigen::Vector3f& p : cloud_map) {
    Voxel& v = voxels_[CellKey(p, inv)];
    v.sum += p.cast<double>();
    ++v.count;
  }
}

PointCloud MapBuilder::MapCloud() const {
  PointCloud out;
  out.reserve(voxels_.size());
  for (const auto& [key, v] : voxels_) out.push_back((v.sum / v.count).cast<float>());
  return out;
}

// Map points near the last pose, expressed in the last scan's base_link (the registration target).
PointCloud MapBuilder::LocalTarget(const Eigen::Isometry3d& T_map_last) const {
  const Eigen::Isometry3f T_last_map = T_map_last.inverse().cast<float>();
  const float r2 = static_cast<float>(config_.local_map_radius_m * config_.local_map_radius_m);
  PointCloud out;
  for (const auto& [key, v] : voxels_) {
    const Eigen::Vector3f p = T_last_map * (v.sum / v.count).cast<float>();
    if (p.head<2>().squaredNorm() <= r2) out.push_back(p);
  }
  return out;
}

Result<MergeStep> MapBuilder::Add(const PointCloud& cloud_base,
                                  const std::optional<Eigen::Isometry3d>& odometry_T_map_base,
                                  const std::optional<GuessUncertainty>& odometry_uncertainty,
                                  const std::optional<MeasuredTilt>& measured_tilt) {
  MergeStep step;
  step.scan_index = scans_seen_++;
  if (trajectory_.empty()) {  // the first scan defines the map frame
    std::size_t bad = 0;
    for (const Eigen::Vector3f& p : cloud_base) bad += p.allFinite() ? 0 : 1;
    if (cloud_base.empty()) return Fail(Error::Code::kInvalidArgument, "first scan is empty");
    if (bad > 0) {
      return Fail(Error::Code::kInvalidArgument, "first scan has " + std::to_string(bad) +
                                                     " points that are not finite (NaN/inf)");
    }
    Insert(VoxelDownsample(cloud_base, config_.map_voxel_m));
    last_scan_ = cloud_base;
    trajectory_.push_back({step.scan_index, Eigen::Isometry3d::Identity()});
    step.merged = true;
    step.registration.success = true;
    step.registration.outcome = RegistrationOutcome::kSuccess;
    step.registration.reason = "first scan: defines the map frame";
    return step;
  }
  const Eigen::Isometry3d T_map_last = trajectory_.back().T_map_base;
  RegistrationPrior prior;
  if (odometry_T_map_base) prior.odometry = T_map_last.inverse() * *odometry_T_map_base;
  prior.odometry_uncertainty = odometry_uncertainty;
  if (odometry_T_map_base && measured_tilt) {  // registration works in the last scan's frame
    prior.tilt = measured_tilt;
    prior.tilt->up_target = T_map_last.linear().transpose() * measured_tilt->up_target;
  }
  prior.previous_motion = last_motion_ ? *last_motion_ : Eigen::Isometry3d::Identity();
  prior.target_scan = &last_scan_;  // the map was seen from many places; free space from one
  prior.source_sensor = prior.target_sensor = config_.sensor_base;  // target: the last base_link
  Result<RegistrationResult> r =
      Register(LocalTarget(T_map_last), cloud_base, prior, config_.registration);
  if (!r) return tl::make_unexpected(r.error());
  step.registration = *r;
  if (!r->success) return step;  // reported, never merged
  step.T_map_base = T_map_last * r->T_target_source;
  Insert(TransformCloud(VoxelDownsample(cloud_base, config_.map_voxel_m), step.T_map_base));
  trajectory_.push_back({step.scan_index, step.T_map_base});
  last_scan_ = cloud_base;
  last_motion_ = r->T_target_source;
  step.merged = true;
  return step;
}

}  // namespace pitchlab::mapping
