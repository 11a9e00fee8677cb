#include "pitchlab/mission/run_scoring.hpp"
#include "pitchlab/mission/waypoint_route.hpp"
#include "upper_median.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace pitchlab::mission {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
constexpr double kHazardSearch_m = 5.0;

struct PoseDelta {
  double translation_m, rotation_deg;
};

PoseDelta Compare(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d d = truth.inverse() * estimate;
  return {d.translation().norm(), Eigen::AngleAxisd(d.linear()).angle() * kRadToDeg};
}

double Tilt(const Eigen::Isometry3d& T) {
  return std::acos(std::clamp(T.linear()(2, 2), -1.0, 1.0));
}

bool IsHazard(planning::Blocked b) {
  return b != planning::Blocked::kFree && b != planning::Blocked::kNearHazard &&
         b != planning::Blocked::kUnknown;
}

// The true trajectory as an 8-connected chain of cells (gaps between samples filled in).
planning::Path CellChain(const std::vector<Eigen::Vector2d>& xy, const mapping::GridGeometry& g) {
  planning::Path path;
  for (const Eigen::Vector2d& p : xy) {
    const mapping::CellIndex c = g.IndexOf(p.x(), p.y());
    if (!g.Contains(c)) continue;
    while (!path.cells.empty() && !(path.cells.back() == c)) {
      const mapping::CellIndex b = path.cells.back();
      const mapping::CellIndex step{b.i + (c.i > b.i) - (c.i < b.i),
                                    b.j + (c.j > b.j) - (c.j < b.j)};
      path.cells.push_back(step);
    }
    if (path.cells.empty()) path.cells.push_back(c);
  }
  return path;
}

double ClosestHazard(const std::vector<Eigen::Vector2d>& xy, const planning::TraversabilityGrid& t,
                     Eigen::Vector2d* where) {
  const mapping::GridGeometry& g = t.geometry;
  const int reach = static_cast<int>(std::ceil(kHazardSearch_m / g.cell_m));
  double best = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector2d& p : xy) {
    const mapping::CellIndex c = g.IndexOf(p.x(), p.y());
    for (int j = std::max(0, c.j - reach); j <= std::min(g.size_y - 1, c.j + reach); ++j) {
      for (int i = std::max(0, c.i - reach); i <= std::min(g.size_x - 1, c.i + reach); ++i) {
        if (!IsHazard(t.blocked[g.Linear({i, j})])) continue;
        // Distance to the cell's nearest point, not its centre.
        const Eigen::Vector2d centre = g.CenterOf({i, j});
        const Eigen::Vector2d d = ((p - centre).cwiseAbs().array() - g.cell_m / 2).cwiseMax(0);
        if (d.norm() < best) best = d.norm(), *where = p;
      }
    }
  }
  return best;
}

// RunScore::touched and its steepest tilt: every true hazard cell the centre crossed, or within
// the footprint's reach of a crossed forbidden cell, counted once.
void TouchedHazards(const planning::TraversabilityGrid& truth, const planning::Path& driven,
                    RunScore& s) {
  const mapping::GridGeometry& g = truth.geometry;
  const double reach_m = planning::FootprintReach(truth);
  const int r = static_cast<int>(std::ceil(reach_m / g.cell_m));
  std::vector<bool> seen(g.cell_count(), false);
  const auto touch = [&](std::size_t k) {
    if (seen[k] || !IsHazard(truth.blocked[k])) return;
    seen[k] = true;
    s.touched.Count(truth.blocked[k]);
    if (truth.blocked[k] == planning::Blocked::kTooSteep)
      s.touched_steepest_deg = std::max(s.touched_steepest_deg, truth.Tilt(k) * kRadToDeg);
  };
  for (std::size_t n = 1; n < driven.cells.size(); ++n) {  // the start excluded, as above
    const mapping::CellIndex c = driven.cells[n];
    const std::size_t k = g.Linear(c);
    if (truth.Free(k)) continue;
    touch(k);
    if (truth.blocked[k] != planning::Blocked::kNearHazard) continue;
    for (int dj = -r; dj <= r; ++dj)
      for (int di = -r; di <= r; ++di) {
        const mapping::CellIndex nb{c.i + di, c.j + dj};
        if (g.Contains(nb) && std::hypot(di, dj) * g.cell_m < reach_m - 1e-9) touch(g.Linear(nb));
      }
  }
  s.too_steep_limit_deg = truth.config.robot.max_inclination_rad * kRadToDeg;
}

