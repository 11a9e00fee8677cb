#pragma once
// Traversability (Eq. 3-5 inputs): which cells a P3 may stand on, and what entering each costs.
// Built once per plan from the elevation map's layers; the graph search only reads flat arrays.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"

namespace pitchlab::planning {

/// The weights of Eq. 5: cost of an edge u->v = W_T*T_v + W_P*P_uv + W_phix*|phi_x_v| +
/// W_phiy*|phi_y_v| (+ the unknown penalty), T [m], P [m] (Eq. 4: 3D length), phi [rad].
struct CostWeights {
  double roughness = 10.0;     ///< W_T [1/m]
  double length = 1.0;         ///< W_P [1/m]
  double inclination_x = 1.0;  ///< W_phix [1/rad]
  double inclination_y = 1.0;  ///< W_phiy [1/rad]
};

/// What a robot can drive over.
struct RobotLimits {
  std::string name = "p3at";
  double step_max_m = 0.089;  ///< highest step between neighbouring cells (or within one) [m]
  double max_inclination_rad = 0.3367;  ///< slip/tip limit of the cell's plane tilt [rad]
  double width_m = 0.497;               ///< footprint width: no path through a narrower gap [m]
  /// Footprint length [m]. With the width, what makes a grid coarser than the robot
  /// (CoarserThanRobot).
  double length_m = 0.508;
  /// Radius of the smallest wheel the robot stands on (a caster's, if it has one) [m]: how wide
  /// an unseen gap it rolls over without sinking more than step_max_m (MaxBridgedGap).
  double wheel_radius_m = 0.1075;

  /// Pioneer 3-AT (datasheet: 8.9 cm step, 35 % grade, 50.8 x 49.7 cm, 21.5 cm tyres).
  static RobotLimits P3AT();
  /// Pioneer 3-DX (datasheet: 2.5 cm step, 25 % grade, 45.5 x 38.1 cm; its rear caster's 8 cm
  /// wheel is the smallest).
  static RobotLimits P3DX();
  /// "p3at" or "p3dx"; throws std::invalid_argument naming the known presets otherwise.
  static RobotLimits Preset(const std::string& name);
};

/// What unknown cells are to the planner.
enum class UnknownPolicy { kForbid, kPenalise };

/// Everything a plan is configured by (YAML: see ParsePlannerConfig).
struct PlannerConfig {
  CostWeights weights;
  RobotLimits robot = RobotLimits::P3AT();
  UnknownPolicy unknown = UnknownPolicy::kForbid;
  double unknown_penalty = 1.0;  ///< added to an edge entering an unknown cell (kPenalise) [1]
  /// Soft clearance (a costmap's inflation): entering a free cell closer than clearance_m beyond
  /// the footprint's reach (kNearHazard) to a step, drop or steep cell costs up to clearance_cost
  /// more, falling linearly to 0 at clearance_m. Paths keep off hazards where the ground leaves
  /// room and still pass where it does not: a robot whose odometry slips while it drives needs
  /// the room. 0 (either): off, Eq. 5 as the paper has it.
  double clearance_m = 0.0;     ///< [m]
  double clearance_cost = 0.0;  ///< at the footprint's reach [1]

