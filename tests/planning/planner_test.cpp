// Planner (Eq. 4-5, Algorithm 2): known optimal paths, footprint, no-path reasons, BGL peer cost.

#include <gtest/gtest.h>

#include <algorithm>
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/dijkstra_shortest_paths.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>

#include "pitchlab/planning/path_io.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "same_grids.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::planning {
namespace {

using mapping::CellIndex;
using mapping::ElevationLayers;
using mapping::ElevationMap;
using mapping::GridGeometry;

constexpr double kCostRelTol = 1e-9;

// One point per cell centre at height z(i, j); NaN leaves the cell unknown.
ElevationLayers MakeLayers(int sx, int sy, double cell, const std::function<double(int, int)>& z) {
  ElevationMap map(GridGeometry::FromArea(0, 0, sx * cell, sy * cell, cell));
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < sy; ++j)
    for (int i = 0; i < sx; ++i) {
      const double h = z(i, j);
      if (std::isnan(h)) continue;
      const Eigen::Vector2d c = map.geometry().CenterOf({i, j});
      pts.emplace_back(float(c.x()), float(c.y()), float(h));
    }
  (void)map.InsertPoints(pts.data(), pts.size());
  // Exact heights: the inclination's support is judged against a noise the data do not have
  // (LayerConfig::height_noise_m is a real laser's), which would leave the grid's edge rows,
  // fitted over two rows of cells only, without an inclination.
  mapping::LayerConfig exact;
  exact.height_noise_m = 1e-4;
  return mapping::ComputeLayers(map, exact);
}

PlannerConfig PointRobot() {
  PlannerConfig c;
  c.robot.width_m = 0.0;
  return c;
}

Eigen::Vector2d Centre(const TraversabilityGrid& T, int i, int j) {
  return T.geometry.CenterOf({i, j});
}

double BglCost(const TraversabilityGrid& T, std::size_t s, std::size_t t) {
  using Graph =
      boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, boost::no_property,
                            boost::property<boost::edge_weight_t, double>>;
  const std::vector<GraphEdge> edges = ListEdges(T);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ends;
  std::vector<double> w;
  for (const GraphEdge& e : edges) {
    ends.emplace_back(e.from, e.to);
    w.push_back(e.cost);
  }
  Graph g(ends.begin(), ends.end(), w.begin(), T.geometry.cell_count());
  std::vector<double> d(T.geometry.cell_count());
  boost::dijkstra_shortest_paths(g, s, boost::distance_map(d.data()));
  return d[t];
}

// Rough ground with scattered unknown cells and a few spikes (steps): every layer and every
// blocked kind has cells.
ElevationLayers RoughLayers(int sx, int sy, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  return MakeLayers(sx, sy, 0.1, [&](int i, int j) {
    if (u(rng) < 0.05) return std::nan("");
    return 0.08 * std::sin(0.3 * i) * std::cos(0.25 * j) + 0.01 * u(rng) +
           (u(rng) < 0.01 ? 0.3 : 0.0);
  });
}

TEST(BuildTraversabilityInto, AReusedGridEqualsAFreshOne) {
  const ElevationLayers before = RoughLayers(60, 50, 1), now = RoughLayers(48, 40, 2);
  PlannerConfig first;  // the P3-AT's footprint, unknown cells forbidden
  PlannerConfig second = PointRobot();
  second.unknown = UnknownPolicy::kPenalise;
  second.unknown_penalty = 0.5;
  TraversabilityGrid reused;
  BuildTraversabilityInto(before, first, reused);
  reused.occupancy_cost.assign(reused.z_m.size(), 7.0f);  // as an occupancy grid's would be
  BuildTraversabilityInto(now, second, reused);
  const TraversabilityGrid fresh = BuildTraversability(now, second);
  // Bit for bit, NaN included: a reused buffer must leave nothing of what it held.
  same_grids::ExpectSameTraversability(reused, fresh);
  EXPECT_EQ(reused.config.robot.width_m, fresh.config.robot.width_m);
  EXPECT_TRUE(reused.occupancy_cost.empty());
  // Both kinds of cell the first build had (hazards, unknown) are in this one too: the check
  // compared grids that differ from the first one's cell by cell.
  EXPECT_NE(std::count(fresh.blocked.begin(), fresh.blocked.end(), Blocked::kStep), 0);
  EXPECT_NE(std::count(fresh.blocked.begin(), fresh.blocked.end(), Blocked::kFree), 0);
}

TEST(ComputeLayersInto, AReusedSetOfLayersEqualsAFreshOne) {
  ElevationLayers reused = RoughLayers(60, 50, 3);  // bigger, other heights and unknown cells
  ElevationMap map(GridGeometry::FromArea(0, 0, 4.8, 4.0, 0.1));
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0, 1);
  std::vector<Eigen::Vector3f> pts;
  for (int n = 0; n < 4000; ++n) pts.emplace_back(4.8f * u(rng), 4.0f * u(rng), 0.05f * u(rng));
  (void)map.InsertPoints(pts.data(), pts.size());
  mapping::ComputeLayersInto(map, {}, reused);
  const ElevationLayers fresh = mapping::ComputeLayers(map);
  same_grids::ExpectSameLayers(reused, fresh);
}

