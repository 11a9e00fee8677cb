#include "pitchlab/planning/traversability.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "finish_traversability.hpp"
#include "scan_gaps.hpp"
#include "move_cost.hpp"

namespace pitchlab::planning {
namespace {

using mapping::CellIndex;
using mapping::CellState;
using mapping::ElevationLayers;
using mapping::GridGeometry;

constexpr double kDegToRad = M_PI / 180.0;

std::string Named(const std::string& source, const std::string& field, const std::string& why) {
  return source + ": field '" + field + "': " + why;
}

template <typename T>
void Read(const YAML::Node& node, const std::string& key, const std::string& source, T* out) {
  if (!node[key]) return;
  try {
    *out = node[key].as<T>();
  } catch (const YAML::Exception&) {
    throw std::runtime_error(
        Named(source, key, "not a valid value ('" + YAML::Dump(node[key]) + "')"));
  }
}

// A step inside a cell leaves about a quarter of its height as the RMS residual of the cell's
// points about their plane (0.035 m for urban's 0.14 m curbs on a cell edge, where the cell's
// mean sits half way up and splits the curb into two steps under the limit); ground within the
// robot's limits leaves millimetres (p99 0.022 m on terrain's rough slopes at 0.2 m cells).
constexpr double kResidualPerStep = 0.25;

// Steps within a cell (something sticking up or down from its mean, or points off their plane by
// a step's residual), or this cell standing higher than an observed neighbour by more than
// step_max: the upper side of a step is the hazard cell (a wall, a curb's top, a cliff's edge),
// so gaps keep their true width before inflation. On a grid coarser than the robot
// (CoarserThanRobot) a rise between neighbours d apart is a slope: kTooSteep beyond
// d tan(max_inclination) (and step_max), and a cell's own points may spread by a slope at that
// limit over its half diagonal as well as by a step.
Blocked StepOrSlope(const ElevationLayers& L, int i, int j, const RobotLimits& robot) {
  const GridGeometry& g = L.geometry;
  const std::size_t k = g.Linear({i, j});
  const double step_max = robot.step_max_m;
  const bool coarse = CoarserThanRobot(g, robot);
  const double max_grade = std::tan(robot.max_inclination_rad);
  const double in_cell = step_max + (coarse ? M_SQRT1_2 * g.cell_m * max_grade : 0.0);
  const float z = L.mean_z[k];
  if (L.max_z[k] - z > in_cell || z - L.min_z[k] > in_cell) return Blocked::kStep;
  // NaN: no verdict; layers built by hand may leave the residual out. A step over the limit
  // inside the cell, both sides seen, puts its points at least that far apart; without that
  // spread the residual is noise, or two views of the same ground a pose error apart (the real
  // 3DTK corridor's two scans: cells where both lie 3-6 cm apart leave a 2.2-2.9 cm residual, a
  // row of "steps" across a flat floor).
  if (k < L.plane_residual.size() && L.plane_residual[k] > kResidualPerStep * step_max &&
      L.max_z[k] - L.min_z[k] > step_max)
    return Blocked::kStep;
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      const CellIndex nb{i + di, j + dj};
      if ((di == 0 && dj == 0) || !g.Contains(nb)) continue;
      const std::size_t kn = g.Linear(nb);
      if (L.state[kn] != CellState::kObserved) continue;
      const double rise = z - L.mean_z[kn];
      if (!coarse) {
        if (rise > step_max) return Blocked::kStep;
        continue;
      }
      const double slope_rise = std::hypot(di, dj) * g.cell_m * max_grade;
      if (rise > std::max(step_max, slope_rise))
        return slope_rise >= step_max ? Blocked::kTooSteep : Blocked::kStep;
    }
  return Blocked::kFree;
}

// The hazard cells that border a non-hazard cell: the only ones a disc around them can reach
// beyond the hazard itself.
std::vector<std::size_t> HazardBorder(const TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  std::vector<std::size_t> border;
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      if (!IsFootprintHazard(T.blocked[k])) continue;
      bool edge = false;
      for (const auto& [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const CellIndex nb{i + di, j + dj};
        edge |= g.Contains(nb) && !IsFootprintHazard(T.blocked[g.Linear(nb)]);
      }
      if (edge) border.push_back(k);
    }
  return border;
}

// Cell offsets (not the centre) closer than reach_m [m].
std::vector<std::pair<int, int>> Disc(double reach_m, double cell_m) {
  const int r = static_cast<int>(std::ceil(reach_m / cell_m));
  std::vector<std::pair<int, int>> disc;
  for (int dj = -r; dj <= r; ++dj)
    for (int di = -r; di <= r; ++di)
      if (std::hypot(di, dj) * cell_m < reach_m - 1e-9 && (di || dj)) disc.emplace_back(di, dj);
  return disc;
}

// How far the footprint reaches: a cell whose centre is closer than this to a hazard cell's
// centre puts the robot over it (half the width, plus half a cell for the hazard's edge) [m].
double FootprintReach(const TraversabilityGrid& T) {
  return 0.5 * T.config.robot.width_m + 0.5 * T.geometry.cell_m;
}

// Footprint: every free cell whose centre is closer than the footprint's reach to the centre of
// a hazard cell is blocked. Stamps a disc around the hazard cells that border a non-hazard cell.
void InflateHazards(TraversabilityGrid& T, const std::vector<std::size_t>& border) {
  const GridGeometry& g = T.geometry;
  const double reach_m = FootprintReach(T);
  const std::vector<std::pair<int, int>> disc = Disc(reach_m, g.cell_m);
  const auto near = [&](std::size_t k) {
    Blocked& b = T.blocked[k];
    if (b == Blocked::kFree || b == Blocked::kUnknown) b = Blocked::kNearHazard;
  };
  for (std::size_t k : border) {
    const CellIndex c = g.FromLinear(k);
    for (const auto& [di, dj] : disc) {
      const CellIndex nb{c.i + di, c.j + dj};
      if (g.Contains(nb)) near(g.Linear(nb));
    }
  }
  // Off the grid is nothing known to stand on (a DEM's or a world's edge): the footprint may not
  // hang over it (a terrain run drove off the world's edge along a path hugging the border).
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      const int cells_out = std::min({i, j, g.size_x - 1 - i, g.size_y - 1 - j}) + 1;
      if (cells_out * g.cell_m < reach_m - 1e-9) near(g.Linear({i, j}));
    }
}

