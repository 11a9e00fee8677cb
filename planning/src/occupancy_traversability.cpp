// Occupancy grids <-> traversability (occupancy_grid.hpp): the planner's classes and entry costs
// as map_server values, and a map_server grid as a planning graph.

#include <algorithm>
#include <cmath>
#include <limits>

#include "finish_traversability.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"

namespace pitchlab::planning {

double FullScaleCost(const PlannerConfig& c) {
  return c.weights.roughness * 0.5 * c.robot.step_max_m +
         (c.weights.inclination_x + c.weights.inclination_y) * c.robot.max_inclination_rad;
}

OccupancyGrid ToOccupancy(const TraversabilityGrid& T) {
  OccupancyGrid grid;
  grid.geometry = T.geometry;
  grid.value.assign(T.geometry.cell_count(), kOccupancyUnknown);
  const double full = FullScaleCost(T.config);
  for (std::size_t k = 0; k < grid.value.size(); ++k) {
    const Blocked b = T.blocked[k];
    if (IsFootprintHazard(b)) {
      grid.value[k] = kOccupancyLethal;
    } else if (b == Blocked::kFree || b == Blocked::kNearHazard) {
      // Free under kPenalise but never seen: unknown to a navigation stack all the same.
      if (!std::isfinite(T.z_m[k])) continue;
      const double level = full > 0 ? std::round(99.0 * T.enter_cost[k] / full) : 0.0;
      grid.value[k] = static_cast<std::int8_t>(std::clamp(level, 0.0, 99.0));
    }
  }
  return grid;
}

TraversabilityGrid BuildTraversability(const OccupancyGrid& grid, const PlannerConfig& config) {
  config.Validate();
  const std::size_t n = grid.geometry.cell_count();
  TraversabilityGrid T;
  // No heights: the ground is flat at z = 0 where it is known (Eq. 4's P the flat distance), and
  // no roughness or inclination is known.
  StartTraversability(grid.geometry, config, T);
  T.occupancy_cost.assign(n, 0.0f);
  const double full = FullScaleCost(config);
  for (std::size_t k = 0; k < n; ++k) {
    const std::int8_t v = grid.value[k];
    if (v >= kOccupancyLethal) {
      T.blocked[k] = Blocked::kOccupied;
    } else if (v < 0) {
      T.blocked[k] = config.unknown == UnknownPolicy::kForbid ? Blocked::kUnknown : Blocked::kFree;
      T.enter_cost[k] = static_cast<float>(config.unknown_penalty);
    } else {
      T.z_m[k] = 0.0f;
      T.occupancy_cost[k] = T.enter_cost[k] = static_cast<float>(v / 99.0 * full);
    }
  }
  FinishTraversability(T);
  return T;
}

}  // namespace pitchlab::planning