TEST(Planner, SerpentineCorridorGivesItsUniqueOptimalPath) {
  // 1-cell corridor through unknown cells (forbidden): right along row 0, up column 6, left
  // along row 4. The only path; its cost is W_P * cell per edge on flat ground.
  const double cell = 0.2;
  const auto corridor = [](int i, int j) {
    return (j == 0 && i <= 6) || (i == 6 && j <= 4) || (j == 4 && i <= 6);
  };
  ElevationLayers L =
      MakeLayers(8, 6, cell, [&](int i, int j) { return corridor(i, j) ? 0.0 : std::nan(""); });
  // A line of ground one cell wide leaves its cross slope undetermined, and the planner hands
  // such cells to the unknown policy; this test is about the search, on ground level by
  // construction.
  for (std::size_t k = 0; k < L.phi_x.size(); ++k) {
    if (L.state[k] != mapping::CellState::kObserved) continue;
    L.phi_x[k] = L.phi_y[k] = 0.0f;
  }
  const TraversabilityGrid T = BuildTraversability(L, PointRobot());
  for (Algorithm a : {Algorithm::kDijkstra, Algorithm::kAStar}) {
    const auto path = PlanPath(T, Centre(T, 0, 0), Centre(T, 0, 4), a);
    ASSERT_TRUE(path) << path.error().message;
    ASSERT_EQ(path->cells.size(), 7u + 4u + 6u);
    EXPECT_EQ(path->cells[6], (CellIndex{6, 0}));
    EXPECT_EQ(path->cells[10], (CellIndex{6, 4}));
    // Move costs are stored in float (TraversabilityGrid::move_cost): 16 moves of float(cell).
    const double move = static_cast<float>(cell);
    EXPECT_NEAR(path->cost, 16 * move, 1e-12);
    EXPECT_NEAR(path->length_m, 16 * move, 1e-12);
    EXPECT_NEAR(path->parts.Total(), path->cost, 1e-9);
  }
}

// The same serpentine corridor and, apart from it, a three-cell island of ground (row 2, columns
// 0-2) no move leads to: from the corridor's start exactly the corridor's 17 cells are reached,
// from the island exactly the island's 3, from off the grid none.
TEST(ReachableCells, AreTheCellsTheAllowedMovesLeadTo) {
  const auto corridor = [](int i, int j) {
    return (j == 0 && i <= 6) || (i == 6 && j <= 4) || (j == 4 && i <= 6);
  };
  const auto island = [](int i, int j) { return j == 2 && i <= 2; };
  ElevationLayers L = MakeLayers(
      8, 6, 0.2, [&](int i, int j) { return corridor(i, j) || island(i, j) ? 0.0 : std::nan(""); });
  for (std::size_t k = 0; k < L.phi_x.size(); ++k) {  // level, as above
    if (L.state[k] != mapping::CellState::kObserved) continue;
    L.phi_x[k] = L.phi_y[k] = 0.0f;
  }
  const TraversabilityGrid T = BuildTraversability(L, PointRobot());
  const auto count_as = [&](const std::vector<bool>& reached, auto&& in) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < reached.size(); ++k) {
      const CellIndex c = T.geometry.FromLinear(k);
      EXPECT_EQ(reached[k], in(c.i, c.j)) << c.i << ", " << c.j;
      n += reached[k];
    }
    return n;
  };
  EXPECT_EQ(count_as(ReachableCells(T, Centre(T, 0, 0)), corridor), 17u);
  EXPECT_EQ(count_as(ReachableCells(T, Centre(T, 1, 2)), island), 3u);
  EXPECT_EQ(count_as(ReachableCells(T, {-1.0, 0.1}), [](int, int) { return false; }), 0u);
}

TEST(Planner, StraightRunOnTiltedGroundCostsEq5) {
  // Ground z = 0.1 x: a straight run along x is the unique optimum; every edge costs
  // W_T*0 + W_P*sqrt(c^2 + (0.1c)^2) + W_phix*atan(0.1) + W_phiy*0.
  const double cell = 0.1;
  const ElevationLayers L =
      MakeLayers(20, 5, cell, [&](int i, int) { return 0.1 * (i + 0.5) * cell; });
  PlannerConfig cfg = PointRobot();
  cfg.weights = {2.0, 1.0, 3.0, 5.0};
  const TraversabilityGrid T = BuildTraversability(L, cfg);
  const auto path = PlanPath(T, Centre(T, 1, 2), Centre(T, 18, 2), Algorithm::kAStar);
  ASSERT_TRUE(path) << path.error().message;
  ASSERT_EQ(path->cells.size(), 18u);
  for (const CellIndex& c : path->cells) EXPECT_EQ(c.j, 2);
  const double edge = std::hypot(cell, 0.1 * cell) + 3.0 * std::atan(0.1);
  EXPECT_NEAR(path->cost, 17 * edge, 1e-5);
  EXPECT_NEAR(path->parts.inclination_x, 17 * 3.0 * std::atan(0.1), 1e-5);
  EXPECT_NEAR(path->parts.inclination_y, 0.0, 1e-5);
  EXPECT_NEAR(path->max_step_m, 0.1 * cell, 1e-6);
  EXPECT_NEAR(path->max_inclination_rad, std::atan(0.1), 1e-5);
}

