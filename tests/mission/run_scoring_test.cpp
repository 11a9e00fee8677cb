// ScoreRun's map comparison on hand-made traversability grids whose every cell's verdict is known.

#include <cmath>

#include <gtest/gtest.h>

#include "pitchlab/mission/run_scoring.hpp"

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

}  // namespace
}  // namespace pitchlab::mission
