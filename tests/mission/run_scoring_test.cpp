// ScoreRun's map comparison on hand-made traversability grids whose every cell's verdict is known.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mission/run_scoring.hpp"

#include "level_layers.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A 5 x 1 row of level, free, observed cells of 1 m.
planning::TraversabilityGrid LevelRow() {
  planning::TraversabilityGrid g;
  g.geometry = mapping::GridGeometry::FromArea(0, 0, 5, 1, 1.0);
  const std::size_t n = g.geometry.cell_count();
  g.z_m.assign(n, 0.0f);
  g.phi_x_rad.assign(n, 0.0f);
  g.phi_y_rad.assign(n, 0.0f);
  g.blocked.assign(n, planning::Blocked::kFree);
  g.moves.assign(n, 0);  // no cell reached from another: no false hazard is in reach
  return g;
}

// Truth: cells 1, 2 and 3 too steep (20, 25, 30 deg about x or y); the map: all three free, read
// at 10 and 12 deg and, cell 3, without a supported slope (0, as BuildTraversability leaves it).
// Cell 4 is a missed step, not a slope.
TEST(ScoreRun, MissedTooSteepCellsReportTheMapsAndTheTruthsTilt) {
  planning::TraversabilityGrid truth = LevelRow(), map = LevelRow();
  truth.blocked[1] = truth.blocked[2] = truth.blocked[3] = planning::Blocked::kTooSteep;
  truth.phi_x_rad[1] = float(20 * kDeg);
  truth.phi_y_rad[2] = float(25 * kDeg);
  truth.phi_x_rad[3] = float(30 * kDeg);
  truth.blocked[4] = planning::Blocked::kStep;
  map.phi_x_rad[1] = float(10 * kDeg);
  map.phi_y_rad[2] = float(-12 * kDeg);
  const RunScore s = ScoreRun(MissionResult{}, truth, map, {0.5, 0.5}, {0.5, 0.5},
                              planning::Algorithm::kAStar);
  EXPECT_EQ(s.missed_hazard_cells, 4u);
  EXPECT_EQ(s.missed_as.too_steep, 3u);
  EXPECT_EQ(s.missed_steep_tilt_unknown, 1u);
  EXPECT_NEAR(s.missed_steep_map_tilt_deg, 12.0, 1e-4);   // the upper median of 10 and 12
  EXPECT_NEAR(s.missed_steep_true_tilt_deg, 25.0, 1e-4);  // of 20, 25 and 30
}

// A row of ten cells, the limit 16 deg: true tilts 2 and 4 (below half the limit), 10, 12 and 14
// (half to the limit), 20 and 25 (beyond it); cell 7 a true step and cell 8 unseen by the map,
// both left out. The map reads them 3, 3 / 10, 10, 17 / 15 and unsupported.
TEST(ScoreRun, TheMapsTiltIsComparedWithTheTruthsOverAllCellsBinnedByTheTrueTilt) {
  planning::TraversabilityGrid truth = LevelRow(), map = LevelRow();
  truth.geometry = map.geometry = mapping::GridGeometry::FromArea(0, 0, 10, 1, 1.0);
  for (planning::TraversabilityGrid* g : {&truth, &map}) {
    g->z_m.assign(10, 0.0f);
    g->phi_x_rad.assign(10, 0.0f);
    g->phi_y_rad.assign(10, 0.0f);
    g->blocked.assign(10, planning::Blocked::kFree);
    g->moves.assign(10, 0);
  }
  truth.config.robot.max_inclination_rad = 16 * kDeg;
  const double true_deg[] = {2, 4, 10, 12, 14, 20, 25, 30, 30, 0};
  const double map_deg[] = {3, 3, 10, 10, 17, 15, 0, 30, 30, 0};
  for (std::size_t k = 0; k < 10; ++k) {
    truth.phi_x_rad[k] = float(true_deg[k] * kDeg);
    map.phi_y_rad[k] = float(map_deg[k] * kDeg);
  }
  truth.blocked[5] = truth.blocked[6] = planning::Blocked::kTooSteep;
  truth.blocked[7] = planning::Blocked::kStep;
  map.z_m[8] = std::nanf("");
  const RunScore s =
      ScoreRun(MissionResult{}, truth, map, {0.5, 0.5}, {0.5, 0.5}, planning::Algorithm::kAStar);
  ASSERT_EQ(s.tilt_against_truth.size(), 3u);
  const TiltAgainstTruth &low = s.tilt_against_truth[0], &mid = s.tilt_against_truth[1],
                         &steep = s.tilt_against_truth[2];
  EXPECT_NEAR(low.lo_deg, 0, 1e-9);
  EXPECT_NEAR(mid.lo_deg, 8, 1e-9);
  EXPECT_NEAR(steep.lo_deg, 16, 1e-9);
  EXPECT_NEAR(steep.hi_deg, 90, 1e-9);
  EXPECT_EQ(low.cells, 3u);                      // 2, 4 and the level cell 9
  EXPECT_EQ(low.unsupported, 1u);                // cell 9: the map reads no slope (0, 0)
  EXPECT_NEAR(low.median_error_deg, 1.0, 1e-4);  // the upper median of +1 and -1
  EXPECT_EQ(mid.cells, 3u);
  EXPECT_EQ(mid.unsupported, 0u);
  EXPECT_NEAR(mid.median_error_deg, 0.0, 1e-4);  // of -2, 0 and +3
  EXPECT_NEAR(mid.p10_error_deg, -2.0, 1e-4);
  EXPECT_NEAR(mid.p90_error_deg, 3.0, 1e-4);
  EXPECT_EQ(steep.cells, 2u);  // the step and the cell the map did not see are left out
  EXPECT_EQ(steep.unsupported, 1u);
  EXPECT_NEAR(steep.median_error_deg, -5.0, 1e-4);
}

