#include "pitchlab/mapping/point_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "cell_sort.hpp"
#include "voxel_hash.hpp"

namespace pitchlab::mapping {

PointCloud CloudFromScan(const sensors::Scan3D& scan) {
  PointCloud cloud;
  cloud.reserve(scan.points.size());
  for (const sensors::ScanPoint& p : scan.points) cloud.emplace_back(p.x, p.y, p.z);
  return cloud;
}

PointCloud TransformCloud(const PointCloud& cloud_source,
                          const Eigen::Isometry3d& T_target_source) {
  const Eigen::Isometry3f T = T_target_source.cast<float>();
  PointCloud out;
  out.reserve(cloud_source.size());
  for (const Eigen::Vector3f& p : cloud_source) out.push_back(T * p);
  return out;
}

PointCloud VoxelDownsample(const PointCloud& cloud, double voxel_size_m) {
  PointCloud finite;
  finite.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud) {
    if (p.allFinite()) finite.push_back(p);
  }
  if (voxel_size_m <= 0 || finite.empty()) return finite;
  const float inv = static_cast<float>(1.0 / voxel_size_m);
  std::vector<std::uint64_t> keys(finite.size());
  for (std::size_t i = 0; i < finite.size(); ++i) keys[i] = CellKey(finite[i], inv);
  const std::vector<int> order = internal::OrderByCell(keys);
  PointCloud out;
  for (std::size_t b = 0; b < order.size();) {
    std::size_t e = b;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; e < order.size() && keys[order[e]] == keys[order[b]]; ++e) {
      sum += finite[order[e]].cast<double>();
    }
    out.push_back((sum / static_cast<double>(e - b)).cast<float>());
    b = e;
  }
  return out;
}

}  // namespace pitchlab::mapping
