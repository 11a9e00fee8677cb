#pragma once
// Algorithm 2: the least-cost path over 8-connected cells (Eq. 5 edge costs), by Dijkstra (as
// in the paper) or A* with an admissible, consistent heuristic; both return the optimal cost.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <tl/expected.hpp>

#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::planning {

enum class Algorithm { kDijkstra, kAStar };
/// "dijkstra" / "astar"; throws std::invalid_argument otherwise.
Algorithm ParseAlgorithm(const std::string& name);
const char* ToString(Algorithm a);

/// A point of the path: a cell centre at its height [m] (z NaN in an unknown cell).
struct Waypoint {
  double x_m = 0, y_m = 0, z_m = 0;
};

/// The terms of Eq. 5 summed over the path's edges.
struct CostParts {
  double roughness = 0;      ///< sum W_T * T [1]
  double length = 0;         ///< sum W_P * P [1]
  double inclination_x = 0;  ///< sum W_phix * |phi_x| [1]
  double inclination_y = 0;  ///< sum W_phiy * |phi_y| [1]
  double unknown = 0;        ///< sum of unknown-cell penalties [1]
  double occupancy = 0;  ///< sum of an occupancy grid's grey-level costs (occupancy_grid.hpp) [1]
  double Total() const {
    return roughness + length + inclination_x + inclination_y + unknown + occupancy;
  }
};

/// A found path.
struct Path {
  Algorithm algorithm = Algorithm::kDijkstra;
  std::vector<mapping::CellIndex> cells;  ///< start to goal
  std::vector<Waypoint> waypoints;        ///< the cells' centres
  double cost = 0;                        ///< optimal Eq. 5 cost, as the search summed it [1]
  CostParts parts;                        ///< its terms
  double length_m = 0;                    ///< 3D length, sum of P [m]
  double max_step_m = 0;                  ///< largest |dz| between consecutive cells [m]
  double max_inclination_rad = 0;         ///< largest plane tilt of a path cell [rad]
  /// Cells expanded by the search; a cell lowered after its expansion (A*, rarely: its bucket
  /// queue is label-correcting) counts again [1].
  std::size_t expanded = 0;
};

/// Why there is no path.
struct NoPath {
  enum class Reason {
    kStartOutsideMap,
    kGoalOutsideMap,
    kStartBlocked,
    kGoalBlocked,
    kDisconnected
  };
  Reason reason = Reason::kDisconnected;
  std::string message;  ///< names the point and the blocking cause
};
const char* ToString(NoPath::Reason r);

/// Plans from `start` to `goal` (map frame [m]). The start cell may be unknown (the robot's own
/// cell is rarely seen by its laser); every other rule of BuildTraversability holds.
tl::expected<Path, NoPath> PlanPath(const TraversabilityGrid& grid, const Eigen::Vector2d& start_m,
                                    const Eigen::Vector2d& goal_m, Algorithm algorithm);

/// One directed edge of the planning graph with its Eq. 5 cost (for peer implementations).
struct GraphEdge {
  std::uint32_t from = 0, to = 0;  ///< linear cell indices
  double cost = 0;                 ///< [1]
};
/// Every edge PlanPath may take between free cells, each with its Eq. 5 cost.
std::vector<GraphEdge> ListEdges(const TraversabilityGrid& grid);
/// Eq. 5 cost of the edge from cell a to its 8-neighbour b, with its parts; NaN when not allowed.
double EdgeCost(const TraversabilityGrid& grid, std::size_t a, std::size_t b,
                CostParts* parts = nullptr);

/// A path's cost on another map's grid (the true one): the cost, and how many of its cells
/// that map forbids (same geometry required; throws std::invalid_argument otherwise).
struct PathOnMap {
  double cost = 0;  ///< Eq. 5 summed with `grid`'s costs; forbidden edges still count
  std::size_t forbidden_cells = 0;  ///< path cells blocked in `grid` (start excluded) [1]
  std::size_t unknown_cells = 0;    ///< path cells unknown in `grid` [1]
};
PathOnMap EvaluatePath(const TraversabilityGrid& grid, const Path& path);

}  // namespace pitchlab::planning