// A run whose true trajectory runs along y = y_m from x0_m to x1_m, a sample every step_m.
MissionResult TrackAlongX(double x0_m, double x1_m, double y_m, double step_m) {
  MissionResult run;
  for (double x = x0_m; x <= x1_m + 1e-9; x += step_m) {
    TrajectorySample s;
    s.T_world_base_true = Eigen::Isometry3d(Eigen::Translation3d(x, y_m, 0));
    run.trajectory.push_back(s);
  }
  return run;
}

// A track along a row of five 1 m cells crosses cells 1-4, built from layers as a run's truth is:
// three too-steep cells (20, 30, 25 deg; the limit 16) and a step inside cell 4. The hazards under
// it are those four, the steepest 30 deg.
TEST(ScoreRun, SaysWhatTheHazardsTheRobotCameOverWere) {
  mapping::ElevationLayers L =
      test_support::LevelLayers(mapping::GridGeometry::FromArea(0, 0, 5, 1, 1.0));
  L.phi_x[1] = float(20 * kDeg);
  L.phi_y[2] = float(-30 * kDeg);
  L.phi_x[3] = float(25 * kDeg);
  L.max_z[4] = 0.5f;  // a step within the cell
  planning::PlannerConfig config;
  config.robot.max_inclination_rad = 16 * kDeg;
  const planning::TraversabilityGrid truth = planning::BuildTraversability(L, config);
  ASSERT_EQ(truth.blocked[2], planning::Blocked::kTooSteep);
  ASSERT_EQ(truth.blocked[4], planning::Blocked::kStep);
  const RunScore s = ScoreRun(TrackAlongX(0.5, 4.5, 0.5, 0.25), truth, truth, {0.5, 0.5},
                              {4.5, 0.5}, planning::Algorithm::kAStar);
  EXPECT_EQ(s.hazard_cells_crossed, 4u);
  EXPECT_EQ(s.touched.too_steep, 3u);
  EXPECT_EQ(s.touched.step, 1u);
  EXPECT_EQ(s.touched.drop, 0u);
  EXPECT_NEAR(s.touched_steepest_deg, 30.0, 1e-4);
  EXPECT_NEAR(s.too_steep_limit_deg, 16.0, 1e-9);
}

