#include "pitchlab/mission/slope_guard.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "pitchlab/planning/traversability.hpp"
#include "level_layers.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Waypoints every 0.1 m along x from 0 to 5 m; flat, except a ramp of `grade` from x = 2 to 3 m.
planning::Path RampPath(double grade) {
  planning::Path p;
  for (int i = 0; i <= 50; ++i) {
    const double x = 0.1 * i;
    const double z = grade * std::clamp(x - 2.0, 0.0, 1.0);
    p.waypoints.push_back({x, 0.0, z});
  }
  return p;
}

TEST(MaxGrade, FindsTheRampOnlyInAWindowThatReachesIt) {
  const planning::Path p = RampPath(0.3);
  EXPECT_NEAR(MaxGrade(p, 0.0, 1.5), 0.0, 1e-9);
  EXPECT_NEAR(MaxGrade(p, 1.5, 2.5), 0.3, 1e-6);  // baselines starting before 2 m end on the ramp
  EXPECT_NEAR(MaxGrade(p, 0.0, 5.0), 0.3, 1e-6);
  EXPECT_NEAR(MaxGrade(p, 3.5, 5.0), 0.0, 1e-9);
  // A descent is as steep as a climb.
  EXPECT_NEAR(MaxGrade(RampPath(-0.2), 0.0, 5.0), 0.2, 1e-6);
}

TEST(MaxGrade, APathShorterThanTheBaselineHasNoGrade) {
  planning::Path p;
  EXPECT_EQ(MaxGrade(p, 0.0, 1.0), 0.0);
  p.waypoints = {{0, 0, 0}, {0.1, 0, 0.5}};
  EXPECT_EQ(MaxGrade(p, 0.0, 1.0), 0.0);
}

// A 4 x 4 m map of 0.1 m cells: flat and observed at z = 0, except the unknown column x in
// [3.0, 3.1) and one drop cell at (2.05, 2.05).
mapping::ElevationLayers FlatLayers() {
  mapping::ElevationLayers L =
      test_support::LevelLayers(mapping::GridGeometry::FromArea(0.0, 0.0, 4.0, 4.0, 0.1));
  for (int j = 0; j < L.geometry.size_y; ++j) {
    const std::size_t k = L.geometry.Linear({30, j});
    L.state[k] = mapping::CellState::kUnknown;
    L.count[k] = 0;
    L.mean_z[k] = L.min_z[k] = L.max_z[k] = L.roughness[k] = L.phi_x[k] = L.phi_y[k] = NAN;
  }
  L.state[L.geometry.Linear({20, 20})] = mapping::CellState::kDrop;
  return L;
}

planning::Blocked BlockedAt(const mapping::ElevationLayers& L, double x, double y) {
  planning::PlannerConfig config;  // P3-AT: 19.3 deg at most
  config.robot.width_m = 0.0;      // no inflation: only the marked cells themselves
  const planning::TraversabilityGrid grid = planning::BuildTraversability(L, config);
  return grid.blocked[L.geometry.Linear(L.geometry.IndexOf(x, y))];
}

// Along the contour of a side slope the path is level, yet the robot rolls by the slope's tilt:
// the map's cell tilt explains that, the path's grade does not.
TEST(PathGrade, ASideSlopesTiltComesFromTheCellsNotTheLevelPath) {
  mapping::ElevationLayers L = FlatLayers();
  const float side = static_cast<float>(15.0 * kPi / 180);
  for (int j = 0; j < L.geometry.size_y; ++j) {
    for (int i = 20; i < 25; ++i) L.phi_y[L.geometry.Linear({i, j})] = side;  // x in [2.0, 2.5)
  }
  const planning::TraversabilityGrid grid = planning::BuildTraversability(L, {});
  planning::Path p;
  for (int i = 0; i <= 35; ++i) p.waypoints.push_back({0.05 + 0.1 * i, 1.05, 0.0});  // level
  const PathGrade grade(p);
  EXPECT_EQ(grade.Max(0.0, 4.0), 0.0);
  EXPECT_NEAR(grade.MaxTilt(grid, 1.5, 2.5), side, 1e-6);
  EXPECT_NEAR(grade.MaxTilt(grid, 0.0, 1.9), 0.0, 1e-9);  // before the slope
  EXPECT_NEAR(grade.MaxTilt(grid, 2.5, 3.5), 0.0, 1e-9);  // after it, and over the unknown column
  // A path that leaves the grid has no tilt there.
  p.waypoints.push_back({5.0, 1.05, 0.0});
  EXPECT_NEAR(PathGrade(p).MaxTilt(grid, 3.0, 10.0), 0.0, 1e-9);
}

