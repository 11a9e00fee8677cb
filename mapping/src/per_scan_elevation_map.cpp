#include "pitchlab/mapping/per_scan_elevation_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace pitchlab::mapping {
namespace {

// A pose is usable when finite and rigid (1e-6: a rotation composed a few thousand times in
// doubles stays orthonormal to ~1e-12; a scaled or sheared matrix is far off).
Result<void> CheckPose(const Eigen::Isometry3d& T, std::size_t id) {
  const Eigen::Matrix3d R = T.linear();
  if (!T.matrix().allFinite() || !(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      R.determinant() < 0) {
    return Fail(Error::Code::kInvalidArgument,
                "per-scan elevation map: scan " + std::to_string(id) +
                    ": T_map_base is not a finite rotation and translation");
  }
  return {};
}

// The part of `g` under the xy bounding box of `points` and `sensor` (rays run between them),
// aligned to g's cells; nullopt when it misses the grid.
std::optional<GridGeometry> ExtentOn(const GridGeometry& g,
                                     const std::vector<Eigen::Vector3f>& points,
                                     const Eigen::Vector3f& sensor) {
  Eigen::Vector2f lo = sensor.head<2>(), hi = sensor.head<2>();
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const CellIndex a = g.IndexOf(lo.x(), lo.y()), b = g.IndexOf(hi.x(), hi.y());
  if (b.i < 0 || b.j < 0 || a.i >= g.size_x || a.j >= g.size_y) return std::nullopt;
  const int i0 = std::max(a.i, 0), j0 = std::max(a.j, 0);
  const int i1 = std::min(b.i, g.size_x - 1), j1 = std::min(b.j, g.size_y - 1);
  GridGeometry local = g;
  local.x_min_m = g.x_min_m + i0 * g.cell_m;
  local.y_min_m = g.y_min_m + j0 * g.cell_m;
  local.size_x = i1 - i0 + 1;
  local.size_y = j1 - j0 + 1;
  return local;
}

}  // namespace

PerScanElevationMap::PerScanElevationMap(const GridGeometry& geometry, const InsertConfig& config)
    : geometry_(geometry), config_(config), map_(geometry) {}

// The scan inserted alone into a grid over its extent, kept as the cells it touched.
PerScanElevationMap::Contribution PerScanElevationMap::Contribute(const Scan& scan) const {
  const Eigen::Isometry3f T = scan.T_map_base.cast<float>();
  std::vector<Eigen::Vector3f> points;
  points.reserve(scan.points_base.size());
  for (const Eigen::Vector3f& p : scan.points_base) points.push_back(T * p);
  const std::size_t scan_points = points.size();
  for (const Eigen::Vector3f& p : scan.ground_base) points.push_back(T * p);
  const Eigen::Vector3f sensor = T * scan.sensor_base;
  Contribution out;
  const std::optional<GridGeometry> local = ExtentOn(geometry_, points, sensor);
  if (!local) return out;
  ElevationMap view(*local);
  (void)view.InsertScan(points.data(), scan_points, sensor, config_);
  (void)view.InsertPoints(points.data() + scan_points, points.size() - scan_points, config_);
  const long di = std::lround((local->x_min_m - geometry_.x_min_m) / geometry_.cell_m);
  const long dj = std::lround((local->y_min_m - geometry_.y_min_m) / geometry_.cell_m);
  for (std::size_t k = 0; k < view.cells().size(); ++k) {
    const CellStats& c = view.at(k);
    if (!c.known() && !std::isfinite(c.clearance_z)) continue;
    const CellIndex at = local->FromLinear(k);
    out.cells.push_back(static_cast<std::uint32_t>(
        geometry_.Linear({static_cast<int>(at.i + di), static_cast<int>(at.j + dj)})));
    out.stats.push_back(c);
  }
  return out;
}

// The map from the contributions: every scan's clearance first, then the points in id order,
// a scan's cell left out where it floats over another scan's ray.
void PerScanElevationMap::Combine() {
  std::vector<CellStats> cells(geometry_.cell_count());
  for (const auto& [id, scan] : scans_) {
    const Contribution& c = scan.contribution;
    for (std::size_t k = 0; k < c.cells.size(); ++k) {
      float& clearance = cells[c.cells[k]].clearance_z;
      clearance = std::min(clearance, c.stats[k].clearance_z);
    }
  }
  const float headroom = config_.overhang_headroom_m > 0
                             ? static_cast<float>(config_.overhang_headroom_m)
                             : std::numeric_limits<float>::infinity();
  overhang_cells_ = 0;
  for (const auto& [id, scan] : scans_) {
    const Contribution& c = scan.contribution;
    for (std::size_t k = 0; k < c.cells.size(); ++k) {
      const CellStats& s = c.stats[k];
      CellStats& into = cells[c.cells[k]];
      if (!s.known()) continue;
      // Within one scan no point lies that far over its own rays (InsertScan left those out):
      // the lower ray is another scan's.
      if (s.min_z > into.clearance_z + headroom) {
        ++overhang_cells_;
        continue;
      }
      if (into.known()) {
        CombineCells(into, s);
      } else {  // what CombineCells gives an empty cell, without its arithmetic
        const float clearance = into.clearance_z;
        into = s;
        into.clearance_z = clearance;  // every scan's rays: already the lowest
      }
    }
  }
  map_.SetCells(std::move(cells));
}

Result<void> PerScanElevationMap::Insert(std::size_t id, std::vector<Eigen::Vector3f> points_base,
                                         const Eigen::Vector3f& sensor_base,
                                         const Eigen::Isometry3d& T_map_base,
                                         std::vector<Eigen::Vector3f> ground_base) {
  if (scans_.count(id)) {
    return Fail(Error::Code::kInvalidArgument,
                "per-scan elevation map: scan " + std::to_string(id) + " is already in the map");
  }
  if (auto ok = CheckPose(T_map_base, id); !ok) return ok;
  Scan scan{std::move(points_base), std::move(ground_base), sensor_base, T_map_base, {}};
  scan.contribution = Contribute(scan);
  scans_.emplace(id, std::move(scan));
  Combine();
  return {};
}

Result<void> PerScanElevationMap::Remove(std::size_t id) {
  if (scans_.erase(id) == 0) {
    return Fail(Error::Code::kInvalidArgument,
                "per-scan elevation map: no scan " + std::to_string(id) + " to remove");
  }
  Combine();
  return {};
}

Result<std::size_t> PerScanElevationMap::Repose(
    const std::vector<std::pair<std::size_t, Eigen::Isometry3d>>& T_map_base) {
  for (const auto& [id, T] : T_map_base) {
    if (!scans_.count(id)) {
      return Fail(Error::Code::kInvalidArgument,
                  "per-scan elevation map: no scan " + std::to_string(id) + " to move");
    }
    if (auto ok = CheckPose(T, id); !ok) return tl::make_unexpected(ok.error());
  }
  std::size_t moved = 0;
  for (const auto& [id, T] : T_map_base) {
    Scan& scan = scans_.at(id);
    if (scan.T_map_base.matrix() == T.matrix()) continue;
    scan.T_map_base = T;
    scan.contribution = Contribute(scan);
    ++moved;
  }
  if (moved > 0) Combine();
  return moved;
}

}  // namespace pitchlab::mapping
