#include "pitchlab/mapping/elevation_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "elevation_insert.hpp"

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {
namespace {

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
  if (z < c.min_z) {
    c.next_min_z = c.min_z;
    c.min_z = z;
  } else if (z < c.next_min_z) {
    c.next_min_z = z;
  }
  if (z > c.max_z) {
    c.next_max_z = c.max_z;
    c.max_z = z;
  } else if (z > c.next_max_z) {
    c.next_max_z = z;
  }
}

// Chan et al.'s parallel combination: `a` becomes the statistics of a's and b's points, where b's
// positions are shifted by (ox, oy) into a's cell frame.
void CombineInto(CellStats& a, const CellStats& b, float ox, float oy) {
  if (b.count == 0) {
    a.clearance_z = std::min(a.clearance_z, b.clearance_z);
    return;
  }
  const double na = a.count, nb = b.count, n = na + nb;
  const double dx = b.mean_x + ox - a.mean_x, dy = b.mean_y + oy - a.mean_y,
               dz = b.mean_z - a.mean_z;
  const double w = na * nb / n;
  a.c_xx = static_cast<float>(a.c_xx + b.c_xx + dx * dx * w);
  a.c_xy = static_cast<float>(a.c_xy + b.c_xy + dx * dy * w);
  a.c_xz = static_cast<float>(a.c_xz + b.c_xz + dx * dz * w);
  a.c_yy = static_cast<float>(a.c_yy + b.c_yy + dy * dy * w);
  a.c_yz = static_cast<float>(a.c_yz + b.c_yz + dy * dz * w);
  a.c_zz = static_cast<float>(a.c_zz + b.c_zz + dz * dz * w);
  a.mean_x = static_cast<float>(a.mean_x + dx * nb / n);
  a.mean_y = static_cast<float>(a.mean_y + dy * nb / n);
  a.mean_z = static_cast<float>(a.mean_z + dz * nb / n);
  a.count += b.count;
  // The second extreme of the union: the lesser of the two extremes or the greater second one.
  a.next_min_z = std::min(std::max(a.min_z, b.min_z), std::min(a.next_min_z, b.next_min_z));
  a.next_max_z = std::max(std::min(a.max_z, b.max_z), std::max(a.next_max_z, b.next_max_z));
  a.min_z = std::min(a.min_z, b.min_z);
  a.max_z = std::max(a.max_z, b.max_z);
  a.clearance_z = std::min(a.clearance_z, b.clearance_z);
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

// std::hypot(x, y) as glibc computes it for finite floats (2.36, e_hypotf: read from its
// disassembly): the exact squares summed and rooted in double, rounded once to float. The same
// bits without the call and its checks, which took a tenth of a re-pose (issue 20).
// insert_scan_reference_test holds InsertScan to the version with std::hypot.
inline float Hypot(float x, float y) {
  const double dx = x, dy = y;
  return static_cast<float>(std::sqrt(dx * dx + dy * dy));
}

// A rectangle of a grid's cells, [i0, i0 + sx) x [j0, j0 + sy).
struct Window {
  int i0 = 0, j0 = 0, sx = 0, sy = 0;
  bool Contains(int i, int j) const {
    return static_cast<unsigned>(i - i0) < static_cast<unsigned>(sx) &&
           static_cast<unsigned>(j - j0) < static_cast<unsigned>(sy);
  }
  std::size_t Linear(int i, int j) const {
    return static_cast<std::size_t>(j - j0) * sx + static_cast<std::size_t>(i - i0);
  }
  std::size_t size() const { return static_cast<std::size_t>(sx) * sy; }
};

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

// Where a point of the scan fell: its cell, or i = kNonFinite / kOffGrid (off the grid or the z
// limits). Found once and read by every pass.
struct PointCell {
  int i, j;
};
constexpr int kNonFinite = -1;
constexpr int kOffGrid = -2;

// InsertScan's buffers, one set per thread and kept between calls: re-posing re-inserts every
// scan, and a window's buffers allocated (and faulted in) afresh for each are a cost of their own.
struct ScanScratch {
  std::vector<PointCell> cells;      // per point
  std::vector<float> clearance;      // the rays' area: see TraceRays
  std::vector<std::int32_t> slot;    // the window's cells: index into sums, or -1
  std::vector<PointSums> sums;       // per cell holding rising points
  std::vector<CellIndex> slot_cell;  // which cell each of sums is
  std::vector<Eigen::Vector3d> normal;
  std::vector<Facing> facing;  // per point
};
ScanScratch& Scratch() {
  thread_local ScanScratch scratch;
  return scratch;
}

// Each point's cell (into `cells`), and the window of the scan's cells: its points' and the
// sensor's (clamped to the grid's edge), two cells around, cut to the grid. TraceRays adds a guard
// band for the rays. Empty when no point is on the grid.
Window LocatePoints(const FastGrid& g, const Eigen::Vector3f* points, std::size_t count,
                    const Eigen::Vector3f& origin, float z_lo, float z_hi,
                    std::vector<PointCell>& cells) {
  cells.resize(count);
  int lo_i = g.sx, lo_j = g.sy, hi_i = -1, hi_j = -1;
  for (std::size_t k = 0; k < count; ++k) {
    PointCell& c = cells[k];
    if (!points[k].allFinite()) {
      c.i = kNonFinite;
    } else if (!CellOf(g, points[k], z_lo, z_hi, &c.i, &c.j)) {
      c.i = kOffGrid;
    } else {
      lo_i = std::min(lo_i, c.i), hi_i = std::max(hi_i, c.i);
      lo_j = std::min(lo_j, c.j), hi_j = std::max(hi_j, c.j);
    }
  }
  if (hi_i < 0) return {};
  const auto clamped = [](float f, int size) {  // NaN: -1
    return static_cast<int>(std::floor(f > -1.0f ? std::min(f, static_cast<float>(size)) : -1.0f));
  };
  const int oi = clamped((origin.x() - g.x0) * g.inv_cell, g.sx);
  const int oj = clamped((origin.y() - g.y0) * g.inv_cell, g.sy);
  constexpr int kPad = 2;
  Window w;
  w.i0 = std::max(0, std::min(lo_i, oi) - kPad);
  w.j0 = std::max(0, std::min(lo_j, oj) - kPad);
  w.sx = std::min(g.sx, std::max(hi_i, oi) + kPad + 1) - w.i0;
  w.sy = std::min(g.sy, std::max(hi_j, oj) + kPad + 1) - w.j0;
  return w;
}

// Where a ray's walk starts: Amanatides & Woo in 2D over the cells under the segment from `from`
// to `to` (map frame), the times [0, 1 along the segment] of the next column and row boundary
// and between boundaries, and at most how many steps it takes.
struct RayWalk {
  float t_x, t_y, t_dx, t_dy, z0, dz;
  int i, j, ie, je, step_i, step_j, max_steps;
};

RayWalk StartWalk(const FastGrid& g, const Eigen::Vector3f& from, const Eigen::Vector3f& to) {
  const float gx = (from.x() - g.x0) * g.inv_cell, gy = (from.y() - g.y0) * g.inv_cell;
  const float hx = (to.x() - g.x0) * g.inv_cell, hy = (to.y() - g.y0) * g.inv_cell;
  RayWalk r;
  r.i = static_cast<int>(std::floor(gx)), r.j = static_cast<int>(std::floor(gy));
  r.ie = static_cast<int>(std::floor(hx)), r.je = static_cast<int>(std::floor(hy));
  const float ddx = hx - gx, ddy = hy - gy;
  r.step_i = ddx > 0 ? 1 : -1, r.step_j = ddy > 0 ? 1 : -1;
  r.t_dx = ddx != 0 ? std::abs(1.0f / ddx) : kInf;
  r.t_dy = ddy != 0 ? std::abs(1.0f / ddy) : kInf;
  r.t_x = ddx != 0 ? ((ddx > 0 ? (r.i + 1 - gx) : (gx - r.i)) * r.t_dx) : kInf;
  r.t_y = ddy != 0 ? ((ddy > 0 ? (r.j + 1 - gy) : (gy - r.j)) * r.t_dy) : kInf;
  r.z0 = from.z(), r.dz = to.z() - from.z();
  r.max_steps = std::abs(r.ie - r.i) + std::abs(r.je - r.j) + 2;
  return r;
}

// The clearance arrays of the rays' pass: `scratch` (a rectangle of cells, the array's layout)
// holds the clearance of the grid's cells in `w` = scratch cut to the grid; its other cells are
// off the grid and thrown away.
struct ClearanceArea {
  Window scratch, w;
  float* clearance;
};

// The walk cell by cell in order, lowering each crossed cell's clearance to the ray's highest z
// inside it; the cell of `to` (where the point landed) is left alone. Cells of a.w are lowered in
// a.clearance, other cells of the grid in `cells`. Returns the number of cells of the grid
// updated: the reference walk, for rays that may leave the scratch area or the grid.
std::size_t CheckedWalk(const FastGrid& g, const ClearanceArea& a, std::vector<CellStats>& cells,
                        RayWalk r) {
  float t_in = 0.0f;
  std::size_t updated = 0;
  for (int s = 0; s < r.max_steps && !(r.i == r.ie && r.j == r.je); ++s) {
    const float t_out = std::min(std::min(r.t_x, r.t_y), 1.0f);
    const float z_high = r.z0 + r.dz * (r.dz < 0 ? t_in : t_out);
    if (a.w.Contains(r.i, r.j)) {
      float& c = a.clearance[a.scratch.Linear(r.i, r.j)];
      c = std::min(c, z_high);
      ++updated;
    } else if (r.i >= 0 && r.j >= 0 && r.i < g.sx && r.j < g.sy) {
      CellStats& c = cells[static_cast<std::size_t>(r.j) * g.sx + r.i];
      c.clearance_z = std::min(c.clearance_z, z_high);
      ++updated;
    }
    t_in = t_out;
    if (r.t_x < r.t_y) {
      r.i += r.step_i;
      r.t_x += r.t_dx;
    } else {
      r.j += r.step_j;
      r.t_y += r.t_dy;
    }
  }
  return updated;
}

// CheckedWalk's loop for a walk known to stay in the scratch area: no bounds, the cell an index
// stepped along, the end that index (the same cell there), the rising or falling ray's z chosen
// once. Returns the steps taken; `reached`: whether it ended in the point's cell.
template <bool kFalling>
int UncheckedWalk(float* clearance, std::ptrdiff_t at, std::ptrdiff_t at_end,
                  std::ptrdiff_t row_step, RayWalk r, bool* reached) {
  float t_in = 0.0f;
  int s = 0;
  for (; s < r.max_steps && at != at_end; ++s) {
    const float t_out = std::min(std::min(r.t_x, r.t_y), 1.0f);
    const float z_high = r.z0 + r.dz * (kFalling ? t_in : t_out);
    float& c = clearance[at];
    c = std::min(c, z_high);
    t_in = t_out;
    if (r.t_x < r.t_y) {
      at += r.step_i;
      r.t_x += r.t_dx;
    } else {
      at += row_step;
      r.t_y += r.t_dy;
    }
  }
  *reached = at == at_end;
  return s;
}

// One ray: unchecked when its walk cannot leave the scratch area. A walk steps its column towards
// the end's, never back, and in at most max_steps = |columns| + |rows| + 2 steps passes the end's
// column by at most |rows| + 2 (round-off); rows alike. Its updates are all on the grid when it
// started on the grid and ended in the point's cell; otherwise (a start off the grid, round-off
// past the end) CheckedWalk walks it again for the count: min() again with the same z changes no
// bit.
std::size_t Walk(const FastGrid& g, const ClearanceArea& a, std::vector<CellStats>& cells,
                 const RayWalk& r) {
  const Window& S = a.scratch;
  const int u = r.i - S.i0, v = r.j - S.j0, ue = r.ie - S.i0, ve = r.je - S.j0;
  const int past_u = std::abs(ve - v) + 2, past_v = std::abs(ue - u) + 2;
  if (std::min(u, ue) < past_u || std::min(v, ve) < past_v || std::max(u, ue) + past_u >= S.sx ||
      std::max(v, ve) + past_v >= S.sy) {
    return CheckedWalk(g, a, cells, r);
  }
  const std::ptrdiff_t at = static_cast<std::ptrdiff_t>(v) * S.sx + u;
  const std::ptrdiff_t at_end = static_cast<std::ptrdiff_t>(ve) * S.sx + ue;
  const std::ptrdiff_t row_step = static_cast<std::ptrdiff_t>(r.step_j) * S.sx;
  bool reached = false;
  const int steps = r.dz < 0 ? UncheckedWalk<true>(a.clearance, at, at_end, row_step, r, &reached)
                             : UncheckedWalk<false>(a.clearance, at, at_end, row_step, r, &reached);
  if (reached && a.w.Contains(r.i, r.j)) return static_cast<std::size_t>(steps);
  return CheckedWalk(g, a, cells, r);
}

// The rays' pass: each ray's last `ray_len` [m] lowers the clearance of the cells it crosses.
// Traced in a float array (4 bytes a cell, where CellStats' 52 left the walk waiting on memory)
// over the scan's window `pw` and a guard band as wide as a walk's reach, so most walks need no
// bounds; the grid's cells there are copied out of the cells and back, so every cell sees the
// same min()s in the same order as when the rays were traced over the cells themselves. Out of
// line: inlined into InsertScan, the walk's constants went to the stack.
[[gnu::noinline]] std::size_t TraceRays(const FastGrid& g, const Window& pw,
                                        std::vector<CellStats>& cells,
                                        const Eigen::Vector3f* points, std::size_t count,
                                        const Eigen::Vector3f& origin, float ray_len,
                                        ScanScratch& s) {
  // A walk starts between the sensor and its point (both in pw unless the sensor is off the
  // grid) and passes its point's cell by at most a ray's rows or columns and 2 (see Walk).
  const float reach = ray_len * g.inv_cell + 4.0f;
  const int guard = reach < 100.0f ? static_cast<int>(reach) : 0;  // whole rays: bounds checked
  ClearanceArea a;
  a.scratch = {pw.i0 - guard, pw.j0 - guard, pw.sx + 2 * guard, pw.sy + 2 * guard};
  a.w.i0 = std::max(a.scratch.i0, 0), a.w.j0 = std::max(a.scratch.j0, 0);
  a.w.sx = std::min(a.scratch.i0 + a.scratch.sx, g.sx) - a.w.i0;
  a.w.sy = std::min(a.scratch.j0 + a.scratch.sy, g.sy) - a.w.j0;
  s.clearance.resize(a.scratch.size());
  a.clearance = s.clearance.data();
  for (int j = a.w.j0; j < a.w.j0 + a.w.sy; ++j) {
    for (int i = a.w.i0; i < a.w.i0 + a.w.sx; ++i) {
      a.clearance[a.scratch.Linear(i, j)] =
          cells[static_cast<std::size_t>(j) * g.sx + i].clearance_z;
    }
  }
  std::size_t updated = 0;
  for (std::size_t k = 0; k < count; ++k) {
    if (s.cells[k].i < 0) continue;
    const Eigen::Vector3f& p = points[k];
    const Eigen::Vector3f d = p - origin;
    const float horizontal = Hypot(d.x(), d.y());
    if (horizontal < 1e-6f) continue;
    const Eigen::Vector3f from =
        horizontal > ray_len ? Eigen::Vector3f(p - d * (ray_len / horizontal)) : origin;
    updated += Walk(g, a, cells, StartWalk(g, from, p));
  }
  for (int j = a.w.j0; j < a.w.j0 + a.w.sy; ++j) {
    for (int i = a.w.i0; i < a.w.i0 + a.w.sx; ++i) {
      cells[static_cast<std::size_t>(j) * g.sx + i].clearance_z =
          a.clearance[a.scratch.Linear(i, j)];
    }
  }
  return updated;
}

// The plane through the rising points pooled over cell c's 3 x 3 cells: its up normal, or zero
// when there is no verdict (see SeenFrom). Pooled in the same order as ever: rows, then columns.
Eigen::Vector3d PooledNormal(const Window& w, const CellIndex& c, double cell_m,
                             const ScanScratch& s) {
  PointSums pooled;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      if (!w.Contains(c.i + di, c.j + dj)) continue;  // the window holds every rising point
      const std::int32_t q = s.slot[w.Linear(c.i + di, c.j + dj)];
      if (q >= 0) pooled.Add(s.sums[q]);
    }
  // A plane needs its points spread across both horizontal axes: a quarter cell (std dev) each.
  const double min_spread = 0.25 * cell_m;
  const double cos_max_tilt = 0.5;  // cos 60 deg
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
  return n;
}

// InsertConfig::drop_undersides and the band: the side each rising point's surface was seen from
// (into s.facing). Per cell holding such points, the plane through the rising points of its 3 x 3
// cells (points relative to the sensor, so float sums keep millimetres); a plane within 60 deg of
// level (the same limit as the layers' step rule, tan 60 deg) that the point's ray met from
// underneath marks the point. Too few points, or points along one line (a thin pole, a single
// scan line: their plane is not determined), give no verdict and the point is kept. The cells'
// sums are in an array over the window (a hash map of them took a fifth of InsertScan).
void SeenFrom(const Window& w, double cell_m, const Eigen::Vector3f* points, std::size_t count,
              const Eigen::Vector3f& origin, ScanScratch& s) {
  s.facing.assign(count, Facing::kUndecided);
  s.slot.assign(w.size(), -1);
  s.sums.clear();
  s.slot_cell.clear();
  const auto rising = [&](std::size_t k) {
    return s.cells[k].i >= 0 && points[k].z() > origin.z();
  };
  for (std::size_t k = 0; k < count; ++k) {
    if (!rising(k)) continue;
    std::int32_t& q = s.slot[w.Linear(s.cells[k].i, s.cells[k].j)];
    if (q < 0) {
      q = static_cast<std::int32_t>(s.sums.size());
      s.sums.emplace_back();
      s.slot_cell.push_back({s.cells[k].i, s.cells[k].j});
    }
    s.sums[q].Add((points[k] - origin).cast<double>());
  }
  s.normal.resize(s.sums.size());
  for (std::size_t q = 0; q < s.sums.size(); ++q) {
    s.normal[q] = PooledNormal(w, s.slot_cell[q], cell_m, s);
  }
  for (std::size_t k = 0; k < count; ++k) {
    if (!rising(k)) continue;
    const Eigen::Vector3d& n = s.normal[s.slot[w.Linear(s.cells[k].i, s.cells[k].j)]];
    if (n.z() <= 0) continue;
    // The ray travels up through the plane: it met the surface's lower face.
    s.facing[k] = (points[k] - origin).cast<double>().dot(n) > 0 ? Facing::kBelow : Facing::kAbove;
  }
}

InsertStats InsertPointsImpl(const GridGeometry& geometry, std::vector<CellStats>& cells,
                             const Eigen::Vector3f* points, std::size_t count,
                             const InsertConfig& config) {
  const FastGrid g(geometry);
  const float z_lo = static_cast<float>(config.min_z_m), z_hi = static_cast<float>(config.max_z_m);
  InsertStats stats;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3f& p = points[k];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
      ++stats.non_finite;
      continue;
    }
    int i, j;
    if (!CellOf(g, p, z_lo, z_hi, &i, &j)) {
      ++stats.outside;
      continue;
    }
    const float lx = p.x() - (g.x0 + i * g.cell + g.half_cell);
    const float ly = p.y() - (g.y0 + j * g.cell + g.half_cell);
    AddToCell(cells[static_cast<std::size_t>(j) * g.sx + i], lx, ly, p.z());
    ++stats.inserted;
  }
  return stats;
}

