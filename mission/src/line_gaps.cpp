#include "line_gaps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pitchlab::mission {

double DenseLinesRadius(const sensors::Scan3D& scan, double laser_height_m, double cell_m) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < scan.lines.size(); ++i) {
    steps.push_back(std::abs(scan.lines[i].pitch_rad - scan.lines[i - 1].pitch_rad));
  }
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double dtheta = steps[steps.size() / 2];
  if (!(dtheta > 0.0) || !(laser_height_m > 0.0)) return 0.0;
  // A line at depression t meets the ground at d = h / tan t; the next, dtheta lower, nearer by
  // dtheta h / sin^2 t = dtheta (d^2 + h^2) / h: one cell at d^2 = cell h / dtheta - h^2.
  return std::sqrt(
      std::max(0.0, cell_m * laser_height_m / dtheta - laser_height_m * laser_height_m));
}

double NearestGroundAhead(const sensors::Scan3D& scan, const sensors::MountConfig& mount) {
  double steepest = -std::numeric_limits<double>::infinity();
  for (const sensors::LaserLine& line : scan.lines) steepest = std::max(steepest, line.pitch_rad);
  if (!std::isfinite(steepest)) return std::numeric_limits<double>::infinity();
  // Positive pitch turns the scan plane's forward beam down (R_y).
  const Eigen::Isometry3d T = mount.BaseToLaser(steepest);
  const Eigen::Vector3d o = T.translation(), d = T.linear() * Eigen::Vector3d::UnitX();
  if (!(d.z() < 0.0) || !(o.z() > 0.0)) return std::numeric_limits<double>::infinity();
  const double hit_x = o.x() - o.z() / d.z() * d.x();
  return std::max(0.0, hit_x - mount.BaseToLaser(0.0).translation().x());
}

std::size_t RefuteBridges(const planning::TraversabilityGrid& grid,
                          const mapping::ElevationLayers& layers, const Eigen::Vector2d& laser_xy,
                          double heading_rad, double near_m, double radius_m,
                          std::vector<RefutedGap>& refuted) {
  const mapping::GridGeometry& g = grid.geometry;
  refuted.resize(g.cell_count(), RefutedGap::kNone);
  if (!(radius_m > 0.0) || grid.z_m.size() != g.cell_count() ||
      layers.state.size() != g.cell_count() || layers.clearance_z.size() != g.cell_count()) {
    return 0;
  }
  const Eigen::Vector2d ahead(std::cos(heading_rad), std::sin(heading_rad));
  const int reach = static_cast<int>(std::ceil(radius_m / g.cell_m));
  const mapping::CellIndex c = g.IndexOf(laser_xy.x(), laser_xy.y());
  std::size_t marked = 0;
  for (int j = c.j - reach; j <= c.j + reach; ++j) {
    for (int i = c.i - reach; i <= c.i + reach; ++i) {
      if (!g.Contains({i, j})) continue;
      const std::size_t k = g.Linear({i, j});
      const bool bridged =
          layers.state[k] == mapping::CellState::kUnknown && std::isfinite(grid.z_m[k]);
      if (!bridged || refuted[k] != RefutedGap::kNone) continue;
      const Eigen::Vector2d to = g.CenterOf({i, j}) - laser_xy;
      const double ahead_m = to.dot(ahead);
      if (to.norm() > radius_m || ahead_m <= 0.0 || ahead_m < near_m) continue;
      refuted[k] = layers.clearance_z[k] < grid.z_m[k] - kBelowGround_m ? RefutedGap::kDepression
                                                                        : RefutedGap::kUnseen;
      ++marked;
    }
  }
  return marked;
}

void MarkRefutedGaps(mapping::ElevationLayers& layers, const std::vector<RefutedGap>& refuted) {
  const std::size_t n = std::min(refuted.size(), layers.state.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (refuted[k] == RefutedGap::kNone || layers.state[k] != mapping::CellState::kUnknown) {
      continue;
    }
    if (refuted[k] == RefutedGap::kDepression) {
      layers.state[k] = mapping::CellState::kDrop;
    } else {
      layers.clearance_z[k] = std::numeric_limits<float>::infinity();
    }
  }
}

}  // namespace pitchlab::mission
