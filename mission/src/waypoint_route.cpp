#include "pitchlab/mission/waypoint_route.hpp"

#include <algorithm>
#include <string>

namespace pitchlab::mission {
namespace {

std::string PointName(std::size_t k, std::size_t via_count) {
  if (k == 0) return "the start";
  return k <= via_count ? "waypoint " + std::to_string(k) : "the goal";
}

void Append(planning::Path& route, const planning::Path& leg) {
  const bool joined = !route.cells.empty();  // the leg starts on the route's last cell
  route.cells.insert(route.cells.end(), leg.cells.begin() + (joined ? 1 : 0), leg.cells.end());
  route.waypoints.insert(route.waypoints.end(), leg.waypoints.begin() + (joined ? 1 : 0),
                         leg.waypoints.end());
  route.cost += leg.cost;
  route.parts.roughness += leg.parts.roughness;
  route.parts.length += leg.parts.length;
  route.parts.inclination_x += leg.parts.inclination_x;
  route.parts.inclination_y += leg.parts.inclination_y;
  route.parts.unknown += leg.parts.unknown;
  route.parts.occupancy += leg.parts.occupancy;
  route.length_m += leg.length_m;
  route.max_step_m = std::max(route.max_step_m, leg.max_step_m);
  route.max_inclination_rad = std::max(route.max_inclination_rad, leg.max_inclination_rad);
  route.expanded += leg.expanded;
}

}  // namespace

tl::expected<planning::Path, planning::NoPath> PlanRoute(const planning::TraversabilityGrid& grid,
                                                         const Eigen::Vector2d& start_m,
                                                         const std::vector<Eigen::Vector2d>& via_m,
                                                         const Eigen::Vector2d& goal_m,
                                                         planning::Algorithm algorithm) {
  std::vector<Eigen::Vector2d> points{start_m};
  points.insert(points.end(), via_m.begin(), via_m.end());
  points.push_back(goal_m);
  planning::Path route;
  route.algorithm = algorithm;
  const std::size_t legs = points.size() - 1;
  for (std::size_t k = 0; k < legs; ++k) {
    auto leg = planning::PlanPath(grid, points[k], points[k + 1], algorithm);
    if (!leg) {
      planning::NoPath error = leg.error();
      if (legs > 1) {
        error.message = "leg " + std::to_string(k + 1) + " of " + std::to_string(legs) + " (" +
                        PointName(k, via_m.size()) + " to " + PointName(k + 1, via_m.size()) +
                        "): " + error.message;
      }
      return tl::make_unexpected(error);
    }
    Append(route, *leg);
  }
  return route;
}

}  // namespace pitchlab::mission
