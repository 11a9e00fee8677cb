// The back-off's way back (mission/src/back_trail.hpp): the track kept, the way cut from it, and a
// robot retracing an arc it drove instead of reversing straight off it.

#include "back_trail.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pitchlab::mission {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDt_s = 0.1;  // the mission's control period
constexpr double kSpeed_mps = 0.2, kYawRate_rps = 0.3;  // the mission's back-off and slope turn

struct Unicycle {
  double x = 0, y = 0, yaw = 0;
  void Apply(double v_mps, double omega_rps) {
    x += v_mps * std::cos(yaw) * kDt_s;
    y += v_mps * std::sin(yaw) * kDt_s;
    yaw += omega_rps * kDt_s;
  }
};

// Distance from p to the polyline.
double DistanceTo(const std::vector<Eigen::Vector2d>& line, const Eigen::Vector2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < line.size(); ++i) {
    const Eigen::Vector2d ab = line[i] - line[i - 1];
    const double t = std::clamp((p - line[i - 1]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (line[i - 1] + t * ab - p).norm());
  }
  return best;
}

TEST(BackTrail, KeepsPointsASpacingApartAndAboutTheLengthAsked) {
  BackTrail trail(1.0);
  for (int i = 0; i <= 300; ++i) trail.Add({0.01 * i, 0.0});  // 3 m in 1 cm steps
  const std::vector<Eigen::Vector2d> all = trail.WayBack({3.0, 0.0}, 10.0);
  ASSERT_EQ(all.size(), trail.size() + 1);  // `here`, then every point of the track
  for (std::size_t i = 2; i < all.size(); ++i) {
    // 5 cm apart (the retrace's tolerance) at least, so the next 1 cm step at most beyond
    const double step = (all[i - 1] - all[i]).norm();
    EXPECT_GE(step, 0.05 - 1e-9);
    EXPECT_LE(step, 0.06 + 1e-9);
  }
  // The oldest are dropped while the rest still spans a metre.
  const double span = all[1].x() - all.back().x();
  EXPECT_GE(span, 1.0 - 1e-9);
  EXPECT_LT(span, 1.06);
}

TEST(BackTrail, TheWayBackRunsNewestToOldestAndIsCutAtItsLength) {
  BackTrail trail(5.0);
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                   Eigen::Vector2d(1, 1)}) {
    trail.Add(p);
  }
  const std::vector<Eigen::Vector2d> way = trail.WayBack({1.0, 1.2}, 1.5);
  ASSERT_EQ(way.size(), 4u);
  EXPECT_TRUE(way[0].isApprox(Eigen::Vector2d(1.0, 1.2)));
  EXPECT_TRUE(way[1].isApprox(Eigen::Vector2d(1.0, 1.0)));
  EXPECT_TRUE(way[2].isApprox(Eigen::Vector2d(1.0, 0.0)));
  EXPECT_TRUE(way[3].isApprox(Eigen::Vector2d(0.7, 0.0)));  // 0.2 + 1 + 0.3
  EXPECT_NEAR(PolylineLength(way), 1.5, 1e-12);
}

TEST(BackTrail, AnEmptyTrackIsNoWayBackAndBadInputIsRefused) {
  BackTrail trail(1.0);
  EXPECT_EQ(trail.WayBack({2.0, 3.0}, 0.6).size(), 1u);
  trail.Add({std::nan(""), 0.0});
  EXPECT_EQ(trail.size(), 0u);
  EXPECT_THROW(BackTrail(0.0), std::invalid_argument);
}

// The robot drove forwards round a 1.5 m radius bend; backed off 0.6 m, the retrace goes back
// along the bend in reverse, never turning on the spot, where reversing along the heading ends
// the chord's sagitta (0.6^2 / (2 * 1.5) = 0.12 m) off the track.
TEST(RetraceFollower, ReversesAlongTheBendItCameBy) {
  constexpr double kRadius_m = 1.5;
  BackTrail trail(1.2);
  Unicycle robot;
  for (int i = 0; i < 40; ++i) {  // 0.8 m along the bend (0.2 m/s for 4 s)
    robot.Apply(kSpeed_mps, kSpeed_mps / kRadius_m);
    trail.Add({robot.x, robot.y});
  }
  const Eigen::Vector2d here(robot.x, robot.y);
  const std::vector<Eigen::Vector2d> way = trail.WayBack(here, 0.6);
  ASSERT_GE(PolylineLength(way), kMinRetrace_m);
  PurePursuit retrace(way, RetraceFollower(kSpeed_mps, kYawRate_rps));
  double worst_m = 0;
  int steps = 0;
  for (; steps < 200; ++steps) {
    const DriveCommand c = retrace.Command(robot.x, robot.y, robot.yaw);
    if (c.done) break;
    EXPECT_LT(c.v_mps, 0.0) << "in reverse, and never on the spot";
    EXPECT_LE(std::abs(c.omega_rps), kYawRate_rps + 1e-12);
    robot.Apply(c.v_mps, c.omega_rps);
    worst_m = std::max(worst_m, DistanceTo(way, {robot.x, robot.y}));
  }
  ASSERT_LT(steps, 200);
  EXPECT_LT((Eigen::Vector2d(robot.x, robot.y) - way.back()).norm(), 0.06);
  EXPECT_LT(worst_m, 0.03);
  // Reversing straight for 0.6 m from `here` along the heading: that far off the track.
  const Eigen::Vector2d straight =
      here - 0.6 * Eigen::Vector2d(std::cos(0.8 / kRadius_m), std::sin(0.8 / kRadius_m));
  EXPECT_GT(DistanceTo(way, straight), 0.1);
}

// After a quarter turn on the spot the way back lies beside the robot, ahead of its axle: it
// drives there forwards, bending round, rather than turning on the spot again.
TEST(RetraceFollower, AWayBackAheadOfTheAxleIsDrivenForwardsWithoutTurningOnTheSpot) {
  PurePursuit retrace({{0, 0}, {0.6, 0}}, RetraceFollower(kSpeed_mps, kYawRate_rps));
  Unicycle robot;
  robot.yaw = kPi / 3;  // the way back 60 deg to its right
  int steps = 0;
  for (; steps < 400; ++steps) {
    const DriveCommand c = retrace.Command(robot.x, robot.y, robot.yaw);
    if (c.done) break;
    EXPECT_GE(c.v_mps, 0.0);
    EXPECT_FALSE(c.v_mps == 0.0 && c.omega_rps != 0.0) << "a turn on the spot";
    robot.Apply(c.v_mps, c.omega_rps);
  }
  ASSERT_LT(steps, 400);
  EXPECT_FALSE(retrace.reversing());
}

}  // namespace
}  // namespace pitchlab::mission
