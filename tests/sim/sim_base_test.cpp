#include "pitchlab/sim/sim_base.hpp"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "sim_test_worlds.hpp"

namespace pitchlab::sim {
namespace {

using testing::kFlatWorld;

constexpr double kDistanceTolerance = 0.05;  // relative, for tyre slip and servo lag [1]
constexpr double kOdometryAgreement = 0.03;  // odometry vs truth, noise off [1]

double Yaw(const Eigen::Isometry3d& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

struct Rig {
  std::unique_ptr<Simulation> sim;
  std::unique_ptr<SimBase> base;
  Eigen::Isometry3d start;
};

Rig Make(P3Model model, const OdometryConfig& odometry = {}) {
  RobotConfig robot;
  robot.model = model;
  Rig s;
  s.sim = Simulation::FromString(kFlatWorld, "/tmp", robot);
  Result<Eigen::Isometry3d> pose = s.sim->PlaceRobot(-2.0, 0.0, 0.0);
  if (!pose) throw std::runtime_error(pose.error().message);
  s.start = *pose;
  s.base = std::make_unique<SimBase>(*s.sim, odometry);
  return s;
}

// Distance covered from rest when holding v for T with acceleration limit a (trapezoid ramp).
double RampedDistance(double v, double T, double a) { return v * T - v * v / (2 * a); }

class BaseModels : public ::testing::TestWithParam<P3Model> {};
INSTANTIATE_TEST_SUITE_P(Base, BaseModels, ::testing::Values(P3Model::kP3AT, P3Model::kP3DX),
                         [](const auto& info) {
                           return std::string(info.param == P3Model::kP3AT ? "P3AT" : "P3DX");
                         });

TEST_P(BaseModels, DrivingAtPointThreeForThreeSecondsCoversTheRampedDistance) {
  Rig s = Make(GetParam());
  Result<sensors::Odometry> odo = s.base->Drive(0.3, 0.0, 3.0);
  ASSERT_TRUE(odo) << odo.error().message;
  const Eigen::Isometry3d end = s.sim->T_world_base();
  const Eigen::Vector3d moved = s.start.inverse() * end.translation();
  const double expected = RampedDistance(0.3, 3.0, s.sim->params().max_accel_mps2);
  EXPECT_NEAR(moved.x(), expected, kDistanceTolerance * expected);
  EXPECT_NEAR(moved.y(), 0.0, 0.02);
  EXPECT_NEAR(odo->x_m, moved.x(), kOdometryAgreement * expected);
  EXPECT_NEAR(odo->y_m, moved.y(), 0.02);
  EXPECT_NEAR(odo->v_mps, 0.3, 0.02);
  EXPECT_FALSE(odo->stalled);
}

TEST(SimBase, P3DxTurnsNinetyDegreesAtHalfARadianPerSecondForPiSeconds) {
  Rig s = Make(P3Model::kP3DX);
  Result<sensors::Odometry> odo = s.base->Drive(0.0, 0.5, M_PI);
  ASSERT_TRUE(odo) << odo.error().message;
  const double turned = Yaw(s.start.inverse() * s.sim->T_world_base());
  const double ramp_loss = 0.5 * 0.5 / (2 * s.sim->params().max_yaw_accel_rps2);
  // Each wheel touches the floor at two points that scrub when turning on the spot; with the
  // firm elliptic friction cones (no creep on slopes) that costs the DX ~5 deg of the 86 here.
  EXPECT_NEAR(turned, M_PI / 2 - ramp_loss, 7.0 * M_PI / 180);
  EXPECT_NEAR(odo->yaw_rad, turned, kOdometryAgreement * turned);
  const Eigen::Vector3d moved = s.start.inverse() * s.sim->T_world_base().translation();
  EXPECT_LT(moved.norm(), 0.02);  // turns on the spot
}

TEST(SimBase, P3AtSkidSteerTurnsRoughlyNinetyDegrees) {
  Rig s = Make(P3Model::kP3AT);
  Result<sensors::Odometry> odo = s.base->Drive(0.0, 0.5, M_PI);
  ASSERT_TRUE(odo) << odo.error().message;
  const double turned = Yaw(s.start.inverse() * s.sim->T_world_base());
  EXPECT_NEAR(turned, M_PI / 2, 10.0 * M_PI / 180);
  EXPECT_NEAR(odo->yaw_rad, turned, 0.1 * turned);  // skid-steer slip: a looser bound
}

// Turning on the spot, every wheel of a skid-steer base slips sideways, so friction no longer
// holds the robot against the slope's pull: it slides downhill as it turns. Coulomb friction
// (mu ~ 1) and a wheel 0.13 m from the axle's centre give a few centimetres per quarter turn on
// 10 deg; the simulator's soft contacts slide more. The follower reverses along a path behind the
// robot rather than turn round (path_follower.hpp) because of this.
TEST(SimBase, P3AtTurningOnTheSpotOnASlopeSlidesDownhill) {
  RobotConfig robot;
  robot.model = P3Model::kP3AT;
  auto sim = Simulation::FromString(testing::kBoxFloorWorld, "/tmp", robot);
  Result<Eigen::Isometry3d> pose = sim->PlaceRobot(-5.0, 0.0, 1.0);  // the 10 deg ramp, across it
  ASSERT_TRUE(pose) << pose.error().message;
  SimBase base(*sim);
  ASSERT_TRUE(base.Drive(0.0, 0.0, 1.0));
  const Eigen::Vector3d before = sim->T_world_base().translation();
  ASSERT_TRUE(base.Drive(0.0, 0.3, M_PI / 2 / 0.3));
  const Eigen::Vector3d moved = sim->T_world_base().translation() - before;
  EXPECT_GT(moved.x(), 0.03) << "downhill is +x on the ramp";
  EXPECT_LT(moved.x(), 0.3);
  EXPECT_LT(std::abs(moved.y()), 0.5 * moved.x()) << "mostly straight down the slope";
}

TEST(SimBase, ClampsToTheP3Limits) {
  Rig s = Make(P3Model::kP3AT);
  Result<sensors::Odometry> odo = s.base->Drive(5.0, 0.0, 2.5);
  ASSERT_TRUE(odo);
  EXPECT_NEAR(s.base->command()[0], s.sim->params().max_speed_mps, 1e-9);
  EXPECT_FALSE(s.base->Drive(std::nan(""), 0.0, 1.0));
  ASSERT_TRUE(s.base->Stop());
  EXPECT_LT(s.sim->BaseSpeeds()[0], 0.01);
}

// E_STOP "overrides decel" (ARIA's ArCommands): from 0.5 m/s a stop ramped at the P3's 0.5 m/s^2
// is still at 0.4 m/s after 0.2 s; the emergency stop holds the wheels at once.
TEST(SimBase, AnEmergencyStopBrakesWithoutTheRamp) {
  Rig ramped = Make(P3Model::kP3AT), emergency = Make(P3Model::kP3AT);
  for (Rig* s : {&ramped, &emergency}) ASSERT_TRUE(s->base->Drive(0.5, 0.0, 2.0));
  ASSERT_NEAR(ramped.sim->BaseSpeeds()[0], 0.5, 0.03);
  ASSERT_TRUE(ramped.base->Drive(0.0, 0.0, 0.2));
  emergency.base->EmergencyStop();
  EXPECT_TRUE(emergency.base->command().isZero());
  ASSERT_TRUE(emergency.base->Drive(0.0, 0.0, 0.2));
  EXPECT_NEAR(ramped.sim->BaseSpeeds()[0], 0.4, 0.03);
  EXPECT_LT(emergency.sim->BaseSpeeds()[0], 0.1);
}

std::vector<double> OdometryBytes(std::uint64_t seed) {
  OdometryConfig c;
  c.seed = seed;
  c.scale_sigma = 0.01;
  c.increment_sigma = 0.05;
  c.track_error = 0.02;
  Rig s = Make(P3Model::kP3DX, c);
  std::vector<double> out;
  for (double omega : {0.0, 0.3, -0.3}) {
    const sensors::Odometry o = *s.base->Drive(0.25, omega, 1.0);
    out.insert(out.end(), {o.stamp_s, o.x_m, o.y_m, o.yaw_rad, o.v_mps, o.omega_rps});
  }
  return out;
}

TEST(SimBase, SameSeedGivesTheSameOdometryBytes) {
  const std::vector<double> a = OdometryBytes(7), b = OdometryBytes(7), c = OdometryBytes(8);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_NE(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)), 0);
}

TEST(OdometryConfig, RejectsBadValuesNamingTheField) {
  OdometryConfig c;
  c.ticks_per_rev = 0;
  try {
    c.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ticks_per_rev"), std::string::npos);
  }
}

}  // namespace
}  // namespace pitchlab::sim
