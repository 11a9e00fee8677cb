#pragma once
// The best route through a mission's waypoints (`run --via`, `--round-trip`): one optimal path
// per leg, joined. What the truth's optimum is for a mission that does not go straight to its
// goal.

#include <vector>

#include <Eigen/Core>

#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// From `start_m` through `via_m` in order to `goal_m` (world [m]) on `grid`: each leg planned by
/// planning::PlanPath, the legs joined (the shared cell once), cost, its parts, length and
/// expansions summed, the steepest step and inclination of any leg kept. Error: the first leg
/// without a path, its message naming the leg ("leg 2 of 3 (waypoint 1 to the goal): ...").
tl::expected<planning::Path, planning::NoPath> PlanRoute(const planning::TraversabilityGrid& grid,
                                                         const Eigen::Vector2d& start_m,
                                                         const std::vector<Eigen::Vector2d>& via_m,
                                                         const Eigen::Vector2d& goal_m,
                                                         planning::Algorithm algorithm);

}  // namespace pitchlab::mission
