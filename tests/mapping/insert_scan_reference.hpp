#pragma once
// ElevationMap::InsertScan as it was before it was made faster for re-posing (issue 20): each ray
// walked over the map's CellStats, std::hypot, SeenFrom's cells in hash maps, each point's cell
// computed in every pass. Copied verbatim from mapping/src/elevation_map.cpp at ba940a5, the
// plainest statement of the rules: insert_scan_reference_test.cpp holds the fast path to it bit
// for bit.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <vector>

#include <Eigen/Eigenvalues>

#include "pitchlab/mapping/elevation_map.hpp"

namespace pitchlab::mapping::reference {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Welford's update of one cell's moments with a point (lx, ly) from the cell centre, height z.
inline void AddToCell(CellStats& c, float lx, float ly, float z) {
  const std::uint32_t n = ++c.count;
  const float inv_n = 1.0f / static_cast<float>(n);
  const float dx = lx - c.mean_x, dy = ly - c.mean_y, dz = z - c.mean_z;
  c.mean_x += dx * inv_n;
  c.mean_y += dy * inv_n;
  c.mean_z += dz * inv_n;
  const float ex = lx - c.mean_x, ey = ly - c.mean_y, ez = z - c.mean_z;
  c.c_xx += dx * ex;
  c.c_xy += dx * ey;
  c.c_xz += dx * ez;
  c.c_yy += dy * ey;
  c.c_yz += dy * ez;
  c.c_zz += dz * ez;
  // The two lowest and two highest heights, as a sorted list's ends would give them.
  c.next_min_z = std::max(c.min_z, std::min(c.next_min_z, z));
  c.next_max_z = std::min(c.max_z, std::max(c.next_max_z, z));
  c.min_z = std::min(c.min_z, z);
  c.max_z = std::max(c.max_z, z);
}

// The float constants of the per-point loop.
struct FastGrid {
  float x0, y0, inv_cell, cell, half_cell;
  int sx, sy;
  explicit FastGrid(const GridGeometry& g)
      : x0(static_cast<float>(g.x_min_m)),
        y0(static_cast<float>(g.y_min_m)),
        inv_cell(static_cast<float>(1.0 / g.cell_m)),
        cell(static_cast<float>(g.cell_m)),
        half_cell(static_cast<float>(0.5 * g.cell_m)),
        sx(g.size_x),
        sy(g.size_y) {}
};

// Walks the cells under the segment from `from` to `to` (map frame) in order (Amanatides & Woo
// in 2D), lowering each crossed cell's clearance to the ray's highest z inside it; the cell of
// `to` (where the point landed) is left alone. Returns the number of cells updated.
inline std::size_t TraceClearance(const FastGrid& g, std::vector<CellStats>& cells,
                           const Eigen::Vector3f& from, const Eigen::Vector3f& to) {
  const float gx = (from.x() - g.x0) * g.inv_cell, gy = (from.y() - g.y0) * g.inv_cell;
  const float hx = (to.x() - g.x0) * g.inv_cell, hy = (to.y() - g.y0) * g.inv_cell;
  int i = static_cast<int>(std::floor(gx)), j = static_cast<int>(std::floor(gy));
  const int ie = static_cast<int>(std::floor(hx)), je = static_cast<int>(std::floor(hy));
  const float ddx = hx - gx, ddy = hy - gy;
  const int step_i = ddx > 0 ? 1 : -1, step_j = ddy > 0 ? 1 : -1;
  const float t_dx = ddx != 0 ? std::abs(1.0f / ddx) : kInf;
  const float t_dy = ddy != 0 ? std::abs(1.0f / ddy) : kInf;
  float t_x = ddx != 0 ? ((ddx > 0 ? (i + 1 - gx) : (gx - i)) * t_dx) : kInf;
  float t_y = ddy != 0 ? ((ddy > 0 ? (j + 1 - gy) : (gy - j)) * t_dy) : kInf;
  const float z0 = from.z(), dz = to.z() - from.z();
  float t_in = 0.0f;
  std::size_t updated = 0;
  const int max_steps = std::abs(ie - i) + std::abs(je - j) + 2;
  for (int s = 0; s < max_steps && !(i == ie && j == je); ++s) {
    const float t_out = std::min(std::min(t_x, t_y), 1.0f);
    if (i >= 0 && j >= 0 && i < g.sx && j < g.sy) {
      const float z_high = z0 + dz * (dz < 0 ? t_in : t_out);
      CellStats& c = cells[static_cast<std::size_t>(j) * g.sx + i];
      c.clearance_z = std::min(c.clearance_z, z_high);
      ++updated;
    }
    t_in = t_out;
    if (t_x < t_y) {
      i += step_i;
      t_x += t_dx;
    } else {
      j += step_j;
      t_y += t_dy;
    }
  }
  return updated;
}

// The grid cell of a finite point inside the grid and the z limits, or false.
inline bool CellOf(const FastGrid& g, const Eigen::Vector3f& p, float z_lo, float z_hi, int* i,
                   int* j) {
  const float fx = (p.x() - g.x0) * g.inv_cell, fy = (p.y() - g.y0) * g.inv_cell;
  if (!(fx >= 0.0f && fy >= 0.0f && fx < g.sx && fy < g.sy && p.z() >= z_lo && p.z() <= z_hi))
    return false;
  *i = static_cast<int>(fx);
  *j = static_cast<int>(fy);
  return true;
}

// Running sums of a set of points: count, sum and sum of outer products (double).
struct PointSums {
  double n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  void Add(const Eigen::Vector3d& p) {
    n += 1;
    sum += p;
    outer += p * p.transpose();
  }
  void Add(const PointSums& o) {
    n += o.n;
    sum += o.sum;
    outer += o.outer;
  }
};

// Which side of its surface each of the scan's rising points (above the sensor) was seen from.
enum class Facing : std::uint8_t { kUndecided, kBelow, kAbove };

// InsertConfig::drop_undersides and the band: the side each rising point's surface was seen from. Per cell holding such points, the plane through the rising points of
// its 3 x 3 cells (points relative to the sensor, so float sums keep millimetres); a plane within
// 60 deg of level (the same limit as the layers' step rule, tan 60 deg) that the point's ray met
// from underneath marks the point. Too few points, or points along one line (a thin pole, a
// single scan line: their plane is not determined), give no verdict and the point is kept.
inline std::vector<Facing> SeenFrom(const FastGrid& g, const Eigen::Vector3f* points, std::size_t count,
                             const Eigen::Vector3f& origin, float z_lo, float z_hi) {
  std::vector<Facing> facing(count, Facing::kUndecided);
  std::unordered_map<std::int64_t, PointSums> cells;
  const auto key = [&](int i, int j) { return static_cast<std::int64_t>(j) * g.sx + i; };
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3f& p = points[k];
    int i, j;
    if (!p.allFinite() || !(p.z() > origin.z()) || !CellOf(g, p, z_lo, z_hi, &i, &j)) continue;
    cells[key(i, j)].Add((p - origin).cast<double>());
  }
  // A plane needs its points spread across both horizontal axes: a quarter cell (std dev) each.
  const double min_spread = 0.25 * g.cell;
  const double cos_max_tilt = 0.5;  // cos 60 deg
  std::unordered_map<std::int64_t, Eigen::Vector3d> normal;  // up normal; zero: no verdict
  for (const auto& [k, own] : cells) {
    const int i = static_cast<int>(k % g.sx), j = static_cast<int>(k / g.sx);
    PointSums pooled;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const auto it = cells.find(key(i + di, j + dj));
        if (it != cells.end() && i + di >= 0 && i + di < g.sx) pooled.Add(it->second);
      }
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    if (pooled.n >= 3) {
      const Eigen::Vector3d mean = pooled.sum / pooled.n;
      const Eigen::Matrix3d cov = pooled.outer / pooled.n - mean * mean.transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      if (eig.eigenvalues()(1) > min_spread * min_spread) {
        n = eig.eigenvectors().col(0);
        if (n.z() < 0) n = -n;
        if (n.z() < cos_max_tilt) n.setZero();  // a wall, not a ceiling
      }
    }
    normal.emplace(k, n);
  }
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3f& p = points[k];
    int i, j;
    if (!p.allFinite() || !(p.z() > origin.z()) || !CellOf(g, p, z_lo, z_hi, &i, &j)) continue;
    const Eigen::Vector3d& n = normal.at(key(i, j));
    if (n.z() <= 0) continue;
    // The ray travels up through the plane: it met the surface's lower face.
    facing[k] = (p - origin).cast<double>().dot(n) > 0 ? Facing::kBelow : Facing::kAbove;
  }
  return facing;
}

