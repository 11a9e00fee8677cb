// How far a stop drives (mission/src/drive_length.hpp): up to the unknown margin short of the
// first unobserved cell, a turn when that is too close, a metre into the blind zone after a turn;
// and how far a plan runs over known ground.

#include "drive_length.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pitchlab::mission {
namespace {

constexpr double kDrive_m = 4.0, kMargin_m = 0.5;

TEST(PlanDriveLength, StopsTheMarginShortOfTheFirstUnseenCell) {
  const DriveLength far = PlanDriveLength(kDrive_m, kMargin_m, 10.0, false, false, std::nullopt);
  EXPECT_FALSE(far.turn_only);
  EXPECT_DOUBLE_EQ(far.length_m, kDrive_m);  // a stop's drive at most
  const DriveLength near = PlanDriveLength(kDrive_m, kMargin_m, 2.0, false, false, std::nullopt);
  EXPECT_DOUBLE_EQ(near.length_m, 1.5);
}

// Terrain seed 18: the plan's seen part ended 1.05 m on, at a crack's unseen cells. The robot
// drives 0.55 m, not a metre that would take it 0.05 m from them.
TEST(PlanDriveLength, LessThanAMetreOfSeenGroundIsNotStretchedToAMetre) {
  const DriveLength drive = PlanDriveLength(kDrive_m, kMargin_m, 1.05, false, false, std::nullopt);
  EXPECT_FALSE(drive.turn_only);
  EXPECT_NEAR(drive.length_m, 0.55, 1e-12);
}

TEST(PlanDriveLength, TooCloseToTheUnseenItTurnsOnceThenDrivesAMetre) {
  EXPECT_TRUE(PlanDriveLength(kDrive_m, kMargin_m, 0.8, false, false, std::nullopt).turn_only);
  const DriveLength after_turn = PlanDriveLength(kDrive_m, kMargin_m, 0.8, false, true, std::nullopt);
  EXPECT_FALSE(after_turn.turn_only);
  EXPECT_DOUBLE_EQ(after_turn.length_m, 1.0);
  // More seen ground than a metre after a turn: all of it, as at any stop.
  EXPECT_DOUBLE_EQ(PlanDriveLength(kDrive_m, kMargin_m, 3.0, false, true, std::nullopt).length_m, 2.5);
  // A stop's drive shorter than a metre caps the blind-zone drive too.
  EXPECT_DOUBLE_EQ(PlanDriveLength(0.6, kMargin_m, 0.8, false, true, std::nullopt).length_m, 0.6);
}

// The floor test's third stop: the goal 1.14 m along a plan seen to its end. The margin is for
// unseen ground; there is none, so the robot drives to the goal.
TEST(PlanDriveLength, APlanSeenToItsEndIsDrivenToItsEnd) {
  const DriveLength drive = PlanDriveLength(kDrive_m, kMargin_m, 1.14, true, false, std::nullopt);
  EXPECT_FALSE(drive.turn_only);
  EXPECT_DOUBLE_EQ(drive.length_m, 1.14);
  EXPECT_DOUBLE_EQ(PlanDriveLength(kDrive_m, kMargin_m, 9.0, true, false, std::nullopt).length_m,
                   kDrive_m);  // a stop's drive at most
  // A few waypoints short of the end: the margin again.
  EXPECT_NEAR(PlanDriveLength(kDrive_m, kMargin_m, 1.0, false, false, std::nullopt).length_m, 0.5,
              1e-12);
}

TEST(PlanDriveLength, ARecoveryStopsTheMarginShortOfTheDoubtedCellsEvenAfterATurn) {
  const DriveLength drive = PlanDriveLength(kDrive_m, kMargin_m, 0.8, false, true, 0.9);
  EXPECT_FALSE(drive.turn_only);
  EXPECT_NEAR(drive.length_m, 0.4, 1e-12);
  EXPECT_LT(PlanDriveLength(kDrive_m, kMargin_m, 5.0, false, false, 0.5).length_m, 0.1);  // no way on
}

// A straight plan along row 0 of a 10 x 1 grid of 0.5 m cells, every cell seen level.
struct Corridor {
  mapping::GridGeometry g = mapping::GridGeometry::FromArea(0, 0, 5, 0.5, 0.5);
  planning::TraversabilityGrid grid;
  planning::Path path;
  Corridor() {
    grid.geometry = g;
    grid.z_m.assign(g.cell_count(), 0.0f);
    grid.line_gap.assign(g.cell_count(), false);
    for (int i = 0; i < g.size_x; ++i) {
      const Eigen::Vector2d c = g.CenterOf({i, 0});
      path.cells.push_back({i, 0});
      path.waypoints.push_back({c.x(), c.y(), 0.0});
    }
  }
};

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

TEST(PlanKnownStretch, AllKnownIsSeenToTheEnd) {
  const Corridor c;
  const KnownStretch known = PlanKnownStretch(c.path, c.grid);
  EXPECT_TRUE(known.to_the_end);
  EXPECT_NEAR(known.length_m, 4.5, 1e-12);  // centre of cell 0 to centre of cell 9
}

TEST(PlanKnownStretch, EndsBeforeAnUnseenCellAndBeforeALineGap) {
  Corridor unseen;
  unseen.grid.z_m[6] = kNaN;
  KnownStretch known = PlanKnownStretch(unseen.path, unseen.grid);
  EXPECT_FALSE(known.to_the_end);
  EXPECT_NEAR(known.length_m, 2.5, 1e-12);  // cell 0 to cell 5
  Corridor gap;
  gap.grid.line_gap[3] = true;
  known = PlanKnownStretch(gap.path, gap.grid);
  EXPECT_FALSE(known.to_the_end);
  EXPECT_NEAR(known.length_m, 1.0, 1e-12);
}

// The robot's own cell is where it stands: it counts whatever the map says of it.
TEST(PlanKnownStretch, TheRobotsOwnCellCountsAsKnown) {
  Corridor c;
  c.grid.z_m[0] = kNaN;
  const KnownStretch known = PlanKnownStretch(c.path, c.grid);
  EXPECT_TRUE(known.to_the_end);
  EXPECT_NEAR(known.length_m, 4.5, 1e-12);
}

TEST(PlanKnownStretch, APlanOfOneCellIsSeenToItsEnd) {
  Corridor c;
  c.path.waypoints.resize(1);
  c.path.cells.resize(1);
  const KnownStretch known = PlanKnownStretch(c.path, c.grid);
  EXPECT_TRUE(known.to_the_end);
  EXPECT_EQ(known.length_m, 0.0);
}

// A straight plan along y = 0.55 m over a 6 x 2 m grid of 0.1 m cells for a 0.5 m wide robot
// (the footprint reaches 0.3 m: half its width and half a cell), all of it a 10 deg side slope
// (where odometry drifts), free but for the cells set as hazards.
struct OpenGround {
  mapping::GridGeometry g = mapping::GridGeometry::FromArea(0, 0, 6, 2, 0.1);
  planning::TraversabilityGrid grid;
  planning::Path path;
  explicit OpenGround(double tilt_deg = 10.0) {
    grid.geometry = g;
    grid.config.robot.width_m = 0.5;
    grid.z_m.assign(g.cell_count(), 0.0f);
    grid.phi_x_rad.assign(g.cell_count(), 0.0f);
    grid.phi_y_rad.assign(g.cell_count(), static_cast<float>(tilt_deg * M_PI / 180));
    grid.blocked.assign(g.cell_count(), planning::Blocked::kFree);
    for (int i = 0; i < g.size_x; ++i) {
      const Eigen::Vector2d c = g.CenterOf({i, 5});
      path.cells.push_back({i, 5});
      path.waypoints.push_back({c.x(), c.y(), 0.0});
    }
  }
  void Set(int i, int j, planning::Blocked b) { grid.blocked[g.Linear({i, j})] = b; }
};

// A step cell centred at (4.05, 1.25), 0.7 m beside the plan. With 0.2 m of drift a metre, the
// waypoint 3.4 m on is the first closer to it than the reach and the drift: at x = 3.45 the cell
// is sqrt(0.6^2 + 0.7^2) = 0.922 m away, under 0.3 + 0.2 x 3.4 = 0.98 (at x = 3.35: 0.990 against
// 0.96).
TEST(PlanClearStretch, EndsWhereTheDriftCouldReachAHazardBesideThePlan) {
  OpenGround o;
  o.Set(40, 12, planning::Blocked::kStep);
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 10.0), 3.4, 1e-9);
  // Without drift the plan keeps the footprint off it all the way (0.7 m > 0.3 m).
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.0, 10.0), 5.9, 1e-9);
  // Twice the drift: at x = 2.85 the cell is 1.389 m away, under 0.3 + 0.4 x 2.8 = 1.42 (at
  // x = 2.75: 1.476 against 1.38).
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.4, 10.0), 2.8, 1e-9);
}