TEST(Planner, DijkstraAStarAndBglAgreeOnRandomTerrain) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<double> bumps(6);
    for (double& b : bumps) b = u(rng) * 10;
    const ElevationLayers L = MakeLayers(48, 40, 0.1, [&](int i, int j) {
      if (u(rng) < 0.04) return std::nan("");  // scattered unknown cells
      return 0.08 * std::sin(0.3 * i + bumps[0]) * std::cos(0.25 * j + bumps[1]) + 0.01 * u(rng) +
             (u(rng) < 0.01 ? 0.3 : 0.0);  // rough, and a few spikes
    });
    PlannerConfig cfg = PointRobot();
    if (seed % 2) {
      cfg.unknown = UnknownPolicy::kPenalise;
      cfg.unknown_penalty = 0.5;
    }
    const TraversabilityGrid T = BuildTraversability(L, cfg);
    // Pick free start and goal far apart.
    std::size_t s = 0, t = T.geometry.cell_count() - 1;
    while (!T.Free(s)) ++s;
    while (!T.Free(t)) --t;
    const auto d = PlanPath(T, T.geometry.CenterOf(T.geometry.FromLinear(s)),
                            T.geometry.CenterOf(T.geometry.FromLinear(t)), Algorithm::kDijkstra);
    const auto a = PlanPath(T, T.geometry.CenterOf(T.geometry.FromLinear(s)),
                            T.geometry.CenterOf(T.geometry.FromLinear(t)), Algorithm::kAStar);
    const double peer = BglCost(T, s, t);
    if (!std::isfinite(peer) || peer > 1e300) {
      EXPECT_FALSE(d);
      EXPECT_FALSE(a);
      continue;
    }
    ASSERT_TRUE(d) << "seed " << seed << ": " << d.error().message;
    ASSERT_TRUE(a) << "seed " << seed << ": " << a.error().message;
    EXPECT_NEAR(d->cost, peer, kCostRelTol * peer) << "seed " << seed;
    EXPECT_NEAR(a->cost, peer, kCostRelTol * peer) << "seed " << seed;
    EXPECT_NEAR(d->parts.Total(), d->cost, 1e-6 * peer);
    EXPECT_LE(a->expanded, d->expanded);
  }
}

TEST(Planner, ManyStartGoalPairsGiveBglsCostAndTheirOwnEdgeSums) {
  // Nearly flat ground (2 mm of noise: A*'s bound is almost exact, so many cells share a bucket
  // and some are lowered after their expansion, which must be expanded again) and rough ground
  // with unknown cells penalised; 20 random pairs on each of 8 maps of both: Dijkstra, A* and BGL
  // agree, and each path's edges, costed again on the map, sum to the path's cost.
  for (const bool rough : {false, true}) {
    for (unsigned seed = 1; seed <= 8; ++seed) {
      std::mt19937 rng(seed);
      std::uniform_real_distribution<double> u(0, 1);
      const ElevationLayers L = MakeLayers(40, 40, 0.1, [&](int i, int j) {
        if (!rough) return 0.002 * u(rng);
        if (u(rng) < 0.05) return std::nan("");
        return 0.06 * std::sin(0.35 * i) * std::cos(0.2 * j) + 0.015 * u(rng);
      });
      PlannerConfig cfg = PointRobot();
      cfg.unknown = UnknownPolicy::kPenalise;
      cfg.unknown_penalty = 0.3;
      const TraversabilityGrid T = BuildTraversability(L, cfg);
      std::uniform_int_distribution<std::size_t> cell(0, T.geometry.cell_count() - 1);
      const auto centre = [&](std::size_t k) {
        return T.geometry.CenterOf(T.geometry.FromLinear(k));
      };
      for (int pair = 0; pair < 20; ++pair) {
        std::size_t s = cell(rng), t = cell(rng);
        while (!T.Free(s)) s = cell(rng);
        while (!T.Free(t)) t = cell(rng);
        const auto d = PlanPath(T, centre(s), centre(t), Algorithm::kDijkstra);
        const auto a = PlanPath(T, centre(s), centre(t), Algorithm::kAStar);
        ASSERT_TRUE(d && a) << "seed " << seed << " pair " << pair;
        const double peer = BglCost(T, s, t);
        const std::string where = (rough ? "rough, seed " : "flat, seed ") + std::to_string(seed) +
                                  ", pair " + std::to_string(pair);
        EXPECT_NEAR(d->cost, peer, kCostRelTol * peer) << where;
        EXPECT_NEAR(a->cost, peer, kCostRelTol * peer) << where;
        EXPECT_NEAR(EvaluatePath(T, *d).cost, d->cost, kCostRelTol * peer) << where;
        EXPECT_NEAR(EvaluatePath(T, *a).cost, a->cost, kCostRelTol * peer) << where;
        EXPECT_EQ(EvaluatePath(T, *a).forbidden_cells, 0u) << where;
      }
    }
  }
}

