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
