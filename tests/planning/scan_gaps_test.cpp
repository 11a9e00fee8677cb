// Gaps between scan lines (planning/src/scan_gaps.cpp): unknown cells that rays crossed close
// above the ground on both sides of them are ground when the robot's wheels roll over them.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/planner.hpp"

namespace pitchlab::planning {
namespace {

constexpr double kCell = 0.1;
constexpr int kSizeX = 30, kSizeY = 20;

// A level floor of 3 x 2 m in 0.1 m cells, 4 points a cell, with columns [gap_from, gap_to)
// unseen; a ray crossed each of their cells `ray_above_m` over the floor (+inf: none did).
mapping::ElevationLayers FloorWithGap(int gap_from, int gap_to, double ray_above_m) {
  mapping::ElevationMap map(mapping::GridGeometry{0, 0, kCell, kSizeX, kSizeY});
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < kSizeY; ++j)
    for (int i = 0; i < kSizeX; ++i) {
      if (i >= gap_from && i < gap_to) continue;
      for (const double dx : {0.25, 0.75})
        for (const double dy : {0.25, 0.75})
          pts.emplace_back((i + dx) * kCell, (j + dy) * kCell, 0.0f);
    }
  (void)map.InsertPoints(pts.data(), pts.size());
  mapping::ElevationLayers L = mapping::ComputeLayers(map);
  for (int j = 0; j < kSizeY; ++j)
    for (int i = gap_from; i < gap_to; ++i)
      L.clearance_z[L.geometry.Linear({i, j})] = static_cast<float>(ray_above_m);
  return L;
}

// A level floor as FloorWithGap's, 4 points a cell 0.01 m either side of x0 (so they span
// sqrt(3) x 0.01 m either side of it), x0 `left` cells from the centre in the cells left of the
// gap and `right` cells in those right of it (positive: towards +x); a ray crossed the gap 0.03 m
// up.
mapping::ElevationLayers FloorWithPointsAt(int gap_from, int gap_to, double left, double right) {
  mapping::ElevationMap map(mapping::GridGeometry{0, 0, kCell, kSizeX, kSizeY});
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < kSizeY; ++j)
    for (int i = 0; i < kSizeX; ++i) {
      if (i >= gap_from && i < gap_to) continue;
      const double x0 = (i + 0.5 + (i < gap_from ? left : right)) * kCell;
      for (const double dx : {-0.01, 0.01})
        for (const double dy : {0.25, 0.75}) pts.emplace_back(x0 + dx, (j + dy) * kCell, 0.0f);
    }
  (void)map.InsertPoints(pts.data(), pts.size());
  mapping::ElevationLayers L = mapping::ComputeLayers(map);
  for (int j = 0; j < kSizeY; ++j)
    for (int i = gap_from; i < gap_to; ++i) L.clearance_z[L.geometry.Linear({i, j})] = 0.03f;
  return L;
}

Blocked At(const TraversabilityGrid& T, int i, int j) {
  return T.blocked[T.geometry.Linear({i, j})];
}

bool PathAcross(const TraversabilityGrid& T) {
  return PlanPath(T, {0.6, 1.0}, {2.4, 1.0}, Algorithm::kAStar).has_value();
}

TEST(ScanGaps, TheWidestGapAWheelRollsOverFollowsItsRadiusAndTheStepLimit) {
  // 2 sqrt(r^2 - (r - step)^2): P3-AT r 0.1075, step 0.089; P3-DX's caster r 0.04, step 0.025.
  EXPECT_NEAR(MaxBridgedGap(RobotLimits::P3AT()), 0.2118, 1e-4);
  EXPECT_NEAR(MaxBridgedGap(RobotLimits::P3DX()), 0.0742, 1e-4);
  RobotLimits big_step = RobotLimits::P3AT();
  big_step.step_max_m = 0.5;  // deeper than the wheel: the whole wheel fits in
  EXPECT_NEAR(MaxBridgedGap(big_step), 2 * 0.1075, 1e-9);
}

