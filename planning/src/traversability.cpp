#include "pitchlab/planning/traversability.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "finish_traversability.hpp"
#include "scan_gaps.hpp"
#include "move_cost.hpp"
#include "pitchlab/mapping/parallel_for.hpp"

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

// The cell's second lowest and second highest point, where the layers hold them (built by hand
// they may not), else its extremes.
float NextMin(const ElevationLayers& L, std::size_t k) {
  return k < L.next_min_z.size() ? L.next_min_z[k] : L.min_z[k];
}
float NextMax(const ElevationLayers& L, std::size_t k) {
  return k < L.next_max_z.size() ? L.next_max_z[k] : L.max_z[k];
}

// Steps within a cell (something sticking up or down from its mean, or points off their plane by
// a step's residual), or this cell standing higher than an observed neighbour by more than
// step_max: the upper side of a step is the hazard cell (a wall, a curb's top, a cliff's edge),
// so gaps keep their true width before inflation. On a grid coarser than the robot
// (CoarserThanRobot) a rise between neighbours d apart is a slope: kTooSteep beyond
// d tan(max_inclination) (and step_max), and a cell's own points may spread by a slope at that
// limit over its half diagonal as well as by a step.
// A step needs support, as a slope does (LayerConfig's max_slope_error): a rise between two cell
// means counts only where it exceeds step_max by twice its standard error, the layers' point
// noise times sqrt(1/n + 1/n') (two single far points of a floor: 2.8 cm at 2 cm a point), and a
// spread within a cell of two points, and the points' span behind the residual rule, only by twice
// a point's noise (kDoubtful below: the unknown policy decides, and a closer look brings the
// points). The P3-DX's 2.5 cm step limit is within a far floor's noise: far cells of one or two
// points stood as steps, and its missions were walled in by floors they could drive on (office,
// cluttered, corridor seeds 1..4: 0 of 12 reached the goal).
// Within a cell of three points or more a step needs two of them beyond the limit (the second
// extremes): a step the scan saw has points along its face or on its top, while one point alone
// off a dense cell is a mixed pixel at a depth edge or an outlier (the P3-DX's office floors
// stood as steps where one point of a hundred lay 2.6-3.6 cm off the mean). That one point makes
// the cell doubtful, not free.
// `max_grade` is tan(robot.max_inclination_rad).
enum class StepVerdict { kNone, kStep, kTooSteep, kDoubtful };
StepVerdict StepOrSlope(const ElevationLayers& L, int i, int j, const RobotLimits& robot,
                        double max_grade) {
  const GridGeometry& g = L.geometry;
  const std::size_t k = g.Linear({i, j});
  const double step_max = robot.step_max_m;
  const bool coarse = CoarserThanRobot(g, robot);
  const double in_cell = step_max + (coarse ? M_SQRT1_2 * g.cell_m * max_grade : 0.0);
  const float z = L.mean_z[k];
  const double noise = coarse ? 0.0 : L.height_noise_m;
  const bool dense = L.count[k] > 2;
  bool doubtful = false;
  const double spread = std::max(L.max_z[k] - z, z - L.min_z[k]);
  if (spread > in_cell) {
    const double spread_of_two = std::max(NextMax(L, k) - z, z - NextMin(L, k));
    if (dense ? spread_of_two > in_cell : spread > in_cell + 2 * noise) return StepVerdict::kStep;
    doubtful = true;
  }
  // NaN: no verdict; layers built by hand may leave the residual out. A step over the limit
  // inside the cell, both sides seen, puts its points at least that far apart; without that
  // spread the residual is noise, or two views of the same ground a pose error apart (the real
  // 3DTK corridor's two scans: cells where both lie 3-6 cm apart leave a 2.2-2.9 cm residual, a
  // row of "steps" across a flat floor).
  if (k < L.plane_residual.size() && L.plane_residual[k] > kResidualPerStep * step_max &&
      L.max_z[k] - L.min_z[k] > step_max) {
    if (NextMax(L, k) - NextMin(L, k) > step_max + 2 * noise) return StepVerdict::kStep;
    doubtful = true;
  }
  const double n = std::max<std::uint32_t>(L.count[k], 1);
  for (int dj = -1; dj <= 1; ++dj)
    for (int di = -1; di <= 1; ++di) {
      const CellIndex nb{i + di, j + dj};
      if ((di == 0 && dj == 0) || !g.Contains(nb)) continue;
      const std::size_t kn = g.Linear(nb);
      if (L.state[kn] != CellState::kObserved) continue;
      const double rise = z - L.mean_z[kn];
      if (!coarse) {
        if (rise <= step_max) continue;
        const double nn = std::max<std::uint32_t>(L.count[kn], 1);
        if (rise > step_max + 2 * noise * std::sqrt(1 / n + 1 / nn)) return StepVerdict::kStep;
        doubtful = true;
        continue;
      }
      const double slope_rise = std::hypot(di, dj) * g.cell_m * max_grade;
      if (rise > std::max(step_max, slope_rise))
        return slope_rise >= step_max ? StepVerdict::kTooSteep : StepVerdict::kStep;
    }
  return doubtful ? StepVerdict::kDoubtful : StepVerdict::kNone;
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
  // A cell is cells_out = min(i, j, size_x - 1 - i, size_y - 1 - j) + 1 cells from the edge, and
  // the test grows with cells_out: the cells with cells_out <= band, a frame `band` cells wide.
  int band = 0;
  while ((band + 1) * g.cell_m < reach_m - 1e-9) ++band;
  for (int j = 0; j < g.size_y; ++j) {
    const bool edge_row = std::min(j, g.size_y - 1 - j) < band;
    for (int i = 0; i < g.size_x; ++i) {
      if (!edge_row && i == band) i = std::max(band, g.size_x - band);  // skip the inside
      if (i >= g.size_x) break;
      near(g.Linear({i, j}));
    }
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
  // Kept between calls (a run builds a grid or two every stop): a fresh 4-byte-per-cell buffer
  // costs its pages' clearing by the kernel each time.
  thread_local std::vector<float> nearest_m;
  nearest_m.assign(g.cell_count(), std::numeric_limits<float>::infinity());
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

// The 8-neighbour move mask of every cell (see TraversabilityGrid::moves). Inside the grid's
// one-cell frame every neighbour exists and a move's cells are a fixed offset away.
void ComputeMoves(TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  const int sx = g.size_x, sy = g.size_y;
  T.moves.assign(g.cell_count(), 0);
  const auto free = [&](int i, int j) { return g.Contains({i, j}) && T.Free(g.Linear({i, j})); };
  const auto edge_cell = [&](int i, int j) {
    std::uint8_t m = 0;
    for (int b = 0; b < 8; ++b) {
      const bool ok = free(i + kMoveDi[b], j + kMoveDj[b]) &&
                      (b < 4 || (free(i + kMoveDi[b], j) && free(i, j + kMoveDj[b])));
      m |= static_cast<std::uint8_t>(ok) << b;
    }
    T.moves[g.Linear({i, j})] = m;
  };
  const Blocked* blocked = T.blocked.data();
  const std::ptrdiff_t row = g.Linear({0, 1}) - g.Linear({0, 0});
  std::ptrdiff_t offset[8];
  for (int b = 0; b < 8; ++b) offset[b] = kMoveDi[b] + kMoveDj[b] * row;
  mapping::ParallelRows(sy, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j) {
      if (j == 0 || j == sy - 1 || sx < 3) {
        for (int i = 0; i < sx; ++i) edge_cell(i, j);
        continue;
      }
      edge_cell(0, j);
      for (int i = 1; i < sx - 1; ++i) {
        const std::size_t k = g.Linear({i, j});
        const Blocked* c = blocked + k;
        const auto f = [c](std::ptrdiff_t o) { return c[o] == Blocked::kFree; };
        std::uint8_t m = 0;
        for (int b = 0; b < 8; ++b) {
          const bool ok = f(offset[b]) && (b < 4 || (f(kMoveDi[b]) && f(kMoveDj[b] * row)));
          m |= static_cast<std::uint8_t>(ok) << b;
        }
        T.moves[k] = m;
      }
      edge_cell(sx - 1, j);
    }
  });
}