TEST(Planner, HugeUnknownPenaltyStillGivesTheOptimalCost) {
  // Moves into unknown cells cost 1e6: the bucket ring would be too long, so the search falls
  // back to its radix heap; both searches must still agree with BGL.
  const ElevationLayers L = MakeLayers(40, 30, 0.1, [](int i, int j) {
    if (i == 20 && j != 3) return std::nan("");  // an unknown wall with one known gap
    return 0.02 * std::sin(0.4 * i) * std::cos(0.3 * j);
  });
  PlannerConfig cfg = PointRobot();
  cfg.unknown = UnknownPolicy::kPenalise;
  cfg.unknown_penalty = 1e6;
  const TraversabilityGrid T = BuildTraversability(L, cfg);
  const Eigen::Vector2d s = Centre(T, 2, 25), t = Centre(T, 37, 25);
  const double peer = BglCost(T, T.geometry.Linear({2, 25}), T.geometry.Linear({37, 25}));
  for (Algorithm a : {Algorithm::kDijkstra, Algorithm::kAStar}) {
    const auto path = PlanPath(T, s, t, a);
    ASSERT_TRUE(path) << path.error().message;
    EXPECT_NEAR(path->cost, peer, kCostRelTol * peer);
    EXPECT_DOUBLE_EQ(path->parts.unknown, 0.0);  // through the gap, not the wall
  }
}

TEST(Planner, GapNarrowerThanTheRobotIsNotPassed) {
  // A 0.5 m wall across the map (x = 2 m) with a 9-cell (0.45 m) and an 11-cell (0.55 m) gap.
  const double cell = 0.05;
  const auto make = [&](int gap_cells) {
    return MakeLayers(80, 60, cell, [&](int i, int j) {
      const bool wall = i == 40 && !(j >= 20 && j < 20 + gap_cells);
      return wall ? 0.5 : 0.0;
    });
  };
  PlannerConfig at, dx;
  dx.robot = RobotLimits::P3DX();  // 0.381 m wide
  at.robot = RobotLimits::P3AT();  // 0.497 m wide
  const Eigen::Vector2d start(0.5, 1.5), goal(3.5, 1.5);
  const ElevationLayers narrow = make(9), wide = make(11);
  EXPECT_TRUE(PlanPath(BuildTraversability(narrow, dx), start, goal, Algorithm::kAStar));
  const auto blocked = PlanPath(BuildTraversability(narrow, at), start, goal, Algorithm::kAStar);
  ASSERT_FALSE(blocked);
  EXPECT_EQ(blocked.error().reason, NoPath::Reason::kDisconnected);
  EXPECT_TRUE(PlanPath(BuildTraversability(wide, at), start, goal, Algorithm::kAStar));
}

TEST(Planner, ClearanceCostFallsLinearlyFromTheFootprintsReach) {
  // A step wall along x = 2.05 m (column 20 of 0.1 m cells) on flat ground. P3-AT: the footprint
  // reaches 0.2985 m (half width + half a cell), so columns 17..23 are blocked; beyond, the entry
  // cost rises by clearance_cost * (1 - (d - reach) / clearance_m) within clearance_m.
  const ElevationLayers L = MakeLayers(41, 30, 0.1, [](int i, int) { return i == 20 ? 0.5 : 0.0; });
  PlannerConfig plain;
  plain.robot = RobotLimits::P3AT();
  PlannerConfig soft = plain;
  soft.clearance_m = 0.5;
  soft.clearance_cost = 2.0;
  const TraversabilityGrid A = BuildTraversability(L, plain), B = BuildTraversability(L, soft);
  const GridGeometry& g = A.geometry;
  const double reach = 0.5 * plain.robot.width_m + 0.05;
  for (int i = 0; i < 41; ++i) {
    const std::size_t k = g.Linear({i, 15});
    EXPECT_EQ(A.blocked[k], B.blocked[k]) << i;  // the hard footprint is unchanged
    if (!B.Free(k)) continue;
    const double d = std::abs(i - 20) * 0.1;
    const double expected = d < reach + 0.5 ? 2.0 * (1.0 - (d - reach) / 0.5) : 0.0;
    EXPECT_NEAR(B.enter_cost[k] - A.enter_cost[k], expected, 1e-6) << "column " << i;
  }
  EXPECT_GT(B.enter_cost[g.Linear({16, 15})], A.enter_cost[g.Linear({16, 15})]);  // not all 0
}