// A 4 x 2 m floor of 0.1 m cells with a box 0.3 m tall (x 2.0-2.4, y 1.2-2.0), a P3-AT's
// traversability of it, and a true track along y = 1.05: 0.15 m from the box, closer than half the
// robot's width (0.25 m), so the cells beside the box it drives over are forbidden. The score says
// where: one place a cell, each a forbidden cell under the track, all beside the box.
TEST(ScoreRun, SaysWhereTheRunCrossedForbiddenCells) {
  mapping::ElevationMap map(mapping::GridGeometry::FromArea(0, 0, 4, 2, 0.1));
  std::vector<Eigen::Vector3f> points;
  for (double y = 0.025; y < 2; y += 0.05)
    for (double x = 0.025; x < 4; x += 0.05) {
      const bool box = x > 2.0 && x < 2.4 && y > 1.2;
      points.emplace_back(float(x), float(y), box ? 0.3f : 0.0f);
    }
  (void)map.InsertPoints(points.data(), points.size());
  const planning::TraversabilityGrid truth =
      planning::BuildTraversability(mapping::ComputeLayers(map), planning::PlannerConfig{});
  const RunScore s = ScoreRun(TrackAlongX(0.2, 3.8, 1.05, 0.05), truth, truth, {0.2, 1.05},
                              {3.8, 1.05}, planning::Algorithm::kAStar);
  ASSERT_GT(s.forbidden_cells_crossed, 0u);
  EXPECT_EQ(s.hazard_cells_crossed, 0u);  // beside the box, never on it
  ASSERT_EQ(s.forbidden_crossed_at.size(), s.forbidden_cells_crossed);
  for (const Eigen::Vector2d& at : s.forbidden_crossed_at) {
    EXPECT_FALSE(truth.Free(truth.geometry.Linear(truth.geometry.IndexOf(at.x(), at.y()))));
    EXPECT_NEAR(at.y(), 1.05, 1e-9);  // the cell's centre: the track's row
    EXPECT_GT(at.x(), 2.0 - 0.25 - 0.1);
    EXPECT_LT(at.x(), 2.4 + 0.25 + 0.1);
  }
  // The hazards under the footprint: the box's near row of step cells (y 1.2-1.3, 0.2 m from the
  // track's centre line, within the footprint's 0.3 m reach; the next row is 0.3 m away), each once
  // however many forbidden cells reach it.
  EXPECT_EQ(s.touched.step, 4u);
  EXPECT_EQ(s.touched.too_steep + s.touched.drop, 0u);
  EXPECT_EQ(s.touched_steepest_deg, 0.0);
}

// A 4 x 4 m floor of 0.1 m cells with a platform 0.85 m tall on it (x and y 1.0-3.0, a parked
// car's chassis as the truth casts it from above): the platform's middle is truly free, flat and
// far from its edges, but no move of the true map leads up to it. The map reads one cell there and
// one cell of the floor as too steep: the floor's is a false hazard, the platform's is out of the
// robot's reach and counted apart.
TEST(ScoreRun, CountsFalseHazardsTheRobotCouldReachApartFromThoseItCouldNot) {
  mapping::ElevationMap map(mapping::GridGeometry::FromArea(0, 0, 4, 4, 0.1));
  std::vector<Eigen::Vector3f> points;
  for (double y = 0.025; y < 4; y += 0.05)
    for (double x = 0.025; x < 4; x += 0.05) {
      const bool platform = x > 1.0 && x < 3.0 && y > 1.0 && y < 3.0;
      points.emplace_back(float(x), float(y), platform ? 0.85f : 0.0f);
    }
  (void)map.InsertPoints(points.data(), points.size());
  const planning::TraversabilityGrid truth =
      planning::BuildTraversability(mapping::ComputeLayers(map), planning::PlannerConfig{});
  const mapping::GridGeometry& g = truth.geometry;
  const std::size_t on_platform = g.Linear(g.IndexOf(2.05, 2.05));
  const std::size_t on_floor = g.Linear(g.IndexOf(0.55, 3.45));
  ASSERT_TRUE(truth.Free(on_platform));
  ASSERT_TRUE(truth.Free(on_floor));
  planning::TraversabilityGrid estimated = truth;
  estimated.blocked[on_platform] = estimated.blocked[on_floor] = planning::Blocked::kTooSteep;
  const RunScore s = ScoreRun(MissionResult{}, truth, estimated, {0.55, 0.55}, {0.55, 0.55},
                              planning::Algorithm::kAStar);
  EXPECT_EQ(s.false_hazard_cells, 1u);
  EXPECT_EQ(s.false_hazard_cells_out_of_reach, 1u);
  EXPECT_EQ(s.false_as.too_steep, 1u);
  // From a start on the platform, the floor is the one out of reach.
  const RunScore up = ScoreRun(MissionResult{}, truth, estimated, {2.05, 2.05}, {2.05, 2.05},
                               planning::Algorithm::kAStar);
  EXPECT_EQ(up.false_hazard_cells, 1u);
  EXPECT_EQ(up.false_hazard_cells_out_of_reach, 1u);
}

}  // namespace
}  // namespace pitchlab::mission
