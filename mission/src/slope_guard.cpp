#include "pitchlab/mission/slope_guard.hpp"

#include <algorithm>
#include <cmath>

namespace pitchlab::mission {
namespace {

constexpr float kObstacleHeight_m = 0.5f;  // what a felt obstacle stands above its cells

}  // namespace

PathGrade::PathGrade(const planning::Path& path, double baseline_m)
    : path_(path), baseline_m_(baseline_m) {
  const std::vector<planning::Waypoint>& w = path.waypoints;
  arc_m_.reserve(w.size());
  if (!w.empty()) arc_m_.push_back(0.0);
  for (std::size_t i = 1; i < w.size(); ++i) {
    arc_m_.push_back(arc_m_.back() + std::hypot(w[i].x_m - w[i - 1].x_m, w[i].y_m - w[i - 1].y_m));
  }
}

double PathGrade::Max(double from_m, double to_m) const {
  const std::vector<planning::Waypoint>& w = path_.waypoints;
  double grade = 0;
  std::size_t j = 0;
  for (std::size_t i = 0; i < arc_m_.size() && arc_m_[i] <= to_m; ++i) {
    if (arc_m_[i] + baseline_m_ < from_m) continue;
    j = std::max(j, i + 1);
    while (j < arc_m_.size() && arc_m_[j] < arc_m_[i] + baseline_m_) ++j;
    if (j == arc_m_.size()) break;
    grade = std::max(grade, std::abs(w[j].z_m - w[i].z_m) / (arc_m_[j] - arc_m_[i]));
  }
  return grade;
}

double PathGrade::MaxTilt(const planning::TraversabilityGrid& grid, double from_m,
                          double to_m) const {
  const std::vector<planning::Waypoint>& w = path_.waypoints;
  double tilt = 0;
  for (std::size_t i = 0; i < arc_m_.size() && arc_m_[i] <= to_m; ++i) {
    if (arc_m_[i] < from_m) continue;
    const mapping::CellIndex c = grid.geometry.IndexOf(w[i].x_m, w[i].y_m);
    if (!grid.geometry.Contains(c)) continue;
    const double t = grid.Tilt(grid.geometry.Linear(c));
    if (std::isfinite(t)) tilt = std::max(tilt, t);
  }
  return tilt;
}

double MaxGrade(const planning::Path& path, double from_m, double to_m, double baseline_m) {
  return PathGrade(path, baseline_m).Max(from_m, to_m);
}

void MarkFelt(mapping::ElevationLayers& L, const FeltHazard& f) {
  const mapping::GridGeometry& g = L.geometry;
  const double t = std::tan(f.tilt_rad);
  const float phi_x = static_cast<float>(std::atan(t * std::cos(f.heading_rad)));
  const float phi_y = static_cast<float>(std::atan(t * std::sin(f.heading_rad)));
  const int reach = static_cast<int>(std::ceil(f.radius_m / g.cell_m));
  const mapping::CellIndex c = g.IndexOf(f.centre_m.x(), f.centre_m.y());
  for (int j = c.j - reach; j <= c.j + reach; ++j) {
    for (int i = c.i - reach; i <= c.i + reach; ++i) {
      if (!g.Contains({i, j}) || (g.CenterOf({i, j}) - f.centre_m).norm() > f.radius_m) continue;
      const std::size_t k = g.Linear({i, j});
      if (L.state[k] == mapping::CellState::kDrop) continue;
      if (L.state[k] == mapping::CellState::kUnknown) {
        L.state[k] = mapping::CellState::kObserved;
        L.count[k] = 1;
        L.mean_z[k] = L.min_z[k] = L.max_z[k] = static_cast<float>(f.z_m);
        L.roughness[k] = 0.0f;
      }
      const float top = L.mean_z[k] + static_cast<float>(kObstacleHeight_m);
      L.phi_x[k] = phi_x;
      L.phi_y[k] = phi_y;
      // Felt, not seen: a step however many points the scan put in the cell.
      if (f.obstacle) {
        L.max_z[k] = std::max(L.max_z[k], top);
        if (k < L.next_max_z.size()) L.next_max_z[k] = std::max(L.next_max_z[k], top);
      }
    }
  }
}

}  // namespace pitchlab::mission