TEST(Planner, ClearanceKeepsPathsOffHazardsWhereThereIsRoomAndStillPassesAGap) {
  // A wall along y = 1.55 m from x = 0 to 3 m, flat ground elsewhere; start and goal 0.45 m from
  // it (just beyond the footprint). Without clearance the path hugs the wall's margin; with it,
  // the path bows out where the field is open. A gap 0.6 m wide in a second wall is still used.
  const double cell = 0.1;
  const auto z = [](int i, int j) {
    if (j == 15 && i <= 30) return 0.5;               // the wall it runs along
    if (i == 45 && !(j >= 12 && j < 18)) return 0.5;  // a wall across the map, 0.6 m gap
    return 0.0;
  };
  const ElevationLayers L = MakeLayers(60, 40, cell, z);
  PlannerConfig plain;
  plain.robot = RobotLimits::P3AT();
  PlannerConfig soft = plain;
  soft.clearance_m = 0.5;
  soft.clearance_cost = 2.0;
  const Eigen::Vector2d start(0.25, 1.05), goal(2.75, 1.05);
  const auto hug = PlanPath(BuildTraversability(L, plain), start, goal, Algorithm::kAStar);
  const auto wide = PlanPath(BuildTraversability(L, soft), start, goal, Algorithm::kAStar);
  ASSERT_TRUE(hug);
  ASSERT_TRUE(wide);
  const auto farthest_from_wall = [](const Path& p) {
    double d = 0;
    for (const Waypoint& w : p.waypoints) d = std::max(d, 1.55 - w.y_m);
    return d;
  };
  EXPECT_LT(farthest_from_wall(*hug), 0.55);   // along the margin, at most a cell off it
  EXPECT_GT(farthest_from_wall(*wide), 0.75);  // out into the open field
  const auto through =
      PlanPath(BuildTraversability(L, soft), {4.0, 1.5}, {5.5, 1.5}, Algorithm::kAStar);
  ASSERT_TRUE(through) << "a gap the footprint fits stays passable (the wall spans the map)";
  for (const Waypoint& w : through->waypoints) {
    if (std::abs(w.x_m - 4.55) < 0.01)
      EXPECT_NEAR(w.y_m, 1.5, 0.051);  // the gap's middle (between two cells)
  }
}

TEST(Planner, FootprintNeverHangsOffTheMapsEdge) {
  // Flat, all known: the edge is the only hazard. P3-AT: 0.497 m wide, so with 0.1 m cells the
  // cells whose centre lies within 0.2985 m of an outside cell's (the first 2 rings) are blocked.
  const ElevationLayers L = MakeLayers(40, 30, 0.1, [](int, int) { return 0.0; });
  PlannerConfig at;
  at.robot = RobotLimits::P3AT();
  const TraversabilityGrid T = BuildTraversability(L, at);
  const GridGeometry& g = T.geometry;
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      const int ring = std::min({i, j, g.size_x - 1 - i, g.size_y - 1 - j});
      EXPECT_EQ(T.blocked[g.Linear({i, j})] == Blocked::kNearHazard, ring < 2) << i << ", " << j;
    }
  // Along the bottom edge: the path keeps half the robot's width on the map.
  const auto path = PlanPath(T, {0.25, 0.25}, {3.75, 0.25}, Algorithm::kAStar);
  ASSERT_TRUE(path);
  for (const CellIndex& c : path->cells) {
    const Eigen::Vector2d p = g.CenterOf(c);
    EXPECT_GE(std::min({p.x(), p.y(), 4.0 - p.x(), 3.0 - p.y()}), 0.5 * at.robot.width_m);
  }
  const auto off = PlanPath(T, {0.15, 0.15}, {2.0, 1.5}, Algorithm::kAStar);
  ASSERT_FALSE(off);
  EXPECT_EQ(off.error().reason, NoPath::Reason::kStartBlocked);
}

TEST(Planner, StartOrGoalOffTheMapOrInAnObstacleIsAClearError) {
  const ElevationLayers L = MakeLayers(40, 40, 0.1, [](int i, int j) {
    return (i >= 18 && i < 22 && j >= 18 && j < 22) ? 1.0 : 0.0;  // a 0.4 m box, 1 m tall
  });
  const TraversabilityGrid T = BuildTraversability(L, PlannerConfig{});
  const auto reason = [&](Eigen::Vector2d s, Eigen::Vector2d g) {
    const auto r = PlanPath(T, s, g, Algorithm::kDijkstra);
    EXPECT_FALSE(r);
    EXPECT_FALSE(r.error().message.empty());
    return r.error().reason;
  };
  EXPECT_EQ(reason({-1, 1}, {3, 3}), NoPath::Reason::kStartOutsideMap);
  EXPECT_EQ(reason({1, 1}, {3, 4.5}), NoPath::Reason::kGoalOutsideMap);
  EXPECT_EQ(reason({2, 2}, {3, 3}), NoPath::Reason::kStartBlocked);
  EXPECT_EQ(reason({0.5, 0.5}, {2.0, 2.0}), NoPath::Reason::kGoalBlocked);
  EXPECT_EQ(reason({0.5, 0.5}, {2.0, 2.35}), NoPath::Reason::kGoalBlocked);  // footprint
  EXPECT_TRUE(PlanPath(T, {0.5, 0.5}, {3.5, 3.5}, Algorithm::kAStar));
}

