// The rest hold (RestConfig): a parked robot at rest scans as if fully solved; one that creeps
// is never held.

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/sim/sim_rig.hpp"
#include "sim_test_worlds.hpp"

namespace pitchlab::sim {
namespace {

SimRigConfig Config(bool rest) {
  SimRigConfig c;
  c.robot.model = P3Model::kP3AT;
  c.lms200.noise_sigma_m = 0.0;  // the scans differ only where the robot's poses do
  c.rest.enabled = rest;
  return c;
}

// Places the robot, drives a metre-long stretch and takes the seed scan (200 lines, 100 deg).
struct Stop {
  std::unique_ptr<SimRig> rig;
  sensors::Scan3D scan;
};
Stop DriveAndScan(const char* world, double x_m, bool rest) {
  Stop s{SimRig::FromString(world, "/tmp", Config(rest)), {}};
  if (auto pose = s.rig->PlaceRobot(x_m, 0.0, 0.0); !pose) {
    throw std::runtime_error(pose.error().message);
  }
  if (auto odo = s.rig->base().Drive(0.3, 0.0, 1.0); !odo) {
    throw std::runtime_error(odo.error().message);
  }
  Result<sensors::Scan3D> scan = s.rig->Acquire();
  if (!scan) throw std::runtime_error(scan.error().message);
  s.scan = std::move(*scan);
  return s;
}

double Angle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// Flat floor and a wall 3 m ahead: the whole model moves the base by ~1 mm over a scan (the
// laser's weight shifting on the tyres), the held one not at all, so the scan may differ by that.
TEST(RestHold, AScanOnFlatGroundHeldMatchesTheFullySolvedOne) {
  const Stop full = DriveAndScan(testing::kWallWorld, 0.0, false);
  const Stop held = DriveAndScan(testing::kWallWorld, 0.0, true);
  EXPECT_EQ(full.rig->sim().rest_time_s(), 0.0);
  // It is held for a good part of the sweep, else the test shows nothing.
  EXPECT_GT(held.rig->sim().rest_time_s(), 0.25 * held.scan.duration_s);

  // RestConfig bounds the drift a hold may lose to 1 mm and 0.3 mrad over a sweep; the servo's
  // half encoder count (0.005 deg) bounds the pitch.
  constexpr double kPose_m = 0.002, kPose_rad = 0.5e-3, kPitch_rad = 0.01 * M_PI / 180;
  const Eigen::Isometry3d d = full.scan.T_world_base.inverse() * held.scan.T_world_base;
  EXPECT_LT(d.translation().norm(), kPose_m);
  EXPECT_LT(Angle(d.linear()), kPose_rad);
  ASSERT_EQ(full.scan.lines.size(), held.scan.lines.size());
  for (std::size_t k = 0; k < full.scan.lines.size(); ++k) {
    EXPECT_NEAR(full.scan.lines[k].pitch_rad, held.scan.lines[k].pitch_rad, kPitch_rad) << k;
  }
  // The same beams hit (the line and beam of every return), at the same place in the world: a
  // fifth of the LMS200's 1 cm range quantum in RMS; at most one quantum (a reading on the edge
  // of two) plus the pose bound.
  ASSERT_NEAR(static_cast<double>(full.scan.points.size()),
              static_cast<double>(held.scan.points.size()), 0.001 * full.scan.points.size());
  double sum_sq = 0.0, worst = 0.0;
  std::size_t matched = 0;
  for (std::size_t i = 0, j = 0; i < full.scan.points.size() && j < held.scan.points.size();) {
    const sensors::ScanPoint& a = full.scan.points[i];
    const sensors::ScanPoint& b = held.scan.points[j];
    if (a.line != b.line || a.beam != b.beam) {
      (a.line < b.line || (a.line == b.line && a.beam < b.beam)) ? ++i : ++j;
      continue;
    }
    const Eigen::Vector3d pa = full.scan.T_world_base * Eigen::Vector3d(a.x, a.y, a.z);
    const Eigen::Vector3d pb = held.scan.T_world_base * Eigen::Vector3d(b.x, b.y, b.z);
    sum_sq += (pa - pb).squaredNorm();
    worst = std::max(worst, (pa - pb).norm());
    ++matched, ++i, ++j;
  }
  ASSERT_GT(matched, 0.99 * full.scan.points.size());
  const double rms = std::sqrt(sum_sq / matched);
  std::printf("held %.2f of %.2f s; pose %.2f mm %.3f mrad; points rms %.2f mm worst %.2f mm\n",
              held.rig->sim().rest_time_s(), held.scan.duration_s, 1e3 * d.translation().norm(),
              1e3 * Angle(d.linear()), 1e3 * rms, 1e3 * worst);
  EXPECT_LT(rms, 0.002);
  EXPECT_LT(worst, 0.01 + kPose_m);

  // Released by the next drive, it drives off as the fully solved robot does.
  ASSERT_TRUE(full.rig->base().Drive(0.3, 0.0, 2.0));
  ASSERT_TRUE(held.rig->base().Drive(0.3, 0.0, 2.0));
  EXPECT_FALSE(held.rig->sim().resting());
  EXPECT_LT((full.rig->sim().T_world_base().translation() -
             held.rig->sim().T_world_base().translation())
                .norm(),
            kPose_m);
}

// On the 10 deg ramp the wheel hold creeps (0.4 mm/s, 6x RestConfig::max_speed_mps): the state is
// never held and the scan is the fully solved one, bit for bit.
TEST(RestHold, ARobotCreepingDownASlopeIsNeverHeld) {
  const Stop full = DriveAndScan(testing::kBoxFloorWorld, -5.7, false);
  const Stop held = DriveAndScan(testing::kBoxFloorWorld, -5.7, true);
  EXPECT_EQ(held.rig->sim().rest_time_s(), 0.0);
  EXPECT_TRUE(full.scan.T_world_base.isApprox(held.scan.T_world_base, 0.0));
  ASSERT_EQ(full.scan.points.size(), held.scan.points.size());
  EXPECT_TRUE(full.rig->sim().T_world_base().isApprox(held.rig->sim().T_world_base(), 0.0));
}

TEST(RestConfig, RejectsBadValuesNamingTheField) {
  RestConfig c;
  c.window_s = 0.0;
  try {
    c.Validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rest.window_s"), std::string::npos);
  }
  auto sim = Simulation::FromString(testing::kFlatWorld, "/tmp", RobotConfig{});
  RestConfig bad;
  bad.max_speed_mps = -1.0;
  EXPECT_THROW(sim->set_rest_config(bad), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::sim