// A floor (within kFloorTilt_rad) accrues no drift: the hazard 0.7 m beside
// the plan never comes within the footprint's reach. The plan sloped only from cell 20 on (its
// waypoints from x = 2.05): the drift counts from the step into it, 0.2 m a metre; at x = 3.95 the
// cell is 0.707 m away against 0.3 + 0.2 x 2.0 = 0.70, at x = 4.05 0.7 m against 0.72.
TEST(PlanClearStretch, AFloorAccruesNoDrift) {
  OpenGround level(0.5);
  level.Set(40, 12, planning::Blocked::kStep);
  EXPECT_NEAR(PlanClearStretch(level.path, level.grid, 0.2, 10.0), 5.9, 1e-9);
  OpenGround half(0.0);
  half.Set(40, 12, planning::Blocked::kStep);
  for (int j = 0; j < half.g.size_y; ++j)
    for (int i = 20; i < half.g.size_x; ++i)
      half.grid.phi_y_rad[half.g.Linear({i, j})] = static_cast<float>(10 * M_PI / 180);
  EXPECT_NEAR(PlanClearStretch(half.path, half.grid, 0.2, 10.0), 4.0, 1e-9);
}

// Every kind of hazard the footprint may not stand on counts (a step, a too-steep and a drop
// cell); the margin around them (kNearHazard) and unseen ground do not: the plan already keeps off
// the one, and the other is for the unknown margin.
TEST(PlanClearStretch, CountsStepsSlopesAndDropsNotTheirMarginsOrTheUnseen) {
  for (const planning::Blocked b :
       {planning::Blocked::kStep, planning::Blocked::kTooSteep, planning::Blocked::kDrop}) {
    OpenGround o;
    o.Set(40, 12, b);
    EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 10.0), 3.4, 1e-9) << static_cast<int>(b);
  }
  for (const planning::Blocked b : {planning::Blocked::kNearHazard, planning::Blocked::kUnknown}) {
    OpenGround o;
    for (int i = 0; i < o.g.size_x; ++i) o.Set(i, 8, b);
    EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 10.0), 5.9, 1e-9) << static_cast<int>(b);
  }
}

