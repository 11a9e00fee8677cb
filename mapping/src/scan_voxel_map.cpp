#include "pitchlab/mapping/scan_voxel_map.hpp"

#include <stdexcept>
#include <string>

#include "voxel_hash.hpp"

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {

ScanVoxelMap::ScanVoxelMap(double voxel_m, bool keep_scans)
    : voxel_m_(voxel_m), keep_scans_(keep_scans) {
  if (!(voxel_m > 0)) {
    throw std::invalid_argument("scan voxel map: voxel_m = " + NumberText(voxel_m) +
                                ": must be > 0");
  }
}

void ScanVoxelMap::Insert(const PointCloud& cloud_base, const Eigen::Isometry3d& T_map_base) {
  const float inv = static_cast<float>(1.0 / voxel_m_);
  for (const Eigen::Vector3f& p : TransformCloud(cloud_base, T_map_base)) {
    Voxel& v = voxels_[CellKey(p, inv)];
    v.sum += p.cast<double>();
    ++v.count;
  }
}

void ScanVoxelMap::Add(const PointCloud& cloud_base, const Eigen::Isometry3d& T_map_base) {
  PointCloud down = VoxelDownsample(cloud_base, voxel_m_);
  Insert(down, T_map_base);
  if (keep_scans_) scans_.push_back(std::move(down));
  ++scan_count_;
}

Result<void> ScanVoxelMap::Repose(const std::vector<Eigen::Isometry3d>& T_map_base) {
  if (!keep_scans_) {
    return Fail(Error::Code::kInvalidArgument,
                "scan voxel map: the scans were not kept, so the map cannot be re-posed");
  }
  if (T_map_base.size() != scans_.size()) {
    return Fail(Error::Code::kInvalidArgument,
                "scan voxel map: " + std::to_string(T_map_base.size()) + " poses for " +
                    std::to_string(scans_.size()) + " scans");
  }
  voxels_.clear();
  for (std::size_t i = 0; i < scans_.size(); ++i) Insert(scans_[i], T_map_base[i]);
  return {};
}

PointCloud ScanVoxelMap::Cloud() const {
  PointCloud out;
  out.reserve(voxels_.size());
  for (const auto& [key, v] : voxels_) out.push_back((v.sum / v.count).cast<float>());
  return out;
}

PointCloud ScanVoxelMap::Around(const Eigen::Isometry3d& T_map_frame, double radius_m) const {
  const Eigen::Isometry3f T_frame_map = T_map_frame.inverse().cast<float>();
  const float r2 = static_cast<float>(radius_m * radius_m);
  PointCloud out;
  for (const auto& [key, v] : voxels_) {
    const Eigen::Vector3f p = T_frame_map * (v.sum / v.count).cast<float>();
    if (p.head<2>().squaredNorm() <= r2) out.push_back(p);
  }
  return out;
}

}  // namespace pitchlab::mapping