// Traces every ray of the scan, then adds the points that do not float over a lower ray.
inline InsertStats InsertScan(const GridGeometry& geometry, std::vector<CellStats>& cells,
                           const Eigen::Vector3f* points, std::size_t count,
                           const Eigen::Vector3f& origin, const InsertConfig& config) {
  const FastGrid g(geometry);
  const float z_lo = static_cast<float>(config.min_z_m), z_hi = static_cast<float>(config.max_z_m);
  const float ray_len = static_cast<float>(config.clearance_length_m);
  const float headroom = config.overhang_headroom_m > 0
                             ? static_cast<float>(config.overhang_headroom_m)
                             : std::numeric_limits<float>::infinity();
  InsertStats stats;
  if (ray_len > 0.0f) {
    for (std::size_t k = 0; k < count; ++k) {
      const Eigen::Vector3f& p = points[k];
      int i, j;
      if (!p.allFinite() || !CellOf(g, p, z_lo, z_hi, &i, &j)) continue;
      const Eigen::Vector3f d = p - origin;
      const float horizontal = std::hypot(d.x(), d.y());
      if (horizontal < 1e-6f) continue;
      const Eigen::Vector3f from =
          horizontal > ray_len ? Eigen::Vector3f(p - d * (ray_len / horizontal)) : origin;
      stats.clearance_cells += TraceClearance(g, cells, from, p);
    }
  }
  const bool band = std::isfinite(config.max_height_m);
  const std::vector<Facing> facing = config.drop_undersides || band
                                         ? SeenFrom(g, points, count, origin, z_lo, z_hi)
                                         : std::vector<Facing>(count, Facing::kUndecided);
  // The height band's top at the sensor (see InsertConfig::max_height_m).
  const float band_top = static_cast<float>(origin.z() - config.sensor_height_m +
                                            config.max_height_m);
  const float grade = static_cast<float>(config.band_grade);
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3f& p = points[k];
    if (!p.allFinite()) {
      ++stats.non_finite;
      continue;
    }
    int i, j;
    if (!CellOf(g, p, z_lo, z_hi, &i, &j)) {
      ++stats.outside;
      continue;
    }
    if (config.drop_undersides && facing[k] == Facing::kBelow) {
      ++stats.underside;
      continue;
    }
    // Above the band's top at the sensor, only ground seen from above may rise further, by the
    // grade per metre (a hill); a single far scan line, whose side nothing decides, may not.
    if (band && p.z() > band_top &&
        (facing[k] != Facing::kAbove || p.z() > band_top + grade * (p - origin).head<2>().norm())) {
      ++stats.above_band;
      continue;
    }
    CellStats& c = cells[static_cast<std::size_t>(j) * g.sx + i];
    if (p.z() > c.clearance_z + headroom) {
      ++stats.overhang;
      continue;
    }
    AddToCell(c, p.x() - (g.x0 + i * g.cell + g.half_cell),
              p.y() - (g.y0 + j * g.cell + g.half_cell), p.z());
    ++stats.inserted;
  }
  return stats;
}

}  // namespace pitchlab::mapping::reference
