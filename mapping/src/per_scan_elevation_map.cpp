#include "pitchlab/mapping/per_scan_elevation_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <utility>

#include "elevation_insert.hpp"
#include "pitchlab/mapping/parallel_for.hpp"

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

// A thread's buffers for Contribute, kept between scans: the scan's points in the map frame and
// the cells of the grid over its extent, every one of them empty (CellStats{}) between calls
// unless a call was cut short (`clean`).
struct ContributeBuffers {
  std::vector<Eigen::Vector3f> points;
  std::vector<CellStats> view;
  bool clean = true;
};
ContributeBuffers& Buffers() {
  thread_local ContributeBuffers buffers;
  return buffers;
}

}  // namespace

PerScanElevationMap::PerScanElevationMap(const GridGeometry& geometry, const InsertConfig& config)
    : geometry_(geometry),
      config_(config),
      map_(geometry),
      threads_(std::clamp(std::thread::hardware_concurrency(), 1u, kMaxThreads)) {}

// The scan inserted alone into a grid over its extent, kept as the cells it touched.
void PerScanElevationMap::Contribute(Scan& scan) const {
  const Eigen::Isometry3f T = scan.T_map_base.cast<float>();
  ContributeBuffers& b = Buffers();
  std::vector<Eigen::Vector3f>& points = b.points;
  points.clear();
  for (const Eigen::Vector3f& p : scan.points_base) points.push_back(T * p);
  const std::size_t scan_points = points.size();
  for (const Eigen::Vector3f& p : scan.ground_base) points.push_back(T * p);
  const Eigen::Vector3f sensor = T * scan.sensor_base;
  Contribution& out = scan.contribution;
  out.cells.clear();
  out.stats.clear();
  const std::optional<GridGeometry> local = ExtentOn(geometry_, points, sensor);
  if (!local) return;
  if (!b.clean) b.view.assign(b.view.size(), CellStats{});
  if (b.view.size() < local->cell_count()) b.view.resize(local->cell_count());
  b.clean = false;
  (void)internal::InsertScanInto(*local, b.view, points.data(), scan_points, sensor, config_);
  (void)internal::InsertPointsInto(*local, b.view, points.data() + scan_points,
                                   points.size() - scan_points, config_);
  const long di = std::lround((local->x_min_m - geometry_.x_min_m) / geometry_.cell_m);
  const long dj = std::lround((local->y_min_m - geometry_.y_min_m) / geometry_.cell_m);
  for (std::size_t k = 0; k < local->cell_count(); ++k) {
    CellStats& c = b.view[k];
    if (!c.known() && !std::isfinite(c.clearance_z)) continue;  // untouched: empty already
    const CellIndex at = local->FromLinear(k);
    out.cells.push_back(static_cast<std::uint32_t>(
        geometry_.Linear({static_cast<int>(at.i + di), static_cast<int>(at.j + dj)})));
    out.stats.push_back(c);
    c = CellStats{};
  }
  b.clean = true;
}

// Each scan's contribution depends on that scan alone and lands in its own Scan: the threads
// take scans in any order and the result is the same.
void PerScanElevationMap::ContributeAll(const std::vector<Scan*>& scans) const {
  ParallelFor(
      scans.size(), 1,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k) Contribute(*scans[k]);
      },
      threads_);
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
  Contribute(scan);
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
  std::vector<Scan*> reinsert;  // each moved scan once, at its last pose
  for (const auto& [id, T] : T_map_base) {
    Scan& scan = scans_.at(id);
    if (scan.T_map_base.matrix() == T.matrix()) continue;
    scan.T_map_base = T;
    if (std::find(reinsert.begin(), reinsert.end(), &scan) == reinsert.end()) {
      reinsert.push_back(&scan);
    }
    ++moved;
  }
  ContributeAll(reinsert);
  if (moved > 0) Combine();
  return moved;
}

}  // namespace pitchlab::mapping
