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
  std::size_t columns = 0;
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    if (k == 0 || sorted[k] != sorted[k - 1]) {
      cells_.push_back({static_cast<std::uint32_t>(sorted[k] & 0x1FFFFF), static_cast<int>(k)});
      columns += k == 0 || (sorted[k] >> 21) != (sorted[k - 1] >> 21);
    }
  }
  std::size_t size = 16;
  while (size < 2 * columns) size *= 2;  // load factor <= 0.5
  columns_.assign(size, Column{kEmpty, 0, 0});
  mask_ = size - 1;
  for (std::size_t b = 0; b < cells_.size();) {
    const std::uint64_t key = sorted[cells_[b].begin] >> 21;
    std::size_t e = b + 1;
    while (e < cells_.size() && (sorted[cells_[e].begin] >> 21) == key) ++e;
    std::uint64_t s = (Mix(key) >> 32) & mask_;
    while (columns_[s].key != kEmpty) s = (s + 1) & mask_;
    columns_[s] = Column{key, static_cast<int>(b), static_cast<int>(e)};
    b = e;
  }
  cells_.push_back({0, static_cast<int>(points_.size())});  // the last cell's end
}

const VoxelHashIndex::Column* VoxelHashIndex::FindColumn(std::uint64_t key) const {
  for (std::uint64_t s = (Mix(key) >> 32) & mask_;; s = (s + 1) & mask_) {
    const Column& column = columns_[s];
    if (column.key == key) return &column;
    if (column.key == kEmpty) return nullptr;
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
  // CellKey's z bits, in which order the cells of a column are sorted.
  const std::uint32_t z_lo = static_cast<std::uint32_t>(CellKey(0, 0, lo[2]));
  const std::uint32_t z_hi = static_cast<std::uint32_t>(CellKey(0, 0, hi[2]));
  for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
    for (std::int64_t y = lo[1]; y <= hi[1]; ++y) {
      const Column* column = FindColumn(CellKey(x, y, 0) >> 21);
      if (!column) continue;
      // A column of a wall or a building holds tens of cells: searched, not walked.
      const Cell* cells = cells_.data();
      const Cell* first = std::lower_bound(cells + column->first_cell, cells + column->end_cell,
                                           z_lo, [](const Cell& c, std::uint32_t z) { return c.z < z; });
      const Cell* end = first;
      while (end < cells + column->end_cell && end->z <= z_hi) ++end;  // at most 3 cells
      if (first < end) f(first->begin, end->begin);
    }
  }
}

// Every point of a run is written and the end advanced past the ones inside: about a third of the
// points a query reads are, with no pattern a branch predictor could follow.
void VoxelHashIndex::Radius(const Eigen::Vector3f& q, float radius_m, std::vector<int>& out) const {
  const float r2 = radius_m * radius_m;
  ForCells(q, radius_m, [&](int begin, int end) {
    std::size_t n = out.size();
    out.resize(n + static_cast<std::size_t>(end - begin));
    for (int k = begin; k < end; ++k) {
      out[n] = order_[k];
      n += (points_[k] - q).squaredNorm() <= r2;
    }
    out.resize(n);
  });
}

void VoxelHashIndex::RadiusPoints(const Eigen::Vector3f& q, float radius_m,
                                  std::vector<Eigen::Vector3f>& out) const {
  const float r2 = radius_m * radius_m;
  ForCells(q, radius_m, [&](int begin, int end) {
    std::size_t n = out.size();
    out.resize(n + static_cast<std::size_t>(end - begin));
    for (int k = begin; k < end; ++k) {
      out[n] = points_[k];
      n += (points_[k] - q).squaredNorm() <= r2;
    }
    out.resize(n);
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