// InsertScan's last pass: the points that are not undersides, above the band or floating over a
// lower ray go into their cells.
void AddScanPoints(const FastGrid& g, std::vector<CellStats>& cells, const Eigen::Vector3f* points,
                   std::size_t count, const Eigen::Vector3f& origin, const InsertConfig& config,
                   const ScanScratch& s, InsertStats& stats) {
  const float headroom = config.overhang_headroom_m > 0
                             ? static_cast<float>(config.overhang_headroom_m)
                             : std::numeric_limits<float>::infinity();
  const bool band = std::isfinite(config.max_height_m);
  // The height band's top at the sensor (see InsertConfig::max_height_m).
  const float band_top =
      static_cast<float>(origin.z() - config.sensor_height_m + config.max_height_m);
  const float grade = static_cast<float>(config.band_grade);
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3f& p = points[k];
    const int i = s.cells[k].i, j = s.cells[k].j;
    if (i < 0) {
      ++(i == kNonFinite ? stats.non_finite : stats.outside);
      continue;
    }
    if (config.drop_undersides && s.facing[k] == Facing::kBelow) {
      ++stats.underside;
      continue;
    }
    // Above the band's top at the sensor, only ground seen from above may rise further, by the
    // grade per metre (a hill); a single far scan line, whose side nothing decides, may not.
    if (band && p.z() > band_top &&
        (s.facing[k] != Facing::kAbove ||
         p.z() > band_top + grade * (p - origin).head<2>().norm())) {
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
}

// Traces every ray of the scan, then adds the points that do not float over a lower ray. Each
// point's cell is found once; the passes work within the window of cells the scan touches.
InsertStats InsertScanImpl(const GridGeometry& geometry, std::vector<CellStats>& cells,
                           const Eigen::Vector3f* points, std::size_t count,
                           const Eigen::Vector3f& origin, const InsertConfig& config) {
  const FastGrid g(geometry);
  const float z_lo = static_cast<float>(config.min_z_m), z_hi = static_cast<float>(config.max_z_m);
  const float ray_len = static_cast<float>(config.clearance_length_m);
  ScanScratch& s = Scratch();
  const Window w = LocatePoints(g, points, count, origin, z_lo, z_hi, s.cells);
  InsertStats stats;
  if (ray_len > 0.0f && w.size() > 0) {
    stats.clearance_cells = TraceRays(g, w, cells, points, count, origin, ray_len, s);
  }
  if (config.drop_undersides || std::isfinite(config.max_height_m)) {
    SeenFrom(w, g.cell, points, count, origin, s);
  } else {
    s.facing.assign(count, Facing::kUndecided);
  }
  AddScanPoints(g, cells, points, count, origin, config, s, stats);
  return stats;
}

}  // namespace