TEST(Planner, UnknownCellsForbiddenOrPenalised) {
  // A band of unknown cells across the map: forbidden -> disconnected; penalised -> crossed.
  const ElevationLayers L =
      MakeLayers(30, 10, 0.1, [](int i, int) { return i >= 14 && i < 16 ? std::nan("") : 0.0; });
  PlannerConfig cfg = PointRobot();
  const auto forbid =
      PlanPath(BuildTraversability(L, cfg), {0.5, 0.5}, {2.5, 0.5}, Algorithm::kAStar);
  ASSERT_FALSE(forbid);
  EXPECT_EQ(forbid.error().reason, NoPath::Reason::kDisconnected);
  cfg.unknown = UnknownPolicy::kPenalise;
  cfg.unknown_penalty = 2.0;
  const auto pen =
      PlanPath(BuildTraversability(L, cfg), {0.55, 0.55}, {2.55, 0.55}, Algorithm::kAStar);
  ASSERT_TRUE(pen) << pen.error().message;
  EXPECT_NEAR(pen->parts.unknown, 2 * 2.0, 1e-9);
}

TEST(Planner, CurbSplitByAMixedCellIsStillAStep) {
  // A 0.14 m curb (above the P3-AT's 0.089 m) at x = 1.0 m, 0.2 m cells. The cell [0.8, 1.0)
  // holds street points and, as range noise puts them there, points of the curb face and top:
  // its mean, 0.07 m, is under the limit from both sides. Its points off their plane say step.
  const double cell = 0.2;
  const GridGeometry g = GridGeometry::FromArea(0, 0, 2, 1, cell);
  const auto curb = [&](double step_x) {
    ElevationMap map(g);
    std::vector<Eigen::Vector3f> pts;
    for (double y = 0.005; y < 1; y += 0.01)
      for (double x = 0.005; x < 2; x += 0.01)
        pts.emplace_back(float(x), float(y), x < step_x ? 0.0f : 0.14f);
    (void)map.InsertPoints(pts.data(), pts.size());
    return mapping::ComputeLayers(map);
  };
  const ElevationLayers mixed = curb(0.9);  // the curb's edge in the middle of cell 4
  const std::size_t k = g.Linear({4, 2});
  ASSERT_NEAR(mixed.mean_z[k], 0.07, 1e-3);
  EXPECT_NEAR(mixed.plane_residual[k], 0.14 / 4, 1e-3);  // a step's residual: h / 4
  PlannerConfig cfg = PointRobot();
  // The plane fit over the cell's neighbours tilts by the curb too (about the P3-AT's 19.3 deg
  // here); allow 30 deg so that the step rule alone is tested.
  cfg.robot.max_inclination_rad = 30 * M_PI / 180;
  const TraversabilityGrid T = BuildTraversability(mixed, cfg);
  EXPECT_EQ(T.blocked[k], Blocked::kStep);
  EXPECT_FALSE(PlanPath(T, Centre(T, 1, 2), Centre(T, 8, 2), Algorithm::kAStar));
  // A ramp with the same mean profile is no step: its points lie on their plane.
  ElevationMap ramp_map(g);
  std::vector<Eigen::Vector3f> ramp;
  for (double y = 0.005; y < 1; y += 0.01)
    for (double x = 0.005; x < 2; x += 0.01)
      ramp.emplace_back(float(x), float(y), float(std::clamp((x - 0.8) * 0.3, 0.0, 0.14)));
  (void)ramp_map.InsertPoints(ramp.data(), ramp.size());
  const ElevationLayers R = mapping::ComputeLayers(ramp_map);
  EXPECT_LT(R.plane_residual[g.Linear({5, 2})], 1e-4);
  EXPECT_EQ(BuildTraversability(R, cfg).blocked[g.Linear({5, 2})], Blocked::kFree);
}

TEST(Planner, SlopeBeyondTheRobotLimitIsTooSteep) {
  // z = tan(25 deg) x: above the P3-AT's 19.3 deg, below nothing.
  const ElevationLayers L =
      MakeLayers(20, 20, 0.1, [](int i, int) { return std::tan(25 * M_PI / 180) * i * 0.1; });
  const TraversabilityGrid T = BuildTraversability(L, PlannerConfig{});
  EXPECT_EQ(T.blocked[T.geometry.Linear({10, 10})], Blocked::kTooSteep);
  PlannerConfig steep;
  steep.robot.max_inclination_rad = 30 * M_PI / 180;
  steep.robot.step_max_m = 0.1;
  EXPECT_EQ(BuildTraversability(L, steep).blocked[T.geometry.Linear({10, 10})], Blocked::kFree);
}

