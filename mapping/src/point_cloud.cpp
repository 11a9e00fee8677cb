#include "pitchlab/mapping/point_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

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
  std::vector<std::pair<std::uint64_t, int>> keyed(finite.size());
  for (std::size_t i = 0; i < finite.size(); ++i) {
    keyed[i] = {CellKey(finite[i], inv), static_cast<int>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  PointCloud out;
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; e < keyed.size() && keyed[e].first == keyed[b].first; ++e) {
      sum += finite[keyed[e].second].cast<double>();
    }
    out.push_back((sum / static_cast<double>(e - b)).cast<float>());
    b = e;
  }
  return out;
}

VoxelHashIndex::VoxelHashIndex(const PointCloud& cloud, double cell_m)
    : cloud_(cloud),
      cell_m_(static_cast<float>(cell_m)),
      inv_cell_(static_cast<float>(1.0 / cell_m)) {
  std::vector<std::pair<std::uint64_t, int>> keyed(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    keyed[i] = {CellKey(cloud[i], inv_cell_), static_cast<int>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  order_.resize(keyed.size());
  cells_.reserve(keyed.size());
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    for (; e < keyed.size() && keyed[e].first == keyed[b].first; ++e) order_[e] = keyed[e].second;
    cells_.emplace(keyed[b].first, std::make_pair(static_cast<int>(b), static_cast<int>(e)));
    b = e;
  }
}

template <typename F>
void VoxelHashIndex::ForCells(const Eigen::Vector3f& q, F&& f) const {
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const Eigen::Vector3f c = q + cell_m_ * Eigen::Vector3f(dx, dy, dz);
        auto it = cells_.find(CellKey(c, inv_cell_));
        if (it == cells_.end()) continue;
        for (int k = it->second.first; k < it->second.second; ++k) f(order_[k]);
      }
    }
  }
}

void VoxelHashIndex::Radius(const Eigen::Vector3f& q, float radius_m, std::vector<int>& out) const {
  const float r2 = radius_m * radius_m;
  ForCells(q, [&](int i) {
    if ((cloud_[i] - q).squaredNorm() <= r2) out.push_back(i);
  });
}

int VoxelHashIndex::Nearest(const Eigen::Vector3f& q, float max_m, float& d2) const {
  int best = -1;
  d2 = max_m * max_m;
  ForCells(q, [&](int i) {
    const float d = (cloud_[i] - q).squaredNorm();
    if (d < d2) {
      d2 = d;
      best = i;
    }
  });
  return best;
}

}  // namespace pitchlab::mapping
