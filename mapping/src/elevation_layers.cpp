#include "pitchlab/mapping/elevation_layers.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>

#include "pitchlab/mapping/parallel_for.hpp"

namespace pitchlab::mapping {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Pooled moments of the points of a region, in the frame of its centre cell (double precision).
struct Moments {
  double n = 0, mx = 0, my = 0, mz = 0;
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0;

  // Chan's combination with a cell (or a single point when c_* are zero) at offset (ox, oy).
  void Add(double nb, double bx, double by, double bz, double bxx, double bxy, double bxz,
           double byy, double byz) {
    if (nb <= 0) return;
    const double n_new = n + nb;
    const double dx = bx - mx, dy = by - my, dz = bz - mz, w = n * nb / n_new;
    xx += bxx + dx * dx * w;
    xy += bxy + dx * dy * w;
    xz += bxz + dx * dz * w;
    yy += byy + dy * dy * w;
    yz += byz + dy * dz * w;
    mx += dx * nb / n_new;
    my += dy * nb / n_new;
    mz += dz * nb / n_new;
    n = n_new;
  }

  // Least-squares slopes (b, c) of z = a + b x + c y; false when the xy spread along the narrow
  // axis is below min_spread (std dev) or fewer than 3 samples.
  bool Slopes(double min_spread, double* b, double* c) const {
    if (n < 3) return false;
    const double det = xx * yy - xy * xy;
    const double tr = xx + yy;
    const double lambda_min = 0.5 * (tr - std::sqrt(std::max(0.0, tr * tr - 4.0 * det)));
    if (!(lambda_min / n > min_spread * min_spread) || det <= 0) return false;
    *b = (yy * xz - xy * yz) / det;
    *c = (xx * yz - xy * xz) / det;
    return true;
  }