// The P3-DX's 2.5 cm step limit lies within a far floor's noise. A rise between cell means, or a
// spread within a cell, counts as a step only where it stands out of the layers' point noise
// (2 cm) by twice its standard error; short of that the cell is doubtful, and the unknown policy
// decides. Near, dense ground keeps its real steps; a far obstacle well over the noise too.
TEST(Planner, AFarFloorsNoiseIsNoStepForTheP3DxButRealStepsStay) {
  const double cell = 0.1;
  const int sx = 60, sy = 20;
  ElevationMap map(GridGeometry::FromArea(0, 0, sx * cell, sy * cell, cell));
  std::mt19937 rng(7);
  std::normal_distribution<double> near_noise(0.0, 0.003), far_noise(0.0, 0.012);
  const auto box = [](int i, int j) { return i >= 10 && i <= 12 && j >= 8 && j <= 10; };
  const auto pole = [](int i, int j) { return i == 45 && j == 10; };
  std::vector<Eigen::Vector3f> pts;
  std::vector<double> far_z(sx * sy, 0.0);
  for (int j = 0; j < sy; ++j)
    for (int i = 0; i < sx; ++i) {
      const Eigen::Vector2d c = map.geometry().CenterOf({i, j});
      if (i < 30) {  // near: 20 points a cell, a 10 cm box among them
        for (int p = 0; p < 20; ++p)
          pts.emplace_back(float(c.x()), float(c.y()),
                           float((box(i, j) ? 0.10 : 0.0) + near_noise(rng)));
      } else {  // far: one point a cell, a 20 cm obstacle among them
        far_z[j * sx + i] = (pole(i, j) ? 0.20 : 0.0) + far_noise(rng);
        pts.emplace_back(float(c.x()), float(c.y()), float(far_z[j * sx + i]));
      }
    }
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = mapping::ComputeLayers(map);  // 2 cm a point
  ASSERT_DOUBLE_EQ(L.height_noise_m, 0.02);
  PlannerConfig dx;
  dx.robot = RobotLimits::P3DX();
  dx.unknown = UnknownPolicy::kPenalise;
  const TraversabilityGrid T = BuildTraversability(L, dx);
  const GridGeometry& g = T.geometry;
  // Not vacuous: far neighbours' noise rises past 2.5 cm.
  int noisy_rises = 0;
  for (int j = 1; j + 1 < sy; ++j)
    for (int i = 31; i + 1 < sx; ++i)
      if (!pole(i, j) && !pole(i + 1, j))
        noisy_rises += std::abs(far_z[j * sx + i] - far_z[j * sx + i + 1]) > 0.025;
  ASSERT_GT(noisy_rises, 10);
  for (int j = 2; j + 2 < sy; ++j)
    for (int i = 2; i + 2 < sx; ++i) {
      const std::size_t k = g.Linear({i, j});
      if (i == 11 && j == 9) {  // the box's top, inside its edge
        EXPECT_FALSE(T.Free(k));
      } else if (box(i, j) || pole(i, j)) {  // a step, or too steep for the 3 x 3 plane
        EXPECT_TRUE(IsFootprintHazard(T.blocked[k])) << i << ", " << j;
      } else if (i >= 31 && (std::abs(i - 45) > 1 || std::abs(j - 10) > 1)) {  // off the pole's fit
        EXPECT_FALSE(IsFootprintHazard(T.blocked[k])) << "far floor " << i << ", " << j;
      }
    }
  // The near floor beside the box, more than the footprint's reach from it, stays free at no
  // unknown penalty: dense ground is judged as before.
  EXPECT_EQ(T.blocked[g.Linear({20, 10})], Blocked::kFree);
  EXPECT_LT(T.enter_cost[g.Linear({20, 10})], dx.unknown_penalty);
}

// Within a dense cell a step needs two points beyond the limit. One point 4 cm over a floor of 30
// (a mixed pixel at a depth edge) leaves the cell doubtful for the P3-DX's 2.5 cm limit, for the
// unknown policy to decide; two points there, the top of something, are a step.
TEST(Planner, OnePointOffADenseCellIsDoubtfulTwoAreAStep) {
  const double cell = 0.1;
  ElevationMap map(GridGeometry::FromArea(0, 0, 2, 2, cell));
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::uniform_real_distribution<double> at(0.01, 0.09);
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < 20; ++j)
    for (int i = 0; i < 20; ++i)
      for (int p = 0; p < 30; ++p)
        pts.emplace_back(float(i * cell + at(rng)), float(j * cell + at(rng)), float(noise(rng)));
  const auto raised = [&](int i, int j, int points) {
    for (int p = 0; p < points; ++p)
      pts.emplace_back(float(i * cell + at(rng)), float(j * cell + at(rng)), 0.04f);
  };
  raised(5, 10, 1);
  raised(14, 10, 2);
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = mapping::ComputeLayers(map);
  const GridGeometry& g = L.geometry;
  const std::size_t one = g.Linear({5, 10}), two = g.Linear({14, 10});
  ASSERT_GT(L.max_z[one] - L.mean_z[one], 0.035) << "the point stands past the 2.5 cm limit";
  PlannerConfig dx;
  dx.robot = RobotLimits::P3DX();
  dx.unknown = UnknownPolicy::kPenalise;
  const TraversabilityGrid T = BuildTraversability(L, dx);
  EXPECT_EQ(T.blocked[one], Blocked::kFree);
  EXPECT_GE(T.enter_cost[one], dx.unknown_penalty) << "doubtful: priced as unknown";
  EXPECT_EQ(T.blocked[two], Blocked::kStep);
  dx.unknown = UnknownPolicy::kForbid;
  EXPECT_EQ(BuildTraversability(L, dx).blocked[one], Blocked::kUnknown);
  // Layers built by hand without the second extremes judge by the extremes, as before.
  ElevationLayers by_hand = L;
  by_hand.next_min_z.clear();
  by_hand.next_max_z.clear();
  EXPECT_EQ(BuildTraversability(by_hand, dx).blocked[one], Blocked::kStep);
}

