#include "pitchlab/mapping/elevation_truth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "pitchlab/sensors/ray_caster.hpp"

namespace pitchlab::mapping {

namespace {

// A step off a surface before casting on, well above float resolution at the heights used [m].
constexpr float kStepM = 1e-3f;

// Vertical rays at (x, y) from heights z: down (sign -1) or up (+1), `range_m` far at most.
// Writes the hit height (NaN on a miss) and the geom hit.
class VerticalCaster {
 public:
  explicit VerticalCaster(const sensors::RayCaster& caster) : caster_(caster) {}
  void Cast(const std::vector<float>& x, const std::vector<float>& y, const std::vector<float>& z,
            float sign, float range_m, std::vector<float>& hit_z, std::vector<int>& geom) {
    const std::size_t n = x.size();
    origins_.resize(3 * n);
    directions_.assign(3 * n, 0.0f);
    range_.resize(n);
    hit_z.resize(n);
    geom.resize(n);
    for (std::size_t r = 0; r < n; ++r) {
      origins_[3 * r] = x[r];
      origins_[3 * r + 1] = y[r];
      origins_[3 * r + 2] = z[r];
      directions_[3 * r + 2] = sign;
    }
    caster_.Cast(origins_.data(), directions_.data(), n, range_m, range_.data(), geom.data());
    for (std::size_t r = 0; r < n; ++r)
      hit_z[r] = std::isfinite(range_[r]) ? z[r] + sign * range_[r]
                                          : std::numeric_limits<float>::quiet_NaN();
  }

 private:
  const sensors::RayCaster& caster_;
  std::vector<float> origins_, directions_, range_;
};

// One row of vertical lines, followed down through overhangs (see ComputeTrueElevationMap).
// `surface_z` holds each line's first hit on entry (NaN: none) and its true surface on return.
void LookThroughOverhangs(VerticalCaster& cast, const std::vector<float>& x,
                          const std::vector<float>& y, std::vector<float>& surface_z,
                          std::vector<int>& surface_geom, const TruthConfig& config) {
  const float depth = static_cast<float>(config.max_depth_m);
  std::vector<std::size_t> live;
  for (std::size_t r = 0; r < x.size(); ++r)
    if (std::isfinite(surface_z[r])) live.push_back(r);
  std::vector<float> lx, ly, lz, hz, probe_z;
  std::vector<int> hg, probe_g;
  // Casts from the live lines at height z(r) in direction sign; keeps those for which keep()
  // holds.
  const auto step = [&](auto z_of, float sign, float range, auto keep) {
    lx.clear(), ly.clear(), lz.clear();
    for (std::size_t r : live) lx.push_back(x[r]), ly.push_back(y[r]), lz.push_back(z_of(r));
    cast.Cast(lx, ly, lz, sign, range, hz, hg);
    std::size_t kept = 0;
    for (std::size_t n = 0; n < live.size(); ++n)
      if (keep(live[n], hz[n], hg[n])) live[kept++] = live[n];
    live.resize(kept);
  };
  std::vector<float> under_z(x.size()), floor_z(x.size());
  std::vector<int> floor_g(x.size());
  std::vector<char> open_below(x.size());
  for (int layer = 0; layer < config.max_overhangs && !live.empty(); ++layer) {
    // (1) The underside: the same geom next.
    step([&](std::size_t r) { return surface_z[r] - kStepM; }, -1.0f, depth,
         [&](std::size_t r, float z, int g) {
           return under_z[r] = z, std::isfinite(z) && g == surface_geom[r];
         });
    // (2) Nothing else touches the underside, probed from just inside and just below.
    step([&](std::size_t r) { return under_z[r] + kStepM; }, -1.0f, 2 * kStepM,
         [&](std::size_t r, float, int g) { return g == surface_geom[r]; });
    step([&](std::size_t r) { return under_z[r] - kStepM; }, +1.0f, 2 * kStepM,
         [&](std::size_t r, float, int g) { return g == surface_geom[r]; });
    // (3) The floor below, with the headroom.
    step([&](std::size_t r) { return under_z[r] - kStepM; }, -1.0f, depth,
         [&](std::size_t r, float z, int g) {
           floor_z[r] = z, floor_g[r] = g;
           return std::isfinite(z) && under_z[r] - z >= config.min_headroom_m;
         });
    // (4) The floor is a top: its own geom next below (a closed solid), or nothing below and
    // nothing seen from just under it (a one-sided plane; a solid's bottom face would be seen).
    step([&](std::size_t r) { return floor_z[r] - kStepM; }, -1.0f, depth,
         [&](std::size_t r, float z, int g) {
           open_below[r] = !std::isfinite(z);
           return open_below[r] || g == floor_g[r];
         });
    step([&](std::size_t r) { return floor_z[r] - kStepM; }, +1.0f, 2 * kStepM,
         [&](std::size_t r, float z, int) { return !open_below[r] || !std::isfinite(z); });
    for (std::size_t r : live) surface_z[r] = floor_z[r], surface_geom[r] = floor_g[r];
  }
}

}  // namespace

ElevationMap ComputeTrueElevationMap(const sensors::RayCaster& caster, const GridGeometry& geometry,
                                     const TruthConfig& config) {
  ElevationMap truth(geometry);
  const int k = std::max(1, config.samples_per_side);
  const std::size_t row_rays = static_cast<std::size_t>(geometry.size_x) * k;
  VerticalCaster cast(caster);
  std::vector<float> x(row_rays), y(row_rays),
      top(row_rays, static_cast<float>(config.ray_top_z_m));
  std::vector<float> surface_z;
  std::vector<int> surface_geom;
  std::vector<Eigen::Vector3f> hits;
  hits.reserve(row_rays);
  for (std::size_t r = 0; r < row_rays; ++r)
    x[r] = static_cast<float>(geometry.x_min_m + (r + 0.5) / k * geometry.cell_m);
  // One row of sub-samples at a time: rays along x are neighbours, which keeps packets coherent.
  for (int j = 0; j < geometry.size_y; ++j) {
    for (int sj = 0; sj < k; ++sj) {
      const auto yr = static_cast<float>(geometry.y_min_m + (j + (sj + 0.5) / k) * geometry.cell_m);
      std::fill(y.begin(), y.end(), yr);
      cast.Cast(x, y, top, -1.0f, static_cast<float>(config.max_depth_m), surface_z, surface_geom);
      if (config.min_headroom_m > 0)
        LookThroughOverhangs(cast, x, y, surface_z, surface_geom, config);
      hits.clear();
      for (std::size_t r = 0; r < row_rays; ++r)
        if (std::isfinite(surface_z[r])) hits.emplace_back(x[r], yr, surface_z[r]);
      (void)truth.InsertPoints(hits.data(), hits.size());
    }
    if (config.progress) config.progress(j + 1, geometry.size_y);
  }
  return truth;
}

std::vector<bool> WallCells(const ElevationLayers& truth, const CompareConfig& config) {
  const GridGeometry& g = truth.geometry;
  std::vector<bool> wall(g.cell_count(), false);
  if (!(config.wall_slope > 0)) return wall;
  const float span_max = static_cast<float>(config.wall_slope * 3.0 * g.cell_m);
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const CellIndex nb{i + di, j + dj};
          if (!g.Contains(nb)) continue;
          const std::size_t kn = g.Linear(nb);
          if (truth.state[kn] != CellState::kObserved) continue;
          lo = std::min(lo, truth.min_z[kn]);
          hi = std::max(hi, truth.max_z[kn]);
        }
      wall[g.Linear({i, j})] = hi - lo > span_max;
    }
  return wall;
}