// Move b's planar length between cell centres, squared [m^2], and as Eq. 4's P when the height
// does not change, sqrt(d^2 + 0^2) [m].
struct Step {
  double squared_m2, level_m;
};
Step StepOf(int b, double cell_m) {
  const double d_m = (b < 4 ? 1.0 : M_SQRT2) * cell_m, dz = 0.0;
  return {d_m * d_m, std::sqrt(d_m * d_m + dz * dz)};
}

// Eq. 5 with Eq. 4's P, the 3D length between the cell centres (dz = 0 when a height is unknown),
// rounded to float: the one definition behind MoveCostOf and TraversabilityGrid::move_cost. A
// level move takes the length computed once (the same double), sparing the square root.
float MoveCost(float enter_to, float z_from, float z_to, const Step& step, double w_length) {
  const double dz =
      (std::isfinite(z_from) && std::isfinite(z_to)) ? double(z_to) - z_from : 0.0;
  const double length_m = dz == 0.0 ? step.level_m : std::sqrt(step.squared_m2 + dz * dz);
  return static_cast<float>(enter_to + w_length * length_m);
}

// Eq. 4-5 for move b out of cell (i, j), whether allowed or not; +inf off the grid [1].
float MoveCostAt(const TraversabilityGrid& T, int i, int j, int b) {
  const GridGeometry& g = T.geometry;
  const CellIndex nb{i + kMoveDi[b], j + kMoveDj[b]};
  if (!g.Contains(nb)) return std::numeric_limits<float>::infinity();
  const std::size_t k = g.Linear({i, j}), kn = g.Linear(nb);
  return MoveCost(T.enter_cost[kn], T.z_m[k], T.z_m[kn], StepOf(b, g.cell_m),
                  T.config.weights.length);
}

