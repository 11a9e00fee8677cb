#include "pitchlab/mission/path_follower.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDt_s = 0.05;

struct Unicycle {
  double x = 0, y = 0, yaw = 0;
  void Apply(const DriveCommand& c) {
    x += c.v_mps * std::cos(yaw) * kDt_s;
    y += c.v_mps * std::sin(yaw) * kDt_s;
    yaw += c.omega_rps * kDt_s;
  }
};

// Runs the follower on an ideal unicycle; returns steps taken (or -1 when it never finished) and
// the largest distance from the path polyline seen on the way.
int Follow(PurePursuit& follower, Unicycle& robot, const PurePursuitConfig& config,
           double* max_speed = nullptr) {
  for (int step = 0; step < 20000; ++step) {
    const DriveCommand c = follower.Command(robot.x, robot.y, robot.yaw);
    EXPECT_LE(std::abs(c.omega_rps), config.max_yaw_rate_rps + 1e-12);
    EXPECT_EQ(c.v_mps < 0, follower.reversing()) << "drives one way all along";
    if (max_speed) *max_speed = std::max(*max_speed, c.v_mps);
    if (c.done) return step;
    robot.Apply(c);
  }
  return -1;
}

TEST(PurePursuit, DrivesAStraightPathToItsEndWithinTolerance) {
  PurePursuitConfig config;
  PurePursuit follower({{0, 0}, {5, 0}}, config);
  Unicycle robot;
  double max_speed = 0;
  ASSERT_GT(Follow(follower, robot, config, &max_speed), 0);
  EXPECT_NEAR(robot.x, 5.0, config.goal_tolerance_m);
  EXPECT_NEAR(robot.y, 0.0, 0.01);
  EXPECT_NEAR(max_speed, config.max_speed_mps, 1e-9);
}

TEST(PurePursuit, WithoutReverseTurnsOnTheSpotWhenThePathStartsBehind) {
  PurePursuitConfig config;
  config.reverse = false;
  PurePursuit follower({{0, 0}, {-3, 0}}, config);
  Unicycle robot;
  const DriveCommand first = follower.Command(0, 0, 0);
  EXPECT_EQ(first.v_mps, 0.0);
  EXPECT_NEAR(std::abs(first.omega_rps), config.max_yaw_rate_rps, 1e-12);
  EXPECT_FALSE(follower.reversing());
  ASSERT_GT(Follow(follower, robot, config), 0);
  EXPECT_NEAR(robot.x, -3.0, config.goal_tolerance_m);
}

// A skid-steer robot turning on the spot on a slope slides downhill: a path that starts behind it
// is driven backwards, with no turn, and its bends are followed as closely as forwards.
TEST(PurePursuit, ReversesAlongAPathThatStartsBehindWithoutTurningOnTheSpot) {
  PurePursuitConfig config;
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {-3, 0}, {-3, -2}};
  PurePursuit follower(path, config);
  Unicycle robot;
  const DriveCommand first = follower.Command(0, 0, 0);
  EXPECT_LT(first.v_mps, 0.0);
  EXPECT_TRUE(follower.reversing());
  double worst_m = 0;
  int steps = 0;
  for (; steps < 5000; ++steps) {
    const DriveCommand c = follower.Command(robot.x, robot.y, robot.yaw);
    if (c.done) break;
    EXPECT_LE(c.v_mps, 0.0);
    robot.Apply(c);
    const double d1 = robot.x >= -3 ? std::abs(robot.y) : std::hypot(robot.x + 3, robot.y);
    const double d2 = robot.y <= 0 ? std::abs(robot.x + 3) : std::hypot(robot.x + 3, robot.y);
    worst_m = std::max(worst_m, std::min(d1, d2));
    if (robot.x > -2.5) EXPECT_NEAR(robot.yaw, 0.0, 1e-9) << "no turn on the straight";
  }
  ASSERT_LT(steps, 5000);
  EXPECT_NEAR(robot.x, -3.0, config.goal_tolerance_m);
  EXPECT_NEAR(robot.y, -2.0, config.goal_tolerance_m);
  EXPECT_LT(worst_m, config.lookahead_m / 2);
  // Backing round the bend to the right (-y) turns the robot's nose to the left (+yaw).
  EXPECT_NEAR(robot.yaw, kPi / 2, 0.3);
}

// A path off to the side is still driven forwards: only one that a turn on the spot would start
// is reversed along.
TEST(PurePursuit, APathToTheSideIsDrivenForwards) {
  PurePursuitConfig config;
  PurePursuit follower({{0, 0}, {0, 3}}, config);
  Unicycle robot;
  ASSERT_GT(Follow(follower, robot, config), 0);
  EXPECT_FALSE(follower.reversing());
  EXPECT_NEAR(robot.y, 3.0, config.goal_tolerance_m);
}

TEST(PurePursuit, FollowsAnLShapedPathClosely) {
  PurePursuitConfig config;
  const std::vector<Eigen::Vector2d> path = {{0, 0}, {4, 0}, {4, 4}};
  PurePursuit follower(path, config);
  Unicycle robot;
  double worst_m = 0;
  for (int step = 0; step < 5000; ++step) {
    const DriveCommand c = follower.Command(robot.x, robot.y, robot.yaw);
    if (c.done) break;
    robot.Apply(c);
    // Distance from the L: corner cutting is bounded by the lookahead.
    const double d1 = robot.x <= 4 ? std::abs(robot.y) : std::hypot(robot.x - 4, robot.y);
    const double d2 = robot.y >= 0 ? std::abs(robot.x - 4) : std::hypot(robot.x - 4, robot.y);
    worst_m = std::max(worst_m, std::min(d1, d2));
  }
  EXPECT_NEAR(robot.x, 4.0, config.goal_tolerance_m);
  EXPECT_NEAR(robot.y, 4.0, config.goal_tolerance_m);
  EXPECT_LT(worst_m, config.lookahead_m / 2);
  EXPECT_LT(follower.remaining_m(), config.goal_tolerance_m);
}

TEST(PurePursuit, ASinglePointPathIsDoneWhenThere) {
  PurePursuit follower({{1, 1}}, PurePursuitConfig{});
  EXPECT_TRUE(follower.Command(1.05, 1.0, kPi).done);
  EXPECT_FALSE(follower.Command(3.0, 1.0, 0).done);
}

TEST(PurePursuit, RejectsAnEmptyPathAndBadConfig) {
  EXPECT_THROW(PurePursuit({}, PurePursuitConfig{}), std::invalid_argument);
  PurePursuitConfig bad;
  bad.lookahead_m = 0;
  EXPECT_THROW(PurePursuit({{0, 0}}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mission