GridGeometry GridGeometry::FromArea(double x_min_m, double y_min_m, double size_x_m,
                                    double size_y_m, double cell_m) {
  if (!(cell_m > 0.0) || !(size_x_m > 0.0) || !(size_y_m > 0.0)) {
    throw std::invalid_argument("elevation map: cell (" + NumberText(cell_m) +
                                " m) and area (" + NumberText(size_x_m) + " x " +
                                NumberText(size_y_m) + " m) must be positive");
  }
  GridGeometry g;
  g.x_min_m = x_min_m;
  g.y_min_m = y_min_m;
  g.cell_m = cell_m;
  const double m = std::max(1.0, std::round(size_x_m / cell_m));  // Eq. 2
  const double n = std::max(1.0, std::round(size_y_m / cell_m));
  if (m * n > 2147483647.0) {
    throw std::invalid_argument("elevation map: " + std::to_string(m) + " x " + std::to_string(n) +
                                " cells is too many; use a coarser cell");
  }
  g.size_x = static_cast<int>(m);
  g.size_y = static_cast<int>(n);
  return g;
}

GridGeometry GridGeometry::Covering(const Eigen::Vector2d& lo_m, const Eigen::Vector2d& hi_m,
                                    double cell_m, double margin_m) {
  if (!(cell_m > 0.0)) throw std::invalid_argument("elevation map: cell must be positive");
  const double x0 = std::floor((lo_m.x() - margin_m) / cell_m) * cell_m;
  const double y0 = std::floor((lo_m.y() - margin_m) / cell_m) * cell_m;
  const double x1 = (std::floor((hi_m.x() + margin_m) / cell_m) + 1) * cell_m;
  const double y1 = (std::floor((hi_m.y() + margin_m) / cell_m) + 1) * cell_m;
  return FromArea(x0, y0, x1 - x0, y1 - y0, cell_m);
}