// Percentile q of `v` (nearest rank; v not empty).
double Percentile(std::vector<double> v, double q) {
  const auto k = static_cast<std::ptrdiff_t>(std::min(v.size() - 1, std::size_t(q * v.size())));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

std::vector<TiltAgainstTruth> TiltsAgainstTruth(const planning::TraversabilityGrid& estimated,
                                                const planning::TraversabilityGrid& truth) {
  const double limit = truth.config.robot.max_inclination_rad * kRadToDeg;
  std::vector<TiltAgainstTruth> bins(3);
  const double edges[] = {0, 0.5 * limit, limit, 90.0};
  std::vector<std::vector<double>> errors(bins.size());
  for (std::size_t b = 0; b < bins.size(); ++b)
    bins[b].lo_deg = edges[b], bins[b].hi_deg = edges[b + 1];
  for (std::size_t k = 0; k < truth.blocked.size(); ++k) {
    const planning::Blocked t = truth.blocked[k];
    if (!std::isfinite(truth.z_m[k]) || !std::isfinite(estimated.z_m[k]) ||
        t == planning::Blocked::kStep || t == planning::Blocked::kDrop ||
        t == planning::Blocked::kUnknown) {
      continue;
    }
    const double true_deg = truth.Tilt(k) * kRadToDeg;
    std::size_t b = 0;
    while (b + 1 < bins.size() && true_deg >= bins[b].hi_deg) ++b;
    ++bins[b].cells;
    // The grid holds 0 for an inclination the scan did not support (and its unknown cost).
    if (estimated.phi_x_rad[k] == 0.0f && estimated.phi_y_rad[k] == 0.0f) {
      ++bins[b].unsupported;
      continue;
    }
    errors[b].push_back(estimated.Tilt(k) * kRadToDeg - true_deg);
  }
  for (std::size_t b = 0; b < bins.size(); ++b) {
    if (errors[b].empty()) continue;
    bins[b].median_error_deg = UpperMedian(errors[b]);
    bins[b].p10_error_deg = Percentile(errors[b], 0.1);
    bins[b].p90_error_deg = Percentile(errors[b], 0.9);
  }
  return bins;
}

}  // namespace

HazardVerdict CompareHazard(const planning::TraversabilityGrid& estimated,
                            const planning::TraversabilityGrid& truth, std::size_t k) {
  const auto known = [k](const planning::TraversabilityGrid& g) {
    return g.blocked[k] != planning::Blocked::kUnknown &&
           (std::isfinite(g.z_m[k]) || IsHazard(g.blocked[k]));
  };
  if (!known(truth) || !known(estimated)) return HazardVerdict::kNotCompared;
  const planning::Blocked t = truth.blocked[k], e = estimated.blocked[k];
  if (IsHazard(e) && t == planning::Blocked::kFree) return HazardVerdict::kFalseHazard;
  if (IsHazard(t) && e == planning::Blocked::kFree) return HazardVerdict::kMissedHazard;
  return HazardVerdict::kAgree;
}

