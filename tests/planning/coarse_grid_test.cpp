// Grids coarser than the robot (a DEM's 3 m cells): a rise between neighbouring cells is a slope,
// judged by the robot's inclination limit, not by its step height.

#include <gtest/gtest.h>

#include <cmath>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/planner.hpp"

namespace pitchlab::planning {
namespace {

// A terrace: 10 x 5 cells of `cell_m`, columns 0-4 at 0 m, columns 5-9 at `rise_m`, one height
// per cell (a DEM's sample), exact: a laser point's noise would leave a step of one point a side
// doubtful.
mapping::ElevationLayers Terrace(double cell_m, double rise_m) {
  mapping::ElevationMap map(mapping::GridGeometry{0, 0, cell_m, 10, 5});
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 10; ++i)
      pts.emplace_back((i + 0.5) * cell_m, (j + 0.5) * cell_m, i >= 5 ? rise_m : 0.0);
  (void)map.InsertPoints(pts.data(), pts.size());
  mapping::LayerConfig exact;
  exact.height_noise_m = 1e-4;
  return mapping::ComputeLayers(map, exact);
}

Blocked At(const TraversabilityGrid& T, int i, int j) {
  return T.blocked[T.geometry.Linear({i, j})];
}

TEST(CoarseGrid, HalfAMetreBetweenThreeMetreCellsIsASlopeNotAStep) {
  const PlannerConfig p3at;  // step 0.089 m, 19.3 deg, 0.497 x 0.508 m
  const TraversabilityGrid T = BuildTraversability(Terrace(3.0, 0.5), p3at);
  ASSERT_TRUE(CoarserThanRobot(T.geometry, p3at.robot));
  EXPECT_EQ(At(T, 5, 2), Blocked::kFree);  // 0.5 m over 3 m: 9.5 deg
  const auto path = PlanPath(T, {4.5, 7.5}, {28.5, 7.5}, Algorithm::kAStar);
  ASSERT_TRUE(path) << path.error().message;
  EXPECT_NEAR(path->max_step_m, 0.5, 1e-6);
  EXPECT_FALSE(CoarseGridWarning(T.geometry, p3at.robot).empty());
}

TEST(CoarseGrid, ARiseSteeperThanTheRobotsLimitBetweenCellsBlocksTheUpperCell) {
  // 2 m over 3 m is 33.7 deg between the cells; the 3 x 3 plane fit across the edge reads
  // atan(2 * 3 / 18) = 18.4 deg, under 19.3: only the rule between neighbours sees it.
  const PlannerConfig p3at;
  const TraversabilityGrid T = BuildTraversability(Terrace(3.0, 2.0), p3at);
  EXPECT_EQ(At(T, 5, 2), Blocked::kTooSteep);
  EXPECT_EQ(At(T, 4, 2), Blocked::kFree);
  EXPECT_EQ(At(T, 6, 2), Blocked::kFree);
  const auto path = PlanPath(T, {4.5, 7.5}, {28.5, 7.5}, Algorithm::kAStar);
  ASSERT_FALSE(path);
  EXPECT_EQ(path.error().reason, NoPath::Reason::kDisconnected);
  // 1.0 m over 3 m (18.4 deg) is within the limit.
  EXPECT_EQ(At(BuildTraversability(Terrace(3.0, 1.0), p3at), 5, 2), Blocked::kFree);
}

TEST(CoarseGrid, FineGridsKeepTheStepRule) {
  // 0.1 m between 0.5 m cells, finer than the robot (0.508 m long), is a step (above 0.089 m),
  // though as a slope (11.3 deg) it would pass; at 0.6 m cells, coarser, it is a 9.5 deg slope.
  const PlannerConfig p3at;
  const TraversabilityGrid fine = BuildTraversability(Terrace(0.5, 0.1), p3at);
  EXPECT_FALSE(CoarserThanRobot(fine.geometry, p3at.robot));
  EXPECT_TRUE(CoarseGridWarning(fine.geometry, p3at.robot).empty());
  EXPECT_EQ(At(fine, 5, 2), Blocked::kStep);
  const TraversabilityGrid coarse = BuildTraversability(Terrace(0.6, 0.1), p3at);
  EXPECT_TRUE(CoarserThanRobot(coarse.geometry, p3at.robot));
  EXPECT_EQ(At(coarse, 5, 2), Blocked::kFree);
}

}  // namespace
}  // namespace pitchlab::planning