TEST(PlannerConfig, YamlWeightsPresetsAndErrors) {
  const PlannerConfig c = ParsePlannerConfig(
      "robot: p3dx\nweights: {roughness: 4, length: 2, inclination_x: 0.5, inclination_y: 0.25}\n"
      "unknown: penalise\nunknown_penalty: 3\nmax_inclination_deg: 10\n"
      "clearance_m: 0.4\nclearance_cost: 1.5\n",
      "test.yaml");
  EXPECT_EQ(c.robot.name, "p3dx");
  EXPECT_DOUBLE_EQ(c.robot.step_max_m, 0.025);
  EXPECT_NEAR(c.robot.max_inclination_rad, 10 * M_PI / 180, 1e-12);
  EXPECT_DOUBLE_EQ(c.weights.roughness, 4);
  EXPECT_DOUBLE_EQ(c.weights.inclination_y, 0.25);
  EXPECT_EQ(c.unknown, UnknownPolicy::kPenalise);
  EXPECT_DOUBLE_EQ(c.unknown_penalty, 3);
  EXPECT_DOUBLE_EQ(c.clearance_m, 0.4);
  EXPECT_DOUBLE_EQ(c.clearance_cost, 1.5);
  const auto message = [](const std::string& yaml) {
    try {
      (void)ParsePlannerConfig(yaml, "bad.yaml");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("robot: tank\n").find("bad.yaml: field 'robot'"), std::string::npos);
  EXPECT_NE(message("weights: {length: -1}\n").find("weights.length"), std::string::npos);
  EXPECT_NE(message("unknown: maybe\n").find("'unknown'"), std::string::npos);
  EXPECT_NE(message("step_max_m: abc\n").find("step_max_m"), std::string::npos);
  EXPECT_NE(message("clearance_m: -0.1\n").find("clearance_m"), std::string::npos);
}

TEST(PathIo, CsvGeoJsonAndPicture) {
  const test_support::ScopedTempDir dir("path_io");
  const ElevationLayers L = MakeLayers(30, 20, 0.1, [](int i, int) { return 0.01 * i; });
  const TraversabilityGrid T = BuildTraversability(L, PointRobot());
  const auto path = PlanPath(T, {0.25, 0.25}, {2.75, 1.75}, Algorithm::kAStar);
  ASSERT_TRUE(path);
  ASSERT_TRUE(WritePathCsv(*path, (dir / "p.csv").string()));
  std::ifstream csv(dir / "p.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "index,x_m,y_m,z_m,cum_length_m");
  EXPECT_FALSE(WritePathGeoJson(*path, std::nullopt, (dir / "p.geojson").string()));
  const mapping::GeodeticOrigin o{39.571, -104.304, 1500};
  ASSERT_TRUE(WritePathGeoJson(*path, o, (dir / "p.geojson").string()));
  const auto j = nlohmann::json::parse(std::ifstream(dir / "p.geojson"));
  const auto& coords = j["features"][0]["geometry"]["coordinates"];
  ASSERT_EQ(coords.size(), path->waypoints.size());
  // 0.25 m east of the origin is 0.25 / (cos(lat) * 111.3 km) degrees of longitude.
  EXPECT_NEAR(coords[0][0].get<double>(),
              o.longitude_deg + 0.25 / (std::cos(o.latitude_deg * M_PI / 180) * 111319.5), 1e-7);
  EXPECT_NEAR(coords[0][1].get<double>(), o.latitude_deg + 0.25 / 110990.0, 2e-7);
  EXPECT_NEAR(j["features"][0]["properties"]["cost"].get<double>(), path->cost, 1e-5);
  // Every cell known: the third value is the ellipsoidal height, the origin's plus the map's z.
  ASSERT_EQ(coords[1].size(), 3u);
  EXPECT_NEAR(coords[1][2].get<double>(), o.height_m + path->waypoints[1].z_m, 1e-3);
  EXPECT_TRUE(j["features"][0]["properties"]["heights"].get<bool>());
  // A waypoint in a cell of unknown height: no position gets a made-up height.
  Path unknown = *path;
  unknown.waypoints[1].z_m = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(WritePathGeoJson(unknown, o, (dir / "u.geojson").string()));
  const auto u = nlohmann::json::parse(std::ifstream(dir / "u.geojson"));
  for (const auto& position : u["features"][0]["geometry"]["coordinates"]) {
    EXPECT_EQ(position.size(), 2u);
  }
  EXPECT_FALSE(u["features"][0]["properties"]["heights"].get<bool>());
  mapping::ImageOptions opt;
  opt.pixels_per_cell = 4;
  mapping::RgbImage img = mapping::RenderElevationImage(L, opt);
  const auto before = img.rgb;
  DrawPath(*path, L.geometry, img);
  EXPECT_NE(before, img.rgb);
  ASSERT_TRUE(mapping::WritePng(img, (dir / "p.png").string()));
}

}  // namespace
}  // namespace pitchlab::planning
