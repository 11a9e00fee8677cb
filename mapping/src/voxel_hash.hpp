#pragma once
// A spatial hash of points in cubic cells: fixed-radius and nearest-neighbour queries that look at
// the 27 cells around the query. Faster than a k-d tree when the radius is known up front.

#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::mapping {

/// Key of the cell holding `p` for cells of edge 1 / `inv_cell`.
inline std::uint64_t CellKey(const Eigen::Vector3f& p, float inv_cell) {
  const auto q = [inv_cell](float v) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v * inv_cell)) +
                                      (1 << 20)) &
           0x1FFFFF;
  };
  return (q(p.x()) << 42) | (q(p.y()) << 21) | q(p.z());
}

/// Points of a cloud (held by reference: it must outlive the index) bucketed by cell.
class VoxelHashIndex {
 public:
  VoxelHashIndex(const PointCloud& cloud, double cell_m);

  /// Indices of points within `radius_m` (<= the cell edge) of `q`, appended to `out`.
  void Radius(const Eigen::Vector3f& q, float radius_m, std::vector<int>& out) const;
  /// Nearest point within `max_m` (<= the cell edge), or -1; its squared distance in `d2`.
  int Nearest(const Eigen::Vector3f& q, float max_m, float& d2) const;

 private:
  template <typename F>
  void ForCells(const Eigen::Vector3f& q, F&& f) const;

  const PointCloud& cloud_;
  float cell_m_, inv_cell_;
  std::vector<int> order_;                                        // point indices sorted by cell
  std::unordered_map<std::uint64_t, std::pair<int, int>> cells_;  // key -> [begin, end) in order_
};

}  // namespace pitchlab::mapping