// Soft clearance (PlannerConfig::clearance_m): the distance of every free cell's centre to the
// nearest hazard cell's centre, by the same stamping out to the footprint's reach plus the
// clearance, priced into its entry cost.
void AddClearanceCosts(TraversabilityGrid& T, const std::vector<std::size_t>& border) {
  const PlannerConfig& c = T.config;
  if (!(c.clearance_m > 0 && c.clearance_cost > 0)) return;
  const GridGeometry& g = T.geometry;
  const double reach_m = FootprintReach(T);
  const double outer_m = reach_m + c.clearance_m;
  std::vector<std::pair<int, int>> disc = Disc(outer_m, g.cell_m);
  // Only cells beyond the footprint's reach can be free; the inner ones were stamped blocked.
  std::vector<float> offset_m;
  std::vector<std::pair<int, int>> ring;
  for (const auto& [di, dj] : disc) {
    const double d = std::hypot(di, dj) * g.cell_m;
    if (d >= reach_m - 1e-9) ring.emplace_back(di, dj), offset_m.push_back(static_cast<float>(d));
  }
  std::vector<float> nearest_m(g.cell_count(), std::numeric_limits<float>::infinity());
  for (std::size_t k : border) {
    const CellIndex h = g.FromLinear(k);
    for (std::size_t o = 0; o < ring.size(); ++o) {
      const CellIndex nb{h.i + ring[o].first, h.j + ring[o].second};
      if (!g.Contains(nb)) continue;
      float& d = nearest_m[g.Linear(nb)];
      d = std::min(d, offset_m[o]);
    }
  }
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    if (!T.Free(k) || !std::isfinite(nearest_m[k])) continue;
    const double beyond = std::max(0.0, nearest_m[k] - reach_m);
    T.enter_cost[k] += static_cast<float>(c.clearance_cost * (1.0 - beyond / c.clearance_m));
  }
}