// The Eq. 4-5 cost of every allowed move of every cell, +inf for the others
// (TraversabilityGrid::move_cost), and the extremes of the allowed moves' costs that the searches
// need: the A* heuristic's per-move lower bounds and the bucket queue's span, over the cells a
// search may expand (free ones, and unknown ones as a start).
void ComputeMoveCosts(TraversabilityGrid& T) {
  const GridGeometry& g = T.geometry;
  constexpr float kNone = std::numeric_limits<float>::infinity();
  T.move_cost.resize(g.cell_count());
  // In locals, not in T's fields: the compiler cannot keep those in registers across the stores
  // into T (a chain of loads and stores through memory took a third of FinishTraversability).
  // Each block's own, then combined: a minimum and a maximum do not depend on the order.
  struct Extremes {
    double min_straight = std::numeric_limits<double>::infinity();
    double min_diagonal = std::numeric_limits<double>::infinity();
    double max_edge = 0;
  };
  std::mutex mutex;
  Extremes all;
  // An allowed move's neighbour is on the grid (ComputeMoves), a fixed offset away.
  const std::ptrdiff_t row = g.Linear({0, 1}) - g.Linear({0, 0});
  std::ptrdiff_t offset[8];
  Step step[8];
  for (int b = 0; b < 8; ++b) {
    offset[b] = kMoveDi[b] + kMoveDj[b] * row;
    step[b] = StepOf(b, g.cell_m);
  }
  const double w_length = T.config.weights.length;
  const float* z = T.z_m.data();
  const float* enter = T.enter_cost.data();
  mapping::ParallelRows(g.size_y, [&](int j0, int j1) {
    double min_straight = std::numeric_limits<double>::infinity(), min_diagonal = min_straight;
    double max_edge = 0;
    for (int j = j0; j < j1; ++j)
      for (int i = 0; i < g.size_x; ++i) {
        const std::size_t k = g.Linear({i, j});
        const std::uint8_t m = T.moves[k];
        MoveCosts& out = T.move_cost[k];
        const bool source = T.Free(k) || T.blocked[k] == Blocked::kUnknown;
        for (int b = 0; b < 8; ++b) {
          if (!(m >> b & 1)) {
            out.to[b] = kNone;
            continue;
          }
          const std::size_t kn = k + offset[b];
          const float c = MoveCost(enter[kn], z[k], z[kn], step[b], w_length);
          out.to[b] = c;
          if (!source) continue;
          double& lo = b < 4 ? min_straight : min_diagonal;
          lo = std::min(lo, double{c});
          max_edge = std::max(max_edge, double{c});
        }
      }
    const std::lock_guard<std::mutex> lock(mutex);
    all.min_straight = std::min(all.min_straight, min_straight);
    all.min_diagonal = std::min(all.min_diagonal, min_diagonal);
    all.max_edge = std::max(all.max_edge, max_edge);
  });
  T.min_straight_cost = all.min_straight;
  T.min_diagonal_cost = all.min_diagonal;
  T.max_edge_cost = all.max_edge;
}

}  // namespace