bool GridGeometry::SameAs(const GridGeometry& o) const {
  return size_x == o.size_x && size_y == o.size_y && std::abs(cell_m - o.cell_m) < 1e-12 &&
         std::abs(x_min_m - o.x_min_m) < 1e-9 && std::abs(y_min_m - o.y_min_m) < 1e-9;
}

namespace {
void CheckGeometry(const GridGeometry& geometry) {
  if (geometry.size_x <= 0 || geometry.size_y <= 0 || !(geometry.cell_m > 0.0)) {
    throw std::invalid_argument("elevation map: empty geometry (" +
                                std::to_string(geometry.size_x) + " x " +
                                std::to_string(geometry.size_y) + " cells)");
  }
}
}  // namespace

ElevationMap::ElevationMap(const GridGeometry& geometry,
                           std::optional<GeodeticOrigin> geodetic_origin)
    : geometry_(geometry), geodetic_origin_(geodetic_origin) {
  CheckGeometry(geometry);
  cells_.assign(geometry.cell_count(), CellStats{});
}

ElevationMap::ElevationMap(const GridGeometry& geometry, std::vector<CellStats> cells,
                           std::optional<GeodeticOrigin> geodetic_origin)
    : geometry_(geometry), geodetic_origin_(geodetic_origin) {
  CheckGeometry(geometry);
  SetCells(std::move(cells));
}