// The 8-neighbour move mask of every cell (see TraversabilityGrid::moves).
void ComputeMoves(TraversabilityGrid& T) {
  const int* kDi = kMoveDi;
  const int* kDj = kMoveDj;
  const GridGeometry& g = T.geometry;
  T.moves.assign(g.cell_count(), 0);
  const auto free = [&](int i, int j) { return g.Contains({i, j}) && T.Free(g.Linear({i, j})); };
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      std::uint8_t m = 0;
      for (int b = 0; b < 8; ++b) {
        const bool ok =
            free(i + kDi[b], j + kDj[b]) && (b < 4 || (free(i + kDi[b], j) && free(i, j + kDj[b])));
        m |= static_cast<std::uint8_t>(ok) << b;
      }
      T.moves[g.Linear({i, j})] = m;
    }
}

// Eq. 4-5 for move b out of cell (i, j), whether allowed or not, rounded to float: the one
// definition behind MoveCostOf and TraversabilityGrid::move_cost; +inf off the grid [1].
float MoveCostAt(const TraversabilityGrid& T, int i, int j, int b) {
  const GridGeometry& g = T.geometry;
  const CellIndex nb{i + kMoveDi[b], j + kMoveDj[b]};
  if (!g.Contains(nb)) return std::numeric_limits<float>::infinity();
  const std::size_t k = g.Linear({i, j}), kn = g.Linear(nb);
  const float za = T.z_m[k], zb = T.z_m[kn];
  const double dz = (std::isfinite(za) && std::isfinite(zb)) ? double(zb) - za : 0.0;
  const double d_m = (b < 4 ? 1.0 : M_SQRT2) * g.cell_m;
  // Eq. 5 with Eq. 4's P, the 3D length between the cell centres (dz = 0 when a height is unknown).
  return static_cast<float>(T.enter_cost[kn] +
                            T.config.weights.length * std::sqrt(d_m * d_m + dz * dz));
}

// The Eq. 4-5 cost of every allowed move of every cell, +inf for the others
// (TraversabilityGrid::move_cost).
void ComputeMoveCosts(TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  MoveCosts none;
  std::fill(std::begin(none.to), std::end(none.to), std::numeric_limits<float>::infinity());
  T.move_cost.assign(g.cell_count(), none);
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      for (int b = 0; b < 8; ++b)
        if (T.moves[k] >> b & 1) T.move_cost[k].to[b] = MoveCostAt(T, i, j, b);
    }
}

// The extremes of the allowed moves' costs that the searches need: the A* heuristic's per-move
// lower bounds and the bucket queue's span.
void ComputeMoveCostRange(TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // In locals, not in T's fields: the compiler cannot keep those in registers across the stores
  // into T (a chain of loads and stores through memory took a third of FinishTraversability).
  double min_straight = kInf, min_diagonal = kInf, max_edge = 0;
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    const bool source = T.Free(k) || T.blocked[k] == Blocked::kUnknown;
    if (!source) continue;
    for (int b = 0; b < 8; ++b) {
      if (!(T.moves[k] >> b & 1)) continue;
      const double c = T.move_cost[k][b];
      double& lo = b < 4 ? min_straight : min_diagonal;
      lo = std::min(lo, c);
      max_edge = std::max(max_edge, c);
    }
  }
  T.min_straight_cost = min_straight;
  T.min_diagonal_cost = min_diagonal;
  T.max_edge_cost = max_edge;
}

}  // namespace

float MoveCostOf(const TraversabilityGrid& T, std::size_t k, int b) {
  const CellIndex c = T.geometry.FromLinear(k);
  return MoveCostAt(T, c.i, c.j, b);
}

RobotLimits RobotLimits::P3AT() {
  return {"p3at", 0.089, std::atan(0.35), 0.497, 0.508, 0.1075};
}
RobotLimits RobotLimits::P3DX() {
  return {"p3dx", 0.025, std::atan(0.25), 0.381, 0.455, 0.04};
}
RobotLimits RobotLimits::Preset(const std::string& name) {
  if (name == "p3at") return P3AT();
  if (name == "p3dx") return P3DX();
  throw std::invalid_argument("unknown robot '" + name + "'; known: p3at, p3dx");
}