// The search ends at `up_to_m` along the plan (a stop's drive): the hazard 3.4 m on is not looked
// for by a 2.95 m drive, and the stretch is the arc of the first waypoint at or past it (3.0 m).
TEST(PlanClearStretch, LooksNoFartherThanItIsAskedTo) {
  OpenGround o;
  o.Set(40, 12, planning::Blocked::kStep);
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 2.95), 3.0, 1e-9);
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 4.0), 3.4, 1e-9);
}

// A hazard by the plan's start: the robot stands beside it, and the stretch is nothing.
TEST(PlanClearStretch, AHazardWithinTheReachOfTheStartLeavesNoStretch) {
  OpenGround o;
  o.Set(0, 7, planning::Blocked::kTooSteep);  // (0.05, 0.75): 0.2 m from the start
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 10.0), 0.0, 1e-12);
  o.path.waypoints.resize(1);
  EXPECT_NEAR(PlanClearStretch(o.path, o.grid, 0.2, 10.0), 0.0, 1e-12);
}

// A drive the plan's clearance allows is not cut; one it does not is cut to the clear stretch, but
// to a metre at least, and never longer than it was.
TEST(CutForDrift, CutsToTheClearStretchButNotBelowAMetre) {
  EXPECT_DOUBLE_EQ(CutForDrift(3.0, 5.0), 3.0);
  EXPECT_DOUBLE_EQ(CutForDrift(3.0, 2.2), 2.2);
  EXPECT_DOUBLE_EQ(CutForDrift(3.0, 0.4), kMinDriftCut_m);
  EXPECT_DOUBLE_EQ(CutForDrift(0.6, 0.0), 0.6);
  EXPECT_DOUBLE_EQ(CutForDrift(0.6, 0.8), 0.6);
}

// The shortest drive is one the path follower drives: a straight path just that long is not done
// at its start, one just shorter than the follower's tolerance is (and the robot would not move).
TEST(MinDriveLength, IsADriveThePathFollowerDoesNotCountAsDoneBeforeItMoves) {
  for (double tolerance_m : {0.05, 0.15, 0.4}) {
    PurePursuitConfig follower;
    follower.goal_tolerance_m = tolerance_m;
    const double min_m = MinDriveLength(follower);
    EXPECT_GE(min_m, 0.1);
    PurePursuit long_enough({{0, 0}, {min_m + 1e-6, 0}}, follower);
    EXPECT_FALSE(long_enough.Command(0, 0, 0).done) << "tolerance " << tolerance_m;
    PurePursuit too_short({{0, 0}, {tolerance_m - 1e-6, 0}}, follower);
    EXPECT_TRUE(too_short.Command(0, 0, 0).done) << "tolerance " << tolerance_m;
  }
}

}  // namespace
}  // namespace pitchlab::mission
