#pragma once
// ElevationMap::InsertScan and InsertPoints over a bare array of cells, for PerScanElevationMap:
// it inserts each scan alone into a grid over the scan's extent, and keeps one array between
// scans where an ElevationMap of its own would allocate, zero and fault in ~2 MB per scan (a
// 20 x 20 m extent at 0.1 m), every scan of every re-pose.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_map.hpp"

namespace pitchlab::mapping::internal {

/// ElevationMap::InsertScan into `cells` (geometry.cell_count() of them, or more: the rest are
/// left alone).
InsertStats InsertScanInto(const GridGeometry& geometry, std::vector<CellStats>& cells,
                           const Eigen::Vector3f* points_m, std::size_t count,
                           const Eigen::Vector3f& sensor_origin_m, const InsertConfig& config);
/// ElevationMap::InsertPoints into `cells`, as InsertScanInto.
InsertStats InsertPointsInto(const GridGeometry& geometry, std::vector<CellStats>& cells,
                             const Eigen::Vector3f* points_m, std::size_t count,
                             const InsertConfig& config);

}  // namespace pitchlab::mapping::internal