  // Standard error of the fitted slope along its worst-determined horizontal direction, for
  // heights of standard deviation sigma: sigma / sqrt(smallest eigenvalue of the xy co-moment
  // sums) [1].
  double SlopeError(double sigma) const {
    const double det = xx * yy - xy * xy;
    const double tr = xx + yy;
    const double lambda_min = 0.5 * (tr - std::sqrt(std::max(0.0, tr * tr - 4.0 * det)));
    return lambda_min > 0 ? sigma / std::sqrt(lambda_min) : std::numeric_limits<double>::infinity();
  }
};

// RMS residual of the cell's points about their own least-squares plane (see the header).
float PlaneResidual(const CellStats& c, double min_spread) {
  if (c.count < 4) return kNaN;
  Moments m;
  m.Add(c.count, c.mean_x, c.mean_y, c.mean_z, c.c_xx, c.c_xy, c.c_xz, c.c_yy, c.c_yz);
  double b = 0, cy = 0;
  if (!m.Slopes(min_spread, &b, &cy)) return kNaN;
  const double ssr = c.c_zz - b * c.c_xz - cy * c.c_yz;  // c_zz minus what the plane explains
  return static_cast<float>(std::sqrt(std::max(0.0, ssr / c.count)));
}

// Inclination of cell (ci, cj) from its 3 x 3 region (see the header for the method).
void Inclination(const ElevationMap& map, int ci, int cj, const LayerConfig& config, float* phi_x,
                 float* phi_y) {
  const GridGeometry& g = map.geometry();
  // The points pooled (whether the scan determined a slope here), and each cell counted once, its
  // points' spread scaled to one point's worth (the slope): the ground's slope, not where the
  // scanner put its points. Pooled by point, a region over a flat patch seen by 20 points a cell
  // and a mound's far flank seen by 1-9 fitted the flat patch: terrain cells whose truth reads
  // 25-37 deg read 5-15 deg, and robots tipped over there (terrain seeds 148, 180). The truth
  // samples every cell alike.
  Moments points, cells, centres;
  const float z_c = map.at({ci, cj}).mean_z;
  const int r = config.inclination_radius_cells;
  // A neighbour some of whose points stand off its own mean by more than a max_fit_slope face
  // across a cell's diagonal holds a step's foot (a wall or a door jamb and the floor before it),
  // not slope: with its mean still near the floor's, its wall points tilted the fits of the floor
  // cells beside it (office doors closed by "too steep" floor cells at the jambs under the
  // measured LMS200 model). A steep slope through a cell spreads its points evenly about the mean,
  // half the rise each way, and stays in the fit up to a 74 deg face (the bound on the whole rise,
  // max - min, also took the gully's steep ground out of its neighbours' fits: terrain runs
  // drove onto slopes they read as gentler and got stuck).
  const double max_own_rise = config.max_fit_slope * std::sqrt(2.0) * g.cell_m;
  for (int dj = -r; dj <= r; ++dj) {
    for (int di = -r; di <= r; ++di) {
      const CellIndex nb{ci + di, cj + dj};
      if (!g.Contains(nb)) continue;
      const CellStats& c = map.at(nb);
      if (c.count == 0) continue;
      const double ox = di * g.cell_m, oy = dj * g.cell_m;
      if (std::abs(c.mean_z - z_c) > config.max_fit_slope * std::hypot(ox, oy)) continue;
      if ((di != 0 || dj != 0) && std::max(c.max_z - c.mean_z, c.mean_z - c.min_z) > max_own_rise) {
        continue;
      }
      points.Add(c.count, c.mean_x + ox, c.mean_y + oy, c.mean_z, c.c_xx, c.c_xy, c.c_xz, c.c_yy,
                 c.c_yz);
      const double w = 1.0 / c.count;
      cells.Add(1, c.mean_x + ox, c.mean_y + oy, c.mean_z, w * c.c_xx, w * c.c_xy, w * c.c_xz,
                w * c.c_yy, w * c.c_yz);
      centres.Add(1, ox, oy, c.mean_z, 0, 0, 0, 0, 0);
    }
  }
  // Support: the slope counts only when the scan determined it, its standard error at the
  // sensor's height noise below max_slope_error (LayerConfig). The centres' heights are cell
  // means, each as uncertain as one point where a cell holds one or two (far floor).
  const double sigma = config.height_noise_m;
  double b = 0, c = 0;
  if (points.Slopes(config.min_spread_m, &b, &c) &&
      points.SlopeError(sigma) <= config.max_slope_error) {
    cells.Slopes(config.min_spread_m, &b, &c);  // left as the points' when the cells span none
    *phi_x = static_cast<float>(std::atan(b));
    *phi_y = static_cast<float>(std::atan(c));
  } else if (centres.Slopes(0.25 * g.cell_m, &b, &c) &&
             centres.SlopeError(sigma) <= config.max_slope_error) {
    *phi_x = static_cast<float>(std::atan(b));
    *phi_y = static_cast<float>(std::atan(c));
  } else {
    *phi_x = *phi_y = kNaN;
  }
}

// Unknown cells beside a rim (IsRim) whose clearance is below the lowest point of every observed
// neighbour by more than drop_depth become drops (seeds); grown breadth-first from them, below the
// same reference, up to drop_flood_m, so a ditch is marked across and a sunken court along its rim.
// A neighbour a ray passed under (a desk top, a car's body, a canopy: its points hang over free
// space) is not ground at its lowest point but at most at that ray: rays under an office desk read
// the floor between its legs as drops below the desk top, which closed rooms off.
PointSpan SpanOf(const CellStats& c, double cell_m) {
  const float half = static_cast<float>(0.5 * cell_m);
  const float reach = std::sqrt(std::min(3.0f, static_cast<float>(c.count) - 1.0f));
  const auto span = [&](float mean, float comoment, float& lo, float& hi) {
    const float r = reach * std::sqrt(std::max(0.0f, comoment) / static_cast<float>(c.count));
    lo = std::clamp(mean - r, -half, half);
    hi = std::clamp(mean + r, -half, half);
  };
  PointSpan s;
  span(c.mean_x, c.c_xx, s.lo_x, s.hi_x);
  span(c.mean_y, c.c_yy, s.lo_y, s.hi_y);
  return s;
}

float LowestObservedNeighbour(const ElevationLayers& L, const CellIndex& c) {
  const GridGeometry& g = L.geometry;
  float ref = std::numeric_limits<float>::infinity();
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      const CellIndex nb{c.i + di, c.j + dj};
      if (!g.Contains(nb)) continue;
      const std::size_t kn = g.Linear(nb);
      if (L.state[kn] == CellState::kObserved) {
        ref = std::min({ref, L.min_z[kn], L.clearance_z[kn]});
      }
    }
  return ref;
}

// A rim a drop can start from: observed ground the scan supports, a surface and not a few points
// of something standing on it. Its inclination is known (a supported fit, LayerConfig's support
// rule) and within the step rule's 60 deg, and its points span less height than a drop is deep.
// A far cell holding one or two points of a wall, a door frame or a table (the real corridor's
// sparse far cells) is none: rays to the floor beyond passed below those points, and the cells
// between, whose floor the scan did not reach, became drops across the corridor.
bool IsRim(const ElevationLayers& L, std::size_t k, const LayerConfig& config) {
  if (L.state[k] != CellState::kObserved || !std::isfinite(L.phi_x[k]) ||
      !std::isfinite(L.phi_y[k]))
    return false;
  const double tx = std::tan(L.phi_x[k]), ty = std::tan(L.phi_y[k]);
  return tx * tx + ty * ty <= config.max_fit_slope * config.max_fit_slope &&
         L.max_z[k] - L.min_z[k] <= config.drop_depth_m;
}

bool HasRimNeighbour(const ElevationLayers& L, const CellIndex& c, const LayerConfig& config) {
  const GridGeometry& g = L.geometry;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      const CellIndex nb{c.i + di, c.j + dj};
      if (g.Contains(nb) && IsRim(L, g.Linear(nb), config)) return true;
    }
  return false;
}