TEST(MarkFelt, ATiltBeyondTheLimitForbidsTheDiscAndNothingElse) {
  mapping::ElevationLayers L = FlatLayers();
  FeltHazard f;
  f.centre_m = Eigen::Vector2d(3.0, 2.0);
  f.heading_rad = 0.5 * kPi;  // driving north: the slope runs along y
  f.tilt_rad = 25.0 * kPi / 180;
  f.z_m = 0.4;
  ASSERT_EQ(BlockedAt(L, 3.05, 2.05), planning::Blocked::kUnknown);
  MarkFelt(L, f);
  // Inside the disc: observed, too steep, the slope along y.
  EXPECT_EQ(BlockedAt(L, 2.85, 2.05), planning::Blocked::kTooSteep);
  EXPECT_EQ(BlockedAt(L, 3.15, 1.85), planning::Blocked::kTooSteep);
  const std::size_t k = L.geometry.Linear(L.geometry.IndexOf(2.85, 2.05));
  EXPECT_NEAR(L.phi_y[k], f.tilt_rad, 1e-6);
  EXPECT_NEAR(L.phi_x[k], 0.0, 1e-6);
  // The unknown cell inside the disc is now observed at the robot's height.
  const std::size_t u = L.geometry.Linear(L.geometry.IndexOf(3.05, 2.05));
  EXPECT_EQ(L.state[u], mapping::CellState::kObserved);
  EXPECT_FLOAT_EQ(L.mean_z[u], 0.4f);
  EXPECT_EQ(BlockedAt(L, 3.05, 2.05), planning::Blocked::kTooSteep);
  // Outside it nothing changed.
  EXPECT_EQ(BlockedAt(L, 3.45, 2.05), planning::Blocked::kFree);
  EXPECT_EQ(BlockedAt(L, 2.55, 2.05), planning::Blocked::kFree);
  EXPECT_EQ(BlockedAt(L, 3.15, 2.45), planning::Blocked::kFree);
}

// A bump the planned ground does not explain (a wall's foot, a desk leg): a shallow tilt, but the
// cells become a step the planner keeps the robot away from.
TEST(MarkFelt, AnObstacleIsAStepEvenAtAShallowTilt) {
  mapping::ElevationLayers L = FlatLayers();
  FeltHazard f;
  f.centre_m = Eigen::Vector2d(1.5, 1.5);
  f.tilt_rad = 10.0 * kPi / 180;  // below the 19.3 deg limit: a slope this steep is allowed
  MarkFelt(L, f);
  EXPECT_EQ(BlockedAt(L, 1.55, 1.55), planning::Blocked::kFree);
  f.centre_m = Eigen::Vector2d(1.0, 1.0);
  f.obstacle = true;
  MarkFelt(L, f);
  EXPECT_EQ(BlockedAt(L, 1.05, 1.05), planning::Blocked::kStep);
  EXPECT_EQ(BlockedAt(L, 1.25, 1.05), planning::Blocked::kStep);
  EXPECT_EQ(BlockedAt(L, 1.55, 1.05), planning::Blocked::kFree);  // outside the disc
}

TEST(MarkFelt, DropCellsStayDrops) {
  mapping::ElevationLayers L = FlatLayers();
  FeltHazard f;
  f.centre_m = Eigen::Vector2d(2.05, 2.05);
  f.tilt_rad = 0.5;
  MarkFelt(L, f);
  EXPECT_EQ(L.state[L.geometry.Linear({20, 20})], mapping::CellState::kDrop);
  EXPECT_EQ(BlockedAt(L, 2.05, 2.05), planning::Blocked::kDrop);
}

}  // namespace
}  // namespace pitchlab::mission