TEST(ScanGaps, AOneCellGapRaysCrossedJustAboveTheFloorIsGround) {
  const PlannerConfig p3at;  // unknown cells forbidden
  const TraversabilityGrid T = BuildTraversability(FloorWithGap(15, 16, 0.03), p3at);
  EXPECT_EQ(T.bridged_cells, static_cast<std::size_t>(kSizeY));
  EXPECT_EQ(At(T, 15, 10), Blocked::kFree);
  EXPECT_NEAR(T.z_m[T.geometry.Linear({15, 10})], 0.0, 1e-6);
  EXPECT_TRUE(PathAcross(T));
  // Two cells (0.2 m) are within the P3-AT's 0.21 m too.
  EXPECT_TRUE(PathAcross(BuildTraversability(FloorWithGap(15, 17, 0.03), p3at)));
}

TEST(ScanGaps, AGapWiderBetweenItsPointsThanTheWheelsSpanIsALineGap) {
  const PlannerConfig p3at;
  const auto line_gap = [&](const mapping::ElevationLayers& L) {
    const TraversabilityGrid T = BuildTraversability(L, p3at);
    EXPECT_GE(T.bridged_cells, static_cast<std::size_t>(kSizeY));  // ground for the planner
    EXPECT_EQ(At(T, 15, 10), Blocked::kFree);
    return T.line_gap[T.geometry.Linear({15, 10})];
  };
  // Two cells, their bounding points 0.3 cell towards the gap: 0.205 m apart, within the
  // P3-AT's 0.212 m; about the ends' centres 0.265 m apart, which only a gap between scan lines
  // bridges.
  EXPECT_FALSE(line_gap(FloorWithPointsAt(15, 17, 0.3, -0.3)));
  EXPECT_TRUE(line_gap(FloorWithPointsAt(15, 17, 0.0, 0.0)));
  // One cell whose points lie 0.3 cell away from it: 0.225 m apart; about the centres 0.165 m.
  EXPECT_TRUE(line_gap(FloorWithPointsAt(15, 16, -0.3, 0.3)));
  EXPECT_FALSE(line_gap(FloorWithPointsAt(15, 16, 0.0, 0.0)));
}

TEST(ScanGaps, WhatTheScanCannotRuleOutStaysUnknown) {
  const PlannerConfig p3at;
  const auto blocked_across = [&](const mapping::ElevationLayers& L, const PlannerConfig& c) {
    const TraversabilityGrid T = BuildTraversability(L, c);
    EXPECT_EQ(T.bridged_cells, 0u);
    EXPECT_EQ(At(T, 15, 10), Blocked::kUnknown);
    return !PathAcross(T);
  };
  // No ray crossed it: anything could stand there.
  EXPECT_TRUE(blocked_across(FloorWithGap(15, 16, std::numeric_limits<double>::infinity()), p3at));
  // The lowest ray passed 0.15 m up: a box taller than the 0.089 m step may stand under it.
  EXPECT_TRUE(blocked_across(FloorWithGap(15, 16, 0.15), p3at));
  // Three cells (0.3 m) are wider than a P3-AT wheel rolls over.
  EXPECT_TRUE(blocked_across(FloorWithGap(15, 18, 0.03), p3at));
  // The P3-DX's 8 cm caster drops into a 0.1 m hole deeper than its 2.5 cm step.
  PlannerConfig p3dx;
  p3dx.robot = RobotLimits::P3DX();
  EXPECT_TRUE(blocked_across(FloorWithGap(15, 16, 0.03), p3dx));
}

TEST(ScanGaps, WithUnknownCellsPenalisedABridgedGapCostsWhatGroundCosts) {
  PlannerConfig penalise;
  penalise.unknown = UnknownPolicy::kPenalise;
  penalise.unknown_penalty = 5.0;
  const TraversabilityGrid bridged = BuildTraversability(FloorWithGap(15, 16, 0.03), penalise);
  const TraversabilityGrid open =
      BuildTraversability(FloorWithGap(15, 16, std::numeric_limits<double>::infinity()), penalise);
  const std::size_t k = bridged.geometry.Linear({15, 10}), ground = k + 2;
  EXPECT_FLOAT_EQ(bridged.enter_cost[k], bridged.enter_cost[ground]);
  EXPECT_GE(open.enter_cost[k], 5.0f);
}

}  // namespace
}  // namespace pitchlab::planning