double FootprintReach(const TraversabilityGrid& T) {
  return 0.5 * T.config.robot.width_m + 0.5 * T.geometry.cell_m;
}

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
  const double max_grade = std::tan(config.robot.max_inclination_rad);
  // L.Tilt(k) > the limit, i.e. atan(t) > limit for t = |(tan phi_x, tan phi_y)|: decided on t
  // against tan(limit) where t is more than 1e-5 (relative) from it, far beyond the float atan's
  // error, so the verdict is the same; atan only for the few cells at the limit itself.
  const double limit = config.robot.max_inclination_rad;
  const bool by_tan = limit > 0 && limit < 1.5;  // tan(limit) finite and well-conditioned
  const auto steeper = [&](std::size_t k) {
    if (by_tan) {
      const float tx = std::tan(L.phi_x[k]), ty = std::tan(L.phi_y[k]);
      const double t = std::sqrt(tx * tx + ty * ty);
      if (t < max_grade * (1 - 1e-5)) return false;
      if (t > max_grade * (1 + 1e-5)) return true;
    }
    return L.Tilt(k) > limit;
  };
  mapping::ParallelRows(g.size_y, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j)
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
        const bool steep = incl_known && steeper(k);
        const StepVerdict step =
            steep ? StepVerdict::kNone : StepOrSlope(L, i, j, config.robot, max_grade);
        if (steep) {
          T.blocked[k] = Blocked::kTooSteep;
        } else if (step == StepVerdict::kStep || step == StepVerdict::kTooSteep) {
          T.blocked[k] = step == StepVerdict::kStep ? Blocked::kStep : Blocked::kTooSteep;
        } else if (!incl_known || step == StepVerdict::kDoubtful) {
          // Seen, but the scan did not determine its slope (one or two far points, grazing lines:
          // LayerConfig's support rule) or whether a rise past step_max is a step: as steep as
          // anything for all we know, so the unknown policy decides, as for a cell never seen
          // (terrain seed 12 tipped over at 33.8 deg where such cells had counted as level).
          if (config.unknown == UnknownPolicy::kForbid) T.blocked[k] = Blocked::kUnknown;
          T.enter_cost[k] += static_cast<float>(config.unknown_penalty);
        }
      }
  });
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

std::vector<bool> ReachableCells(const TraversabilityGrid& grid, const Eigen::Vector2d& start_m) {
  const GridGeometry& g = grid.geometry;
  if (grid.moves.size() != g.cell_count()) {
    throw std::invalid_argument(
        "reachable cells: the grid has no moves (BuildTraversability makes them)");
  }
  std::vector<bool> reached(g.cell_count(), false);
  const CellIndex start = g.IndexOf(start_m.x(), start_m.y());
  if (!g.Contains(start)) return reached;
  std::vector<CellIndex> open{start};
  reached[g.Linear(start)] = true;
  while (!open.empty()) {
    const CellIndex c = open.back();
    open.pop_back();
    const std::uint8_t allowed = grid.moves[g.Linear(c)];
    for (int b = 0; b < 8; ++b) {
      if (!(allowed & (1u << b))) continue;
      const CellIndex n{c.i + kMoveDi[b], c.j + kMoveDj[b]};
      const std::size_t k = g.Linear(n);
      if (reached[k]) continue;
      reached[k] = true;
      open.push_back(n);
    }
  }
  return reached;
}

}  // namespace pitchlab::planning