void MarkDrops(ElevationLayers& L, const LayerConfig& config) {
  const GridGeometry& g = L.geometry;
  std::vector<float> reference(g.cell_count(), std::numeric_limits<float>::infinity());
  // Flood steps from the nearest seed: a flood that went on without end carried a reference set
  // by something tall (a fence top, a car's side: seen only above a ray) across whole shadowed
  // streets on `urban`; a drop's hazard is its rim, which the first metre covers.
  std::vector<int> hops(g.cell_count(), 0);
  const int max_hops = static_cast<int>(std::floor(config.drop_flood_m / g.cell_m + 1e-9));
  std::deque<std::size_t> queue;
  const auto unknown_with_ray = [&](std::size_t k) {
    return L.state[k] == CellState::kUnknown && std::isfinite(L.clearance_z[k]);
  };
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    if (!unknown_with_ray(k)) continue;
    const float ref = LowestObservedNeighbour(L, g.FromLinear(k));
    if (std::isfinite(ref) && L.clearance_z[k] < ref - config.drop_depth_m &&
        HasRimNeighbour(L, g.FromLinear(k), config)) {
      L.state[k] = CellState::kDrop;
      reference[k] = ref;
      queue.push_back(k);
    }
  }
  while (!queue.empty()) {
    const std::size_t k = queue.front();
    queue.pop_front();
    if (hops[k] >= max_hops) continue;
    const CellIndex c = g.FromLinear(k);
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const CellIndex nb{c.i + di, c.j + dj};
        if (!g.Contains(nb)) continue;
        const std::size_t kn = g.Linear(nb);
        if (!unknown_with_ray(kn)) continue;
        // The reference only goes down: observed ground beside the new cell stops a flood that
        // started at something tall (a car roof, a canopy).
        const float ref = std::min(reference[k], LowestObservedNeighbour(L, nb));
        if (!(L.clearance_z[kn] < ref - config.drop_depth_m)) continue;
        L.state[kn] = CellState::kDrop;
        reference[kn] = ref;
        hops[kn] = hops[k] + 1;
        queue.push_back(kn);
      }
  }
}

}  // namespace

float Roughness(const CellStats& cell) {
  if (cell.count == 0) return kNaN;
  return std::sqrt(std::max(0.0f, cell.c_zz / static_cast<float>(cell.count)));  // Eq. 3
}

float ElevationLayers::Tilt(std::size_t k) const {
  const float tx = std::tan(phi_x[k]), ty = std::tan(phi_y[k]);
  return std::atan(std::sqrt(tx * tx + ty * ty));
}

ElevationLayers ComputeLayers(const ElevationMap& map, const LayerConfig& config) {
  ElevationLayers L;
  ComputeLayersInto(map, config, L);
  return L;
}

void ComputeLayersInto(const ElevationMap& map, const LayerConfig& config, ElevationLayers& L) {
  if (config.inclination_radius_cells < 1 || config.inclination_radius_cells > 16) {
    throw std::invalid_argument("LayerConfig::inclination_radius_cells = " +
                                std::to_string(config.inclination_radius_cells) +
                                " is outside 1 .. 16");
  }
  const GridGeometry& g = map.geometry();
  const std::size_t n = g.cell_count();
  L.geometry = g;
  L.height_noise_m = config.height_noise_m;
  L.state.assign(n, CellState::kUnknown);
  L.count.assign(n, 0);
  L.mean_z.assign(n, kNaN);
  L.min_z.assign(n, kNaN);
  L.max_z.assign(n, kNaN);
  L.next_min_z.assign(n, kNaN);
  L.next_max_z.assign(n, kNaN);
  L.roughness.assign(n, kNaN);
  L.phi_x.assign(n, kNaN);
  L.phi_y.assign(n, kNaN);
  L.clearance_z.assign(n, std::numeric_limits<float>::infinity());
  L.plane_residual.assign(n, kNaN);
  L.point_span.assign(n, PointSpan{});
  // Each cell's layers from the map alone: rows on the cores, the same as one row after another.
  ParallelRows(g.size_y, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j) {
      for (int i = 0; i < g.size_x; ++i) {
        const std::size_t k = g.Linear({i, j});
        const CellStats& c = map.at(k);
        L.clearance_z[k] = c.clearance_z;
        if (c.count == 0) continue;
        L.state[k] = CellState::kObserved;
        L.count[k] = c.count;
        L.mean_z[k] = c.mean_z;  // Eq. 2
        L.min_z[k] = c.min_z;
        L.max_z[k] = c.max_z;
        L.next_min_z[k] = c.next_min_z;
        L.next_max_z[k] = c.next_max_z;
        L.roughness[k] = Roughness(c);  // Eq. 3
        L.plane_residual[k] = PlaneResidual(c, config.min_spread_m);
        L.point_span[k] = SpanOf(c, g.cell_m);
        Inclination(map, i, j, config, &L.phi_x[k], &L.phi_y[k]);
      }
    }
  });
  MarkDrops(L, config);
}

}  // namespace pitchlab::mapping
