// The mission's default rotation bound on odometry (MissionConfig::odometry_error_deg +
// odometry_error_dps x time) against the simulated base's odometry over what one stop drives:
// it must hold the gyro-corrected heading's error with room to spare, and it relies on the gyro.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "pitchlab/mission/mission.hpp"
#include "pitchlab/sim/sim_base.hpp"
#include "pitchlab/sim/simulation.hpp"

namespace pitchlab::mission {
namespace {

// A floor, and a 10 deg ramp the drive crosses (the wheels slip more on it).
constexpr const char* kRampWorld = R"(<mujoco model="ramp">
  <worldbody>
    <geom name="floor" type="box" pos="0 0 -0.05" size="10 10 0.05"/>
    <geom name="ramp" type="box" pos="1.5 0 0.25" size="1.5 3 0.05" euler="0 -10 0"/>
  </worldbody>
</mujoco>)";

struct Drive {
  double v_mps, omega_rps, seconds;
};

// What a stop's drive looks like: turn on the spot to face the path, drive a curving 3 m onto
// the ramp and over it, turn on the spot on the ramp, come back, stand for the scan. Returns the
// heading error of odometry against the truth after it [deg] and the time it took [s].
std::pair<double, double> HeadingErrorOverAStop(const sim::OdometryConfig& odometry) {
  sim::RobotConfig robot;
  robot.model = sim::P3Model::kP3AT;
  std::unique_ptr<sim::Simulation> s = sim::Simulation::FromString(kRampWorld, "/tmp", robot);
  Result<Eigen::Isometry3d> start = s->PlaceRobot(-2.0, 0.0, 0.0);
  if (!start) throw std::runtime_error(start.error().message);
  sim::SimBase base(*s, odometry);
  const auto yaw = [](const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); };
  const double true_yaw0 = yaw(s->T_world_base().linear());
  Result<sensors::Odometry> odo = base.ReadOdometry();
  if (!odo) throw std::runtime_error(odo.error().message);
  const double odo_yaw0 = odo->yaw_rad;
  const Drive drives[] = {{0.0, 0.8, 2.0}, {0.0, -0.8, 2.0},  {0.4, 0.15, 5.0}, {0.4, -0.15, 5.0},
                          {0.0, 0.8, 4.0}, {0.4, 0.0, 4.0},   {0.0, -0.8, 2.0}, {0.0, 0.0, 8.0}};
  double seconds = 0;
  for (const Drive& d : drives) {
    odo = base.Drive(d.v_mps, d.omega_rps, d.seconds);
    if (!odo) throw std::runtime_error(odo.error().message);
    seconds += d.seconds;
  }
  const double turned_true = yaw(s->T_world_base().linear()) - true_yaw0;
  const double turned_odo = odo->yaw_rad - odo_yaw0;
  return {std::abs(std::remainder(turned_odo - turned_true, 2 * M_PI)) * 180 / M_PI, seconds};
}

double DefaultBound_deg(double seconds) {
  const MissionConfig m;
  return m.odometry_error_deg + m.odometry_error_dps * seconds;
}

TEST(OdometryBound, HoldsTheGyroHeadingsErrorOverAStopWithRoomToSpare) {
  // The simulated base's defaults: heading from the yaw-rate gyro. Over 32 s, 7 rad of turning
  // on a floor and a 10 deg ramp; the bound is 1.96 deg. Measured in missions (benchmarks/README,
  // session 44): at most 0.4 of the bound.
  for (std::uint64_t seed : {1, 2, 3}) {
    sim::OdometryConfig odometry;
    odometry.seed = seed;
    const auto [error_deg, seconds] = HeadingErrorOverAStop(odometry);
    EXPECT_LT(error_deg, 0.5 * DefaultBound_deg(seconds)) << "seed " << seed;
  }
}

TEST(OdometryBound, IsNoBoundForAHeadingFromSkidSteerWheels) {
  // The same drive with the heading from the wheels: a skid-steer base's turns on the spot slip
  // (~10 % of the turn), far beyond what the default bound allows for a gyro.
  sim::OdometryConfig wheels;
  wheels.gyro = false;
  const auto [error_deg, seconds] = HeadingErrorOverAStop(wheels);
  EXPECT_GT(error_deg, DefaultBound_deg(seconds));
}

}  // namespace
}  // namespace pitchlab::mission
