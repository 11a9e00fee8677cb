// SimPitchAxis, SimLineScanner and SimRig against tiny inline worlds with known answers.

#include <cmath>

#include <gtest/gtest.h>

#include "pitchlab/sim/sim_rig.hpp"
#include "sim_test_worlds.hpp"

namespace pitchlab::sim {
namespace {

using testing::kWallWorld;

constexpr double kDeg = M_PI / 180.0;
constexpr double kRangeTolerance_m = 0.012;  // 1 cm quantization + settling sag
const std::chrono::milliseconds kTimeout(2000);

SimRigConfig QuietConfig(CasterKind caster = CasterKind::kEmbree) {
  SimRigConfig c;
  c.robot.model = P3Model::kP3AT;
  c.lms200.noise_sigma_m = 0.0;
  c.caster = caster;
  c.pattern.pitch_start_deg = -10.0;
  c.pattern.pitch_end_deg = 10.0;
  c.pattern.lines = 5;
  return c;
}

std::unique_ptr<SimRig> MakeRig(const SimRigConfig& config) {
  auto rig = SimRig::FromString(kWallWorld, "/tmp", config);
  Result<Eigen::Isometry3d> pose = rig->PlaceRobot(0.0, 0.0, 0.0);
  if (!pose) throw std::runtime_error(pose.error().message);
  return rig;
}

TEST(SimPitchAxis, MoveToTenDegreesReachesTheNearestServoStep) {
  auto rig = MakeRig(QuietConfig());
  const double t0 = rig->sim().time_s();
  Result<double> encoder = rig->pitch_axis().MoveTo(10.0 * kDeg, kTimeout);
  ASSERT_TRUE(encoder) << encoder.error().message;
  const double step = 22 * 0.45 * kDeg;  // 10 / 0.45 = 22.2 steps
  const double count = 2 * M_PI / rig->config().pitch_unit.encoder_counts_per_rev;
  EXPECT_NEAR(*encoder, step, count);
  EXPECT_NEAR(rig->sim().pitch_rad(), step, count / 2);  // the joint really is there
  EXPECT_GE(rig->sim().time_s() - t0, rig->pitch_axis().model().MoveTime(0.0, step) - 1e-9);
  EXPECT_NEAR(*rig->pitch_axis().ReadEncoder(), *encoder, 1e-12);
  // It holds the angle while the scanner keeps the simulation running.
  rig->sim().StepFor(1.0);
  EXPECT_NEAR(rig->sim().pitch_rad(), step, count / 2);
}

TEST(SimPitchAxis, EveryStepOfACoarseSweepSettlesOnItsServoStep) {
  auto rig = MakeRig(QuietConfig());
  const sensors::PitchUnitModel& unit = rig->pitch_axis().model();
  for (int line = 0; line < 40; ++line) {  // a 40-line sweep over the seed's 100 deg
    const double target_deg = -40.0 + line * 100.0 / 39;
    Result<double> encoder = rig->pitch_axis().MoveTo(target_deg * kDeg, kTimeout);
    ASSERT_TRUE(encoder) << target_deg << " deg: " << encoder.error().message;
    const double settle_tolerance = 0.45 * kDeg;  // one servo step
    EXPECT_NEAR(*encoder, unit.StepAngle(unit.StepFor(target_deg * kDeg)), settle_tolerance);
  }
}

TEST(SimPitchAxis, TooShortATimeoutIsATimeoutError) {
  auto rig = MakeRig(QuietConfig());
  Result<double> encoder = rig->pitch_axis().MoveTo(80.0 * kDeg, std::chrono::milliseconds(100));
  ASSERT_FALSE(encoder);
  EXPECT_EQ(encoder.error().code, Error::Code::kTimeout);
}

class BothCasters : public ::testing::TestWithParam<CasterKind> {};
INSTANTIATE_TEST_SUITE_P(Sim, BothCasters,
                         ::testing::Values(CasterKind::kEmbree, CasterKind::kMujoco),
                         [](const auto& info) {
                           return std::string(info.param == CasterKind::kEmbree ? "Embree"
                                                                                : "Mujoco");
                         });

TEST_P(BothCasters, ALineOfAWallGivesTheKnownRanges) {
  auto rig = MakeRig(QuietConfig(GetParam()));
  const double t0 = rig->sim().time_s();
  Result<sensors::LaserLine> line = rig->scanner().NextLine(kTimeout);
  ASSERT_TRUE(line) << line.error().message;
  EXPECT_DOUBLE_EQ(line->stamp_s, t0);
  EXPECT_NEAR(rig->sim().time_s() - t0, rig->scanner().model().line_period_s(), 0.003);
  ASSERT_EQ(line->ranges_m.size(), 361u);
  // The wall face is at x = 3 m; the mirror sits at x = mount x + mirror x in base_link.
  const sensors::MountConfig& mount = rig->config().robot.mount;
  const double laser_x = rig->sim().T_world_laser().translation().x();
  EXPECT_NEAR(laser_x, (mount.t_base_mount_m + mount.t_mount_laser_m).x(), 0.01);
  for (double theta_deg : {-45.0, -30.0, 0.0, 10.5, 30.0, 45.0}) {
    const auto i = static_cast<std::size_t>(std::lround((theta_deg + 90.0) / 0.5));
    ASSERT_EQ(line->status[i], sensors::ReadingStatus::kValid) << theta_deg;
    EXPECT_NEAR(line->ranges_m[i], (3.0 - laser_x) / std::cos(theta_deg * kDeg), kRangeTolerance_m)
        << theta_deg;
  }
  // Beyond +-60 deg the beams pass the wall's ends: nothing within range on a finite floor.
  EXPECT_NE(line->status[0], sensors::ReadingStatus::kValid);
  EXPECT_TRUE(std::isnan(line->ranges_m[0]));
}

TEST(SimRig, AcquireGivesAScanWithGroundTruthAndTheWallInBaseLink) {
  auto rig = MakeRig(QuietConfig());
  const Eigen::Isometry3d truth = rig->sim().T_world_base();
  Result<sensors::Scan3D> scan = rig->Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_TRUE(scan->has_truth);
  EXPECT_TRUE(scan->T_world_base.isApprox(truth, 1e-3));
  ASSERT_EQ(scan->lines.size(), 5u);
  EXPECT_NEAR(scan->lines.front().pitch_rad, -9.9 * kDeg, 0.02 * kDeg);  // nearest 0.45 step
  ASSERT_GT(scan->points.size(), 5u * 200u);
  int on_wall = 0, on_floor = 0;
  for (const sensors::ScanPoint& p : scan->points) {
    const Eigen::Vector3d world = scan->T_world_base * Eigen::Vector3d(p.x, p.y, p.z);
    if (std::abs(world.x() - 3.0) < 0.02 && std::abs(world.y()) < 5.01) ++on_wall;
    if (std::abs(world.z()) < 0.02) ++on_floor;  // nose-down lines reach the floor sideways
  }
  EXPECT_GT(on_wall, 5 * 200);
  EXPECT_EQ(on_wall + on_floor, static_cast<int>(scan->points.size()));  // nothing else in view
}

TEST(SimLineScanner, MixedPixelsCastsTheBeamEdgesToo) {
  SimRigConfig config = QuietConfig();
  config.lms200.mixed_pixels = true;
  auto rig = MakeRig(config);
  Result<sensors::LaserLine> line = rig->scanner().NextLine(kTimeout);
  ASSERT_TRUE(line) << line.error().message;
  const std::size_t ahead = 180;  // theta = 0: the flat wall, no depth edge
  ASSERT_EQ(line->status[ahead], sensors::ReadingStatus::kValid);
  EXPECT_NEAR(line->ranges_m[ahead], 3.0 - rig->sim().T_world_laser().translation().x(),
              kRangeTolerance_m);
}

TEST(SimRig, TheSeedPatternTakesItsLinePeriodsPlusServoMovesOfSimulatedTime) {
  SimRigConfig config = QuietConfig();
  config.pattern = sensors::ScanPatternConfig{};  // 200 lines over -40 .. 60 deg
  auto rig = MakeRig(config);
  Result<sensors::Scan3D> scan = rig->Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_EQ(scan->lines.size(), 200u);
  // Lower bound: every line's period plus every servo move's MoveTime (slew + settle_s).
  const sensors::PitchUnitModel& servo = rig->pitch_axis().model();
  double bound_s = 200 * rig->scanner().model().line_period_s();
  for (std::size_t k = 1; k < scan->lines.size(); ++k) {
    bound_s += servo.MoveTime(scan->lines[k - 1].pitch_rad, scan->lines[k].pitch_rad);
  }
  EXPECT_GT(scan->duration_s, bound_s - 0.1);
  EXPECT_LT(scan->duration_s, 1.4 * bound_s);  // settling to half an encoder count costs < 40 %
}

}  // namespace
}  // namespace pitchlab::sim
