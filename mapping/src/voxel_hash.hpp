#pragma once
// A spatial hash of points in cubic cells: fixed-radius and nearest-neighbour queries that look at
// the cells (at most 27) the query ball reaches. Faster than a k-d tree when the radius is known up
// front. ICP asks it millions of times per pair, so the (x, y) columns of cells live in a flat
// open-addressing table and the points are copied in cell order (one contiguous run per column).

#include <cmath>
#include <cstdint>
#include <vector>

#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::mapping {

/// Key of the integer cell (x, y, z), each coordinate within +-2^20.
inline std::uint64_t CellKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto q = [](std::int64_t v) {
    return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF;
  };
  return (q(x) << 42) | (q(y) << 21) | q(z);
}

/// Key of the cell holding `p` for cells of edge 1 / `inv_cell`.
inline std::uint64_t CellKey(const Eigen::Vector3f& p, float inv_cell) {
  const auto c = [inv_cell](float v) {
    return static_cast<std::int64_t>(std::floor(v * inv_cell));
  };
  return CellKey(c(p.x()), c(p.y()), c(p.z()));
}

/// Points of a cloud bucketed by cell (a copy: the cloud need not outlive the index).
class VoxelHashIndex {
 public:
  VoxelHashIndex(const PointCloud& cloud, double cell_m);

  /// Indices of points within `radius_m` (<= the cell edge) of `q`, appended to `out` in the order
  /// of their cells (x, then y, then z ascending) and, within a cell, of their indices.
  void Radius(const Eigen::Vector3f& q, float radius_m, std::vector<int>& out) const;
  /// The points Radius finds, themselves (copies, in the same order): read from the index's own
  /// cell-ordered copy, not the cloud, whose order scatters them through memory.
  void RadiusPoints(const Eigen::Vector3f& q, float radius_m,
                    std::vector<Eigen::Vector3f>& out) const;
  /// Nearest point within `max_m` (<= the cell edge), or -1; its squared distance in `d2`.
  int Nearest(const Eigen::Vector3f& q, float max_m, float& d2) const;

 private:
  // The cells of one (x, y) column: their points are one contiguous run of points_, the cells in
  // ascending z, so a query reads each column it reaches as one run (one table probe per column,
  // not per cell).
  struct Column {
    std::uint64_t key;            // CellKey(x, y, 0) >> 21
    int first_cell, end_cell;     // [first_cell, end_cell) in cells_
  };
  struct Cell {
    std::uint32_t z;  // CellKey's low 21 bits: ascending z
    int begin;        // first point in points_; the cell ends where cells_'s next begins
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no column key has all bits set

  const Column* FindColumn(std::uint64_t key) const;
  // Calls f(begin, end) for the points of the occupied cells the ball (q, radius_m) reaches, in
  // the cells' order (x, then y, then z ascending), each column's cells as one run.
  template <typename F>
  void ForCells(const Eigen::Vector3f& q, float radius_m, F&& f) const;

  float inv_cell_;
  std::vector<Eigen::Vector3f> points_;  // the cloud's points sorted by cell
  std::vector<int> order_;               // index into the cloud of each of points_
  std::vector<Cell> cells_;              // every occupied cell in key order, then an end marker
  std::vector<Column> columns_;          // open addressing, linear probing; size a power of two
  std::uint64_t mask_ = 0;
};

}  // namespace pitchlab::mapping
