#include "pitchlab/mapping/elevation_truth.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "pitchlab/sensors/ray_caster.hpp"

namespace pitchlab::mapping {

ElevationMap ComputeTrueElevationMap(const sensors::RayCaster& caster, const GridGeometry& geometry,
                                     const TruthConfig& config) {
  ElevationMap truth(geometry);
  const int k = std::max(1, config.samples_per_side);
  const std::size_t row_rays = static_cast<std::size_t>(geometry.size_x) * k;
  std::vector<float> origins(row_rays * 3), directions(row_rays * 3), range(row_rays);
  std::vector<Eigen::Vector3f> hits;
  hits.reserve(row_rays);
  for (std::size_t r = 0; r < row_rays; ++r) {
    directions[3 * r] = 0.0f;
    directions[3 * r + 1] = 0.0f;
    directions[3 * r + 2] = -1.0f;
  }
  // One row of sub-samples at a time: rays along x are neighbours, which keeps packets coherent.
  for (int j = 0; j < geometry.size_y; ++j) {
    for (int sj = 0; sj < k; ++sj) {
      const double y = geometry.y_min_m + (j + (sj + 0.5) / k) * geometry.cell_m;
      for (std::size_t r = 0; r < row_rays; ++r) {
        origins[3 * r] = static_cast<float>(geometry.x_min_m + (r + 0.5) / k * geometry.cell_m);
        origins[3 * r + 1] = static_cast<float>(y);
        origins[3 * r + 2] = static_cast<float>(config.ray_top_z_m);
      }
      caster.Cast(origins.data(), directions.data(), row_rays,
                  static_cast<float>(config.max_depth_m), range.data(), nullptr);
      hits.clear();
      for (std::size_t r = 0; r < row_rays; ++r) {
        if (!std::isfinite(range[r])) continue;
        hits.emplace_back(origins[3 * r], origins[3 * r + 1], origins[3 * r + 2] - range[r]);
      }
      (void)truth.InsertPoints(hits.data(), hits.size());
    }
  }
  return truth;
}

MapErrorReport CompareToTruth(const ElevationLayers& estimate, const ElevationLayers& truth) {
  if (!estimate.geometry.SameAs(truth.geometry)) {
    throw std::invalid_argument("compare to truth: the estimate and the truth grids differ");
  }
  MapErrorReport rep;
  std::vector<double> abs_err;
  double sum = 0, sum2 = 0;
  for (std::size_t k = 0; k < truth.state.size(); ++k) {
    rep.drop_cells += estimate.state[k] == CellState::kDrop;
    if (truth.state[k] != CellState::kObserved) continue;
    ++rep.truth_cells;
    if (estimate.state[k] != CellState::kObserved) continue;
    const double e = static_cast<double>(estimate.mean_z[k]) - truth.mean_z[k];
    sum += e;
    sum2 += e * e;
    abs_err.push_back(std::abs(e));
  }
  rep.compared_cells = abs_err.size();
  rep.coverage = rep.truth_cells ? static_cast<double>(rep.compared_cells) / rep.truth_cells : 0.0;
  if (!abs_err.empty()) {
    const double n = static_cast<double>(abs_err.size());
    rep.rmse_m = std::sqrt(sum2 / n);
    rep.mean_error_m = sum / n;
    rep.max_abs_error_m = *std::max_element(abs_err.begin(), abs_err.end());
    auto it = abs_err.begin() + static_cast<std::ptrdiff_t>(0.95 * (abs_err.size() - 1));
    std::nth_element(abs_err.begin(), it, abs_err.end());
    rep.p95_abs_error_m = *it;
  }
  return rep;
}

}  // namespace pitchlab::mapping