namespace {

// RMSE, bias, max and p95 of a set of signed errors (destroys their order).
struct ErrorStats {
  std::vector<double> abs_err;
  double sum = 0, sum2 = 0;
  void Add(double e) {
    sum += e;
    sum2 += e * e;
    abs_err.push_back(std::abs(e));
  }
  double Rmse() const { return abs_err.empty() ? 0.0 : std::sqrt(sum2 / abs_err.size()); }
  double Max() const {
    return abs_err.empty() ? 0.0 : *std::max_element(abs_err.begin(), abs_err.end());
  }
};

}  // namespace

MapErrorReport CompareToTruth(const ElevationLayers& estimate, const ElevationLayers& truth,
                              const CompareConfig& config) {
  if (!estimate.geometry.SameAs(truth.geometry)) {
    throw std::invalid_argument("compare to truth: the estimate and the truth grids differ");
  }
  const std::vector<bool> wall = WallCells(truth, config);
  MapErrorReport rep;
  ErrorStats surface, walls, all;
  for (std::size_t k = 0; k < truth.state.size(); ++k) {
    rep.drop_cells += estimate.state[k] == CellState::kDrop;
    if (truth.state[k] != CellState::kObserved) continue;
    ++rep.truth_cells;
    if (estimate.state[k] != CellState::kObserved) continue;
    const double e = static_cast<double>(estimate.mean_z[k]) - truth.mean_z[k];
    all.Add(e);
    (wall[k] ? walls : surface).Add(e);
  }
  rep.compared_cells = all.abs_err.size();
  rep.coverage = rep.truth_cells ? static_cast<double>(rep.compared_cells) / rep.truth_cells : 0.0;
  rep.surface_cells = surface.abs_err.size();
  rep.wall_cells = walls.abs_err.size();
  rep.rmse_m = surface.Rmse();
  rep.max_abs_error_m = surface.Max();
  rep.wall_rmse_m = walls.Rmse();
  rep.all_rmse_m = all.Rmse();
  rep.all_max_abs_error_m = all.Max();
  if (!surface.abs_err.empty()) {
    std::vector<double>& a = surface.abs_err;
    rep.mean_error_m = surface.sum / static_cast<double>(a.size());
    auto it = a.begin() + static_cast<std::ptrdiff_t>(0.95 * (a.size() - 1));
    std::nth_element(a.begin(), it, a.end());
    rep.p95_abs_error_m = *it;
  }
  return rep;
}

ElevationLayers ComputeTruthLayers(const ElevationMap& truth, const LayerConfig& config) {
  ElevationLayers layers = ComputeLayers(truth, config);
  layers.height_noise_m = 0;
  // No mixed pixel or outlier among exact heights: one point of a wall's top in a floor cell is
  // the wall, so a step needs no second point (the extremes stand for the second ones).
  layers.next_min_z = layers.min_z;
  layers.next_max_z = layers.max_z;
  return layers;
}

}  // namespace pitchlab::mapping
