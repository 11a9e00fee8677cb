#include "voxel_hash.hpp"

#include <algorithm>
#include <utility>

#include "cell_sort.hpp"

namespace pitchlab::mapping {
namespace {

// Fibonacci hashing: the key's bits mixed into the top bits, which pick the slot.
std::uint64_t Mix(std::uint64_t key) { return key * 0x9E3779B97F4A7C15ull; }

}  // namespace

VoxelHashIndex::VoxelHashIndex(const PointCloud& cloud, double cell_m)
    : inv_cell_(static_cast<float>(1.0 / cell_m)) {
  std::vector<std::uint64_t> keys(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) keys[i] = CellKey(cloud[i], inv_cell_);
  order_ = internal::OrderByCell(keys);
  points_.resize(order_.size());
  std::vector<std::uint64_t> sorted(order_.size());
  for (std::size_t k = 0; k < order_.size(); ++k) {
    points_[k] = cloud[order_[k]];
    sorted[k] = keys[order_[k]];
  }
  std::size_t cells = 0;
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    cells += (k == 0 || sorted[k] != sorted[k - 1]) ? 1 : 0;
  }
  std::size_t size = 16;
  while (size < 2 * cells) size *= 2;  // load factor <= 0.5
  slots_.assign(size, Slot{kEmpty, 0, 0});
  mask_ = size - 1;
  for (std::size_t b = 0; b < sorted.size();) {
    std::size_t e = b;
    while (e < sorted.size() && sorted[e] == sorted[b]) ++e;
    const std::uint64_t key = sorted[b];
    std::uint64_t s = (Mix(key) >> 32) & mask_;
    while (slots_[s].key != kEmpty) s = (s + 1) & mask_;
    slots_[s] = Slot{key, static_cast<int>(b), static_cast<int>(e)};
    b = e;
  }
}

const VoxelHashIndex::Slot* VoxelHashIndex::Find(std::uint64_t key) const {
  for (std::uint64_t s = (Mix(key) >> 32) & mask_;; s = (s + 1) & mask_) {
    const Slot& slot = slots_[s];
    if (slot.key == key) return &slot;
    if (slot.key == kEmpty) return nullptr;
  }
}

template <typename F>
void VoxelHashIndex::ForCells(const Eigen::Vector3f& q, float radius_m, F&& f) const {
  // Per axis the cells [floor((q - r) / cell), floor((q + r) / cell)]: with r <= cell, at most the
  // query's cell and its two neighbours.
  std::int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    const std::int64_t c = static_cast<std::int64_t>(std::floor(q[a] * inv_cell_));
    lo[a] = std::max(c - 1, static_cast<std::int64_t>(std::floor((q[a] - radius_m) * inv_cell_)));
    hi[a] = std::min(c + 1, static_cast<std::int64_t>(std::floor((q[a] + radius_m) * inv_cell_)));
  }
  for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y) {
      for (std::int64_t z = lo[2]; z <= hi[2]; ++z) {
        if (const Slot* slot = Find(CellKey(x, y, z))) f(slot->begin, slot->end);
      }
    }
  }
}

void VoxelHashIndex::Radius(const Eigen::Vector3f& q, float radius_m, std::vector<int>& out) const {
  const float r2 = radius_m * radius_m;
  ForCells(q, radius_m, [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      if ((points_[k] - q).squaredNorm() <= r2) out.push_back(order_[k]);
    }
  });
}

void VoxelHashIndex::RadiusPoints(const Eigen::Vector3f& q, float radius_m,
                                  std::vector<Eigen::Vector3f>& out) const {
  const float r2 = radius_m * radius_m;
  ForCells(q, radius_m, [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      if ((points_[k] - q).squaredNorm() <= r2) out.push_back(points_[k]);
    }
  });
}

int VoxelHashIndex::Nearest(const Eigen::Vector3f& q, float max_m, float& d2) const {
  int best = -1;
  d2 = max_m * max_m;
  ForCells(q, max_m, [&](int begin, int end) {
    for (int k = begin; k < end; ++k) {
      const float d = (points_[k] - q).squaredNorm();
      if (d < d2) {
        d2 = d;
        best = k;
      }
    }
  });
  return best < 0 ? -1 : order_[best];
}

}  // namespace pitchlab::mapping