RunScore ScoreRun(const MissionResult& result, const planning::TraversabilityGrid& truth,
                  const planning::TraversabilityGrid& estimated,
                  const Eigen::Vector2d& start_m, const Eigen::Vector2d& goal_m,
                  planning::Algorithm algorithm, const std::vector<Eigen::Vector2d>& via_m) {
  RunScore s;
  std::vector<Eigen::Vector2d> xy{start_m};
  Eigen::Isometry3d last_true = Eigen::Isometry3d::Identity();
  bool have_true = false;
  std::vector<double> step_m, step_deg;
  const StopRecord* last_merged = nullptr;
  for (const StopRecord& stop : result.stops) {
    if (!stop.T_world_base_true) continue;
    const PoseDelta e = Compare(stop.T_world_base, *stop.T_world_base_true);
    if (stop.merge.merged && last_merged) {
      const PoseDelta step =
          Compare(last_merged->T_world_base.inverse() * stop.T_world_base,
                  last_merged->T_world_base_true->inverse() * *stop.T_world_base_true);
      step_m.push_back(step.translation_m);
      step_deg.push_back(step.rotation_deg);
    }
    if (stop.merge.merged) last_merged = &stop;
    if (stop.merge.merged) {
      s.max_registration_translation_error_m =
          std::max(s.max_registration_translation_error_m, e.translation_m);
      s.max_registration_rotation_error_deg =
          std::max(s.max_registration_rotation_error_deg, e.rotation_deg);
    }
    s.final_translation_error_m = e.translation_m;
    s.final_rotation_error_deg = e.rotation_deg;
    s.max_true_tilt_deg = std::max(s.max_true_tilt_deg, Tilt(*stop.T_world_base_true) * kRadToDeg);
    last_true = *stop.T_world_base_true;
    have_true = true;
  }
  s.registration_steps = static_cast<int>(step_m.size());
  if (!step_m.empty()) {
    const auto p95_max = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      const std::size_t k = static_cast<std::size_t>(std::ceil(0.95 * v.size())) - 1;
      return std::pair{v[k], v.back()};
    };
    std::tie(s.registration_step_p95_m, s.registration_step_max_m) = p95_max(step_m);
    std::tie(s.registration_step_p95_deg, s.registration_step_max_deg) = p95_max(step_deg);
  }
  for (const TrajectorySample& sample : result.trajectory) {
    if (!sample.T_world_base_true) continue;
    const Eigen::Vector2d p = sample.T_world_base_true->translation().head<2>();
    s.true_distance_m += (p - xy.back()).norm();
    xy.push_back(p);
    s.max_true_tilt_deg =
        std::max(s.max_true_tilt_deg, Tilt(*sample.T_world_base_true) * kRadToDeg);
  }
  if (have_true) s.final_distance_to_goal_m = (last_true.translation().head<2>() - goal_m).norm();
  const planning::Path driven = CellChain(xy, truth.geometry);
  const planning::PathOnMap on_truth = planning::EvaluatePath(truth, driven);
  s.driven_cost_on_true_map = on_truth.cost;
  s.forbidden_cells_crossed = on_truth.forbidden_cells;
  for (std::size_t i = 1; i < driven.cells.size(); ++i) {  // the start excluded, as above
    const std::size_t k = truth.geometry.Linear(driven.cells[i]);
    s.crossed_as.Count(truth.blocked[k]);
    if (!truth.Free(k)) s.forbidden_crossed_at.push_back(truth.geometry.CenterOf(driven.cells[i]));
  }
  s.hazard_cells_crossed = s.crossed_as.Total();
  TouchedHazards(truth, driven, s);
  auto optimum = PlanRoute(truth, start_m, via_m, goal_m, algorithm);
  if (optimum) {
    s.true_optimal_cost = optimum->cost;
    if (optimum->cost > 0) s.cost_ratio = on_truth.cost / optimum->cost;
  } else {
    s.true_optimum_note = optimum.error().message;
  }
  s.closest_hazard_m = ClosestHazard(xy, truth, &s.closest_hazard_at);
  if (!estimated.geometry.SameAs(truth.geometry)) {
    throw std::invalid_argument("score: the estimated and the true map are on different grids");
  }
  std::vector<double> steep_map_deg, steep_true_deg;
  const std::vector<bool> reachable = planning::ReachableCells(truth, start_m);
  for (std::size_t k = 0; k < truth.blocked.size(); ++k) {
    const HazardVerdict v = CompareHazard(estimated, truth, k);
    s.map_cells_compared += v != HazardVerdict::kNotCompared;
    if (v == HazardVerdict::kMissedHazard) {
      ++s.missed_hazard_cells;
      s.missed_as.Count(truth.blocked[k]);
      if (truth.blocked[k] == planning::Blocked::kTooSteep) {
        steep_true_deg.push_back(truth.Tilt(k) * kRadToDeg);
        // The grid holds 0 for an inclination the scan did not support (and its unknown cost).
        if (estimated.phi_x_rad[k] == 0.0f && estimated.phi_y_rad[k] == 0.0f) {
          ++s.missed_steep_tilt_unknown;
        } else {
          steep_map_deg.push_back(estimated.Tilt(k) * kRadToDeg);
        }
      }
    }
    if (v == HazardVerdict::kFalseHazard && !reachable[k]) ++s.false_hazard_cells_out_of_reach;
    if (v == HazardVerdict::kFalseHazard && reachable[k]) {
      ++s.false_hazard_cells;
      s.false_as.Count(estimated.blocked[k]);
    }
  }
  s.missed_steep_map_tilt_deg = steep_map_deg.empty() ? 0.0 : UpperMedian(steep_map_deg);
  s.missed_steep_true_tilt_deg = steep_true_deg.empty() ? 0.0 : UpperMedian(steep_true_deg);
  s.tilt_against_truth = TiltsAgainstTruth(estimated, truth);
  return s;
}

}  // namespace pitchlab::mission