void PlannerConfig::Validate() const {
  const auto check = [](bool ok, const std::string& field, double v) {
    if (!ok)
      throw std::invalid_argument("planner config: " + field + " = " + std::to_string(v) +
                                  " is out of range");
  };
  check(weights.roughness >= 0, "weights.roughness", weights.roughness);
  check(weights.length > 0, "weights.length", weights.length);
  check(weights.inclination_x >= 0, "weights.inclination_x", weights.inclination_x);
  check(weights.inclination_y >= 0, "weights.inclination_y", weights.inclination_y);
  check(robot.step_max_m > 0, "step_max_m", robot.step_max_m);
  check(robot.max_inclination_rad > 0 && robot.max_inclination_rad < M_PI / 2, "max_inclination",
        robot.max_inclination_rad);
  check(robot.width_m >= 0, "width_m", robot.width_m);
  check(robot.length_m > 0, "length_m", robot.length_m);
  check(robot.wheel_radius_m > 0, "wheel_radius_m", robot.wheel_radius_m);
  check(unknown_penalty >= 0, "unknown_penalty", unknown_penalty);
  check(clearance_m >= 0 && clearance_m <= 10, "clearance_m", clearance_m);
  check(clearance_cost >= 0, "clearance_cost", clearance_cost);
}

PlannerConfig ParsePlannerConfig(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ": not valid YAML: " + e.what());
  }
  PlannerConfig c;
  if (!root || root.IsNull()) return c;
  if (!root.IsMap()) throw std::runtime_error(source + ": expected a mapping at the top level");
  std::string robot = "p3at";
  Read(root, "robot", source, &robot);
  try {
    c.robot = RobotLimits::Preset(robot);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(Named(source, "robot", e.what()));
  }
  Read(root, "step_max_m", source, &c.robot.step_max_m);
  double incl_deg = c.robot.max_inclination_rad / kDegToRad;
  Read(root, "max_inclination_deg", source, &incl_deg);
  c.robot.max_inclination_rad = incl_deg * kDegToRad;
  Read(root, "width_m", source, &c.robot.width_m);
  Read(root, "length_m", source, &c.robot.length_m);
  Read(root, "wheel_radius_m", source, &c.robot.wheel_radius_m);
  if (const YAML::Node w = root["weights"]) {
    Read(w, "roughness", source, &c.weights.roughness);
    Read(w, "length", source, &c.weights.length);
    Read(w, "inclination_x", source, &c.weights.inclination_x);
    Read(w, "inclination_y", source, &c.weights.inclination_y);
  }
  std::string unknown = "forbid";
  Read(root, "unknown", source, &unknown);
  if (unknown == "forbid") {
    c.unknown = UnknownPolicy::kForbid;
  } else if (unknown == "penalise" || unknown == "penalize") {
    c.unknown = UnknownPolicy::kPenalise;
  } else {
    throw std::runtime_error(
        Named(source, "unknown", "'" + unknown + "' is not forbid or penalise"));
  }
  Read(root, "unknown_penalty", source, &c.unknown_penalty);
  Read(root, "clearance_m", source, &c.clearance_m);
  Read(root, "clearance_cost", source, &c.clearance_cost);
  try {
    c.Validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(source + ": " + e.what());
  }
  return c;
}

const char* ToString(Blocked b) {
  switch (b) {
    case Blocked::kFree:
      return "free";
    case Blocked::kUnknown:
      return "unknown";
    case Blocked::kDrop:
      return "drop";
    case Blocked::kStep:
      return "step";
    case Blocked::kTooSteep:
      return "too steep";
    case Blocked::kNearHazard:
      return "closer to a hazard than half the robot's width";
    case Blocked::kOccupied:
      return "occupied";
  }
  return "?";
}

TraversabilityGrid BuildTraversability(const ElevationLayers& L, const PlannerConfig& config) {
  TraversabilityGrid T;
  BuildTraversabilityInto(L, config, T);
  return T;
}

double TraversabilityGrid::Tilt(std::size_t k) const {
  return std::atan(std::hypot(std::tan(phi_x_rad[k]), std::tan(phi_y_rad[k])));
}