InsertStats ElevationMap::InsertPoints(const Eigen::Vector3f* points_m, std::size_t count,
                                       const InsertConfig& config) {
  return InsertPointsImpl(geometry_, cells_, points_m, count, config);
}

InsertStats ElevationMap::InsertScan(const Eigen::Vector3f* points_m, std::size_t count,
                                     const Eigen::Vector3f& sensor_origin_m,
                                     const InsertConfig& config) {
  return InsertScanImpl(geometry_, cells_, points_m, count, sensor_origin_m, config);
}

Result<std::size_t> ElevationMap::Merge(const ElevationMap& other, MergeCells cells) {
  const GridGeometry& a = geometry_;
  const GridGeometry& b = other.geometry_;
  if (std::abs(a.cell_m - b.cell_m) > 1e-9 * a.cell_m) {
    return Fail(Error::Code::kInvalidArgument, "merge: cell sizes differ (" +
                                                   NumberText(a.cell_m) + " m vs " +
                                                   NumberText(b.cell_m) + " m)");
  }
  const double oi = (b.x_min_m - a.x_min_m) / a.cell_m, oj = (b.y_min_m - a.y_min_m) / a.cell_m;
  if (std::abs(oi - std::round(oi)) > 1e-6 || std::abs(oj - std::round(oj)) > 1e-6) {
    return Fail(Error::Code::kInvalidArgument, "merge: grids are offset by a fraction of a cell (" +
                                                   std::to_string(oi) + ", " + std::to_string(oj) +
                                                   " cells); resample one onto the other's grid");
  }
  const int di = static_cast<int>(std::lround(oi)), dj = static_cast<int>(std::lround(oj));
  std::size_t dropped = 0;
  for (int j = 0; j < b.size_y; ++j) {
    for (int i = 0; i < b.size_x; ++i) {
      const CellStats& src = other.cells_[static_cast<std::size_t>(j) * b.size_x + i];
      if (src.count == 0 && !std::isfinite(src.clearance_z)) continue;
      const CellIndex dst{i + di, j + dj};
      if (!a.Contains(dst)) {
        dropped += src.count > 0;
        continue;
      }
      CellStats& into = cells_[a.Linear(dst)];
      if (cells == MergeCells::kUnknown && into.known()) continue;
      CombineInto(into, src, 0.0f, 0.0f);
    }
  }
  return dropped;
}

void CombineCells(CellStats& into, const CellStats& from) { CombineInto(into, from, 0.0f, 0.0f); }

InsertStats internal::InsertScanInto(const GridGeometry& geometry, std::vector<CellStats>& cells,
                                     const Eigen::Vector3f* points_m, std::size_t count,
                                     const Eigen::Vector3f& sensor_origin_m,
                                     const InsertConfig& config) {
  return InsertScanImpl(geometry, cells, points_m, count, sensor_origin_m, config);
}

InsertStats internal::InsertPointsInto(const GridGeometry& geometry, std::vector<CellStats>& cells,
                                       const Eigen::Vector3f* points_m, std::size_t count,
                                       const InsertConfig& config) {
  return InsertPointsImpl(geometry, cells, points_m, count, config);
}

void ElevationMap::SetCells(std::vector<CellStats> cells) {
  if (cells.size() != geometry_.cell_count()) {
    throw std::invalid_argument("elevation map: " + std::to_string(cells.size()) +
                                " cells given for a grid of " +
                                std::to_string(geometry_.cell_count()));
  }
  cells_ = std::move(cells);
}

}  // namespace pitchlab::mapping