  /// Throws std::invalid_argument naming the field and value (negative weights, non-positive
  /// limits).
  void Validate() const;
};

/// Reads planner YAML (`source_name`, e.g. the file's path, names it in messages):
///   robot: p3at                  # preset (p3at | p3dx), then any of its fields overridden:
///   step_max_m: 0.089
///   max_inclination_deg: 19.3
///   width_m: 0.497
///   length_m: 0.508
///   wheel_radius_m: 0.1075
///   weights: {roughness: 10, length: 1, inclination_x: 1, inclination_y: 1}
///   unknown: forbid              # forbid | penalise
///   unknown_penalty: 1.0
///   clearance_m: 0.0             # soft clearance from hazards, and its cost at the footprint
///   clearance_cost: 0.0
/// Missing fields keep their defaults. Throws std::runtime_error naming the source, field and
/// value. A key given twice is the caller's to refuse (sensors::CheckUniqueYamlKeys, as the apps do).
PlannerConfig ParsePlannerConfig(const std::string& yaml_text, const std::string& source_name);

/// True when the grid's cells are larger than the robot's footprint (cell_m > max(width_m,
/// length_m)): the robot stands within one cell, the ground between two cell centres is unseen,
/// and BuildTraversability reads a rise between neighbouring cells as a slope (blocked, too steep,
/// when steeper than max_inclination; a step only where it exceeds step_max and that slope too),
/// not as a step (a 0.5 m rise between 3 m cells is a 9.5 deg slope). Finer grids keep the step
/// rule: the robot spans several cells and meets a rise between two at once.
bool CoarserThanRobot(const mapping::GridGeometry& geometry, const RobotLimits& robot);

/// The widest gap in the ground a wheel of `robot.wheel_radius_m` rolls over sinking no more than
/// `robot.step_max_m`: the chord 2 sqrt(r^2 - (r - step)^2) [m]. P3-AT 0.21 m; P3-DX (caster)
/// 0.07 m.
double MaxBridgedGap(const RobotLimits& robot);
/// What a user should know about planning on `geometry` with `robot`: empty for a grid finer than
/// the robot, else a warning that says what the planner does and what the map cannot show.
std::string CoarseGridWarning(const mapping::GridGeometry& geometry, const RobotLimits& robot);

/// Why a cell may not be entered.
enum class Blocked : std::uint8_t {
  kFree = 0,
  kUnknown,     ///< no data (with UnknownPolicy::kForbid)
  kDrop,        ///< a negative hazard
  kStep,        ///< a step above step_max_m to a neighbour, or within the cell
  kTooSteep,    ///< plane tilt above max_inclination_rad
  kNearHazard,  ///< within half the robot's width of a step, drop or steep cell or the grid's
                ///< edge (footprint)
  kOccupied,    ///< an obstacle in an occupancy grid (occupancy_grid.hpp)
};
/// A cell the robot's footprint must keep off (step, drop, too steep, occupied).
bool IsFootprintHazard(Blocked b);
const char* ToString(Blocked b);

/// The 8 moves of a cell, in the order of TraversabilityGrid::moves: x and y steps [cell].
inline constexpr int kMoveDi[8] = {1, -1, 0, 0, 1, 1, -1, -1};
inline constexpr int kMoveDj[8] = {0, 0, 1, -1, 1, -1, 1, -1};

/// The Eq. 4-5 costs of the 8 moves out of one cell, in the order of kMoveDi/kMoveDj, when the
/// cell's move mask allows them, +inf when not (blocked target, cut corner, off the grid): a search
/// compares all 8 offers with the neighbours' labels without reading the mask, and a forbidden
/// offer never wins [1]. In float (relative rounding 6e-8), so that a search reads 32 bytes per
/// cell instead of gathering 8 heights and entry costs and taking 8 square roots; aligned to 32
/// bytes so that they are always half of one cache line (16-byte aligned, every other cell's costs
/// straddled two lines: 20 % slower searches). Every cost of a path, of the peer graph (ListEdges)
/// and of EvaluatePath (which costs forbidden moves too, from the same definition) agrees with
/// these to the last bit.
struct alignas(32) MoveCosts {
  float to[8];
  float operator[](int b) const { return to[b]; }
};
static_assert(sizeof(MoveCosts) == 32, "a cell's move costs are half a cache line");

/// The planning graph's per-cell data: 8-connected cells of the map's geometry.
struct TraversabilityGrid {
  mapping::GridGeometry geometry;
  PlannerConfig config;
  std::vector<float> z_m;          ///< cell height for P and steps [m]; NaN unknown
  std::vector<float> enter_cost;   ///< W_T*T + W_phix*|phi_x| + W_phiy*|phi_y| (+ penalty) [1]
  std::vector<float> roughness_m;  ///< T [m] (0 when unknown)
  std::vector<float> phi_x_rad, phi_y_rad;  ///< [rad] (0 when unknown)
  /// An occupancy grid's grey-level cost of entering each cell [1]; empty for elevation maps.
  std::vector<float> occupancy_cost;
  std::vector<Blocked> blocked;
  /// Bit b set: the move to neighbour b is allowed (target free, no blocked corner cut); order
  /// +x, -x, +y, -y, (+x+y), (+x-y), (-x+y), (-x-y). Computed for every cell.
  std::vector<std::uint8_t> moves;
  /// Eq. 4-5 costs of the moves out of every cell (see MoveCosts).
  std::vector<MoveCosts> move_cost;
  /// Eq. 4-5 costs of the moves out of cells a search may expand (free cells, and unknown ones as
  /// a start):
  double min_straight_cost = 0;  ///< cheapest move along x or y, +inf if none [1]
  double min_diagonal_cost = 0;  ///< cheapest diagonal move, +inf if none [1]
  double max_edge_cost = 0;      ///< dearest allowed move, 0 if none [1]
  float min_enter_cost = 0;      ///< cheapest entry cost of a free cell [1]
  /// Unknown cells read as ground because they are a gap between scan lines the robot's wheels
  /// roll over (BuildTraversability, "Gaps between scan lines") [1].
  std::size_t bridged_cells = 0;
  /// Bridged cells of a gap wider, between the points that bound it, than the wheels span
  /// (MaxBridgedGap): ground only if the gap lies between scan lines, as it does at range (lines
  /// meet a floor h below the laser d^2 dtheta / h apart). A crack or a hole looks the same from
  /// afar; a look from where the lines are denser than the cells tells them apart.
  std::vector<bool> line_gap;

  bool Free(std::size_t k) const { return blocked[k] == Blocked::kFree; }
  /// Plane tilt of cell k, atan(sqrt(tan^2 phi_x + tan^2 phi_y)) [rad]; 0 where the inclination
  /// is unknown (phi held at 0).
  double Tilt(std::size_t k) const;
};

/// How far the footprint reaches: a cell whose centre is closer than this to a hazard cell's
/// centre puts the robot over it, and is kNearHazard (half the robot's width, plus half a cell for
/// the hazard's edge) [m].
double FootprintReach(const TraversabilityGrid& grid);

/// The cells the robot can reach from `start_m` (map frame [m]) by the moves `grid` allows
/// (TraversabilityGrid::moves: into free cells, no blocked corner cut), its start cell included;
/// none when the start is off the grid. Throws std::invalid_argument when `grid` has no moves.
std::vector<bool> ReachableCells(const TraversabilityGrid& grid, const Eigen::Vector2d& start_m);

/// Classifies every cell and precomputes its entry cost. Throws std::invalid_argument on a bad
/// config.
TraversabilityGrid BuildTraversability(const mapping::ElevationLayers& layers,
                                       const PlannerConfig& config);

/// The same into `grid`, reusing its buffers (about 40 bytes a cell): a caller that plans on the
/// same map at every stop allocates them (and the kernel clears their pages) once.
void BuildTraversabilityInto(const mapping::ElevationLayers& layers, const PlannerConfig& config,
                             TraversabilityGrid& grid);

}  // namespace pitchlab::planning