void BuildTraversabilityInto(const ElevationLayers& L, const PlannerConfig& config,
                             TraversabilityGrid& T) {
  config.Validate();
  const GridGeometry& g = L.geometry;
  StartTraversability(g, config, T);
  const CostWeights& w = config.weights;
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      const std::size_t k = g.Linear({i, j});
      if (L.state[k] == CellState::kDrop) {
        T.blocked[k] = Blocked::kDrop;
        continue;
      }
      if (L.state[k] == CellState::kUnknown) {
        T.blocked[k] =
            config.unknown == UnknownPolicy::kForbid ? Blocked::kUnknown : Blocked::kFree;
        T.enter_cost[k] = static_cast<float>(config.unknown_penalty);
        continue;
      }
      T.z_m[k] = L.mean_z[k];
      T.roughness_m[k] = L.roughness[k];
      const bool incl_known = std::isfinite(L.phi_x[k]) && std::isfinite(L.phi_y[k]);
      T.phi_x_rad[k] = incl_known ? L.phi_x[k] : 0.0f;
      T.phi_y_rad[k] = incl_known ? L.phi_y[k] : 0.0f;
      // Eq. 5 without the length term, which depends on the edge.
      T.enter_cost[k] = static_cast<float>(w.roughness * T.roughness_m[k] +
                                           w.inclination_x * std::abs(T.phi_x_rad[k]) +
                                           w.inclination_y * std::abs(T.phi_y_rad[k]));
      if (incl_known && L.Tilt(k) > config.robot.max_inclination_rad) {
        T.blocked[k] = Blocked::kTooSteep;
      } else if (const Blocked b = StepOrSlope(L, i, j, config.robot); b != Blocked::kFree) {
        T.blocked[k] = b;
      } else if (!incl_known) {
        // Seen, but the scan did not determine its slope (one or two far points, grazing lines:
        // LayerConfig's support rule): as steep as anything for all we know, so the unknown
        // policy decides, as for a cell never seen (terrain seed 12 tipped over at 33.8 deg where
        // such cells had counted as level).
        if (config.unknown == UnknownPolicy::kForbid) T.blocked[k] = Blocked::kUnknown;
        T.enter_cost[k] += static_cast<float>(config.unknown_penalty);
      }
    }
  T.bridged_cells = BridgeScanGaps(L, T);
  FinishTraversability(T);
}

void StartTraversability(const GridGeometry& g, const PlannerConfig& config,
                         TraversabilityGrid& T) {
  const std::size_t n = g.cell_count();
  T.geometry = g;
  T.config = config;
  T.occupancy_cost.clear();
  T.z_m.assign(n, std::numeric_limits<float>::quiet_NaN());
  T.enter_cost.assign(n, 0.0f);
  T.roughness_m.assign(n, 0.0f);
  T.phi_x_rad.assign(n, 0.0f);
  T.phi_y_rad.assign(n, 0.0f);
  T.blocked.assign(n, Blocked::kFree);
  T.line_gap.assign(n, false);
}

void FinishTraversability(TraversabilityGrid& T) {
  const std::vector<std::size_t> border = HazardBorder(T);
  InflateHazards(T, border);
  AddClearanceCosts(T, border);
  ComputeMoves(T);
  ComputeMoveCosts(T);
  ComputeMoveCostRange(T);
  float min_cost = std::numeric_limits<float>::infinity();
  for (std::size_t k = 0; k < T.geometry.cell_count(); ++k)
    if (T.Free(k)) min_cost = std::min(min_cost, T.enter_cost[k]);
  T.min_enter_cost = std::isfinite(min_cost) ? min_cost : 0.0f;
}

bool IsFootprintHazard(Blocked b) {
  return b == Blocked::kDrop || b == Blocked::kStep || b == Blocked::kTooSteep ||
         b == Blocked::kOccupied;
}

double MaxBridgedGap(const RobotLimits& robot) {
  const double r = robot.wheel_radius_m, sink = std::min(robot.step_max_m, r);
  return 2.0 * std::sqrt(r * r - (r - sink) * (r - sink));
}

bool CoarserThanRobot(const GridGeometry& geometry, const RobotLimits& robot) {
  return geometry.cell_m > std::max(robot.width_m, robot.length_m);
}

std::string CoarseGridWarning(const GridGeometry& g, const RobotLimits& robot) {
  if (!CoarserThanRobot(g, robot)) return "";
  char text[640];
  std::snprintf(text, sizeof(text),
                "the map's %g m cells are coarser than the robot (%s, %g x %g m): each cell is "
                "one height under the whole robot, so a rise between neighbouring cells is read "
                "as a slope (too steep beyond %.1f deg), not as a step (%g m); rocks, curbs, "
                "ditches and walls narrower than a cell are not in the map, and the footprint's "
                "margin (%g m) is less than a cell: check the path on the ground",
                g.cell_m, robot.name.c_str(), robot.length_m, robot.width_m,
                robot.max_inclination_rad * 180 / M_PI, robot.step_max_m, 0.5 * robot.width_m);
  return text;
}

}  // namespace pitchlab::planning
