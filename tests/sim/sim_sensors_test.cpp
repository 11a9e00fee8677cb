// SimPitchAxis, SimLineScanner and SimRig against tiny inline worlds with known answers.

#include <array>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/sensors/allowed_cores.hpp"
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
  c.lms200.mount_error_sigma_deg = 0.0;  // the scanner exactly where the mount says
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

// A unit that pitches on during a line (pitch_unit.sweep_lag_deg): the LMS200's 0.5 deg line is
// two 1 deg sweeps, the odd readings cast 2 deg further down than the even ones. Looking 20 deg
// down at the floor, each beam meets the floor where its own sweep's pitch says (range = laser
// height / the beam's downward component), and without the lag both sweeps share one pitch.
TEST(SimLineScanner, AnInterlacedLinesSecondSweepIsCastFurtherDownByTheSweepLag) {
  for (const double lag_deg : {0.0, 2.0}) {
    SimRigConfig config = QuietConfig();
    config.pitch_unit.sweep_lag_deg = lag_deg;
    auto rig = MakeRig(config);
    ASSERT_TRUE(rig->pitch_axis().MoveTo(20.0 * kDeg, kTimeout));
    const Eigen::Isometry3d T = rig->sim().T_world_laser();
    Result<sensors::LaserLine> line = rig->scanner().NextLine(kTimeout);
    ASSERT_TRUE(line) << line.error().message;
    const double h = T.translation().z();
    for (const std::size_t i : {170u, 171u, 180u, 181u, 190u, 191u}) {  // -5 .. 5.5 deg
      const double theta = line->Angle(i);
      const Eigen::Vector3d beam(std::cos(theta), std::sin(theta), 0.0);
      const double lag = (i % 2 == 1 ? lag_deg : 0.0) * kDeg;
      const Eigen::Vector3d d =
          T.linear() * Eigen::AngleAxisd(lag, Eigen::Vector3d::UnitY()) * beam;
      ASSERT_LT(d.z(), -0.1);
      ASSERT_EQ(line->status[i], sensors::ReadingStatus::kValid) << i;
      EXPECT_NEAR(line->ranges_m[i], -h / d.z(), kRangeTolerance_m)
          << "lag " << lag_deg << ", reading " << i;
    }
    // 2 deg at 20 deg down moves the floor hit by ~0.2 m: far beyond the tolerance.
    if (lag_deg > 0) EXPECT_LT(line->ranges_m[181], line->ranges_m[180] - 0.1);
  }
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

// The lines of a sweep of `lines` nodding steps over -20 .. 20 deg, with the scanner's sweep begun
// and ended around them or not; `raw` gets what NextLine handed back before EndSweep.
std::vector<sensors::LaserLine> Sweep(SimRig& rig, int lines, bool as_sweep,
                                      std::vector<sensors::LaserLine>* raw = nullptr) {
  std::vector<sensors::LaserLine> out;
  if (as_sweep) rig.scanner().BeginSweep();
  for (int k = 0; k < lines; ++k) {
    Result<double> encoder = rig.pitch_axis().MoveTo((-20.0 + 40.0 * k / (lines - 1)) * kDeg,
                                                     kTimeout);
    Result<sensors::LaserLine> line = rig.scanner().NextLine(kTimeout);
    if (!encoder || !line) throw std::runtime_error("the sweep failed");
    line->pitch_rad = *encoder;
    out.push_back(std::move(*line));
  }
  if (raw) *raw = out;
  if (as_sweep) rig.scanner().EndSweep(&out);
  return out;
}

// Noise, dropouts and incidence on: every reading draws from the model's generator, so a line cast
// out of order or from another pose would show.
SimRigConfig NoisyConfig(CasterKind caster) {
  SimRigConfig config = QuietConfig(caster);
  config.lms200 = sensors::Lms200Config{};
  config.lms200.mount_error_sigma_deg = 0.0;
  return config;
}

TEST(SimLineScanner, ASweepCastBesideThePhysicsGivesTheLinesOfOneAtATime) {
  auto one_by_one = MakeRig(NoisyConfig(CasterKind::kEmbree));
  auto swept = MakeRig(NoisyConfig(CasterKind::kEmbree));
  const std::vector<sensors::LaserLine> expected = Sweep(*one_by_one, 30, false);
  std::vector<sensors::LaserLine> raw;
  const std::vector<sensors::LaserLine> got = Sweep(*swept, 30, true, &raw);
  ASSERT_EQ(got.size(), expected.size());
  if (sensors::AllowedCores() >= 2) {
    // Handed back before their rays were cast: the casting thread made them.
    for (const sensors::LaserLine& line : raw) EXPECT_TRUE(line.ranges_m.empty());
  }
  int valid = 0;
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].stamp_s, expected[k].stamp_s) << k;
    EXPECT_EQ(got[k].pitch_rad, expected[k].pitch_rad) << k;
    EXPECT_EQ(got[k].duration_s, expected[k].duration_s) << k;
    ASSERT_EQ(got[k].ranges_m.size(), expected[k].ranges_m.size()) << k;
    EXPECT_EQ(got[k].status, expected[k].status) << k;
    for (std::size_t i = 0; i < got[k].ranges_m.size(); ++i) {
      if (std::isnan(expected[k].ranges_m[i])) {
        EXPECT_TRUE(std::isnan(got[k].ranges_m[i])) << k << ' ' << i;
      } else {
        ++valid;
        ASSERT_EQ(got[k].ranges_m[i], expected[k].ranges_m[i]) << k << ' ' << i;
      }
    }
  }
  EXPECT_GT(valid, 30 * 200);
  // The scan time the physics did not hide is still counted, and every ray's CPU time.
  EXPECT_GT(swept->scanner().line_time().cpu_s, 0.0);
}

TEST(SimLineScanner, ASweepEndsWithTheLinesItGaveOrNone) {
  auto rig = MakeRig(NoisyConfig(CasterKind::kEmbree));
  rig->scanner().BeginSweep();
  Result<sensors::LaserLine> line = rig->scanner().NextLine(kTimeout);
  ASSERT_TRUE(line) << line.error().message;
  std::vector<sensors::LaserLine> none;
  EXPECT_THROW(rig->scanner().EndSweep(&none), std::logic_error);
  // A dropped sweep leaves nothing behind: the next one has its own lines only.
  rig->scanner().BeginSweep();
  (void)rig->scanner().NextLine(kTimeout);
  rig->scanner().EndSweep(nullptr);
  const std::vector<sensors::LaserLine> lines = Sweep(*rig, 3, true);
  ASSERT_EQ(lines.size(), 3u);
  for (const sensors::LaserLine& l : lines) EXPECT_EQ(l.ranges_m.size(), 361u);
}

TEST(SimLineScanner, MujocosRaysReadTheLiveStateSoASweepCastsEachLineAtOnce) {
  auto rig = MakeRig(QuietConfig(CasterKind::kMujoco));
  std::vector<sensors::LaserLine> raw;
  Sweep(*rig, 3, true, &raw);
  for (const sensors::LaserLine& line : raw) EXPECT_EQ(line.ranges_m.size(), 361u);
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

TEST(SimRig, TheScannerSitsOffTheNominalMountByTheDrawnErrorUnknownToTheScan) {
  SimRigConfig config = QuietConfig();
  config.lms200.mount_error_sigma_deg = 2.0;
  config.lms200.seed = 5;
  config.pattern.pitch_start_deg = 20.0;  // nose down: the floor in view
  config.pattern.pitch_end_deg = 40.0;
  auto rig = MakeRig(config);
  const std::array<double, 3> e = sensors::DrawMountErrorRpyRad(config.lms200);
  ASSERT_GT(std::hypot(e[0], e[1], e[2]), 0.5 * kDeg);  // this seed draws a visible error
  EXPECT_TRUE(rig->mount_error_rpy_rad().isApprox(Eigen::Vector3d(e[0], e[1], e[2])));
  // The nominal mount the pipeline assembles with is untouched.
  EXPECT_TRUE(rig->config().robot.mount.misalignment_rpy_rad.isZero());
  // The simulated laser is the nominal one turned by roll, pitch, yaw = e.
  Result<double> encoder = rig->pitch_axis().MoveTo(30.0 * kDeg, kTimeout);
  ASSERT_TRUE(encoder) << encoder.error().message;
  const Eigen::Matrix3d nominal =
      (rig->sim().T_world_base() * rig->config().robot.mount.BaseToLaser(*encoder)).rotation();
  const Eigen::Matrix3d drawn = (Eigen::AngleAxisd(e[2], Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(e[1], Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(e[0], Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
  const Eigen::AngleAxisd off(drawn.transpose() * nominal.transpose() *
                              rig->sim().T_world_laser().rotation());
  EXPECT_LT(off.angle(), 0.02 * kDeg);  // the servo holds within half an encoder count
  // The same scan without the error differs: its floor readings sit elsewhere.
  SimRigConfig level = config;
  level.lms200.mount_error_sigma_deg = 0.0;
  auto level_rig = MakeRig(level);
  Result<sensors::Scan3D> tilted = rig->Acquire(), flat = level_rig->Acquire();
  ASSERT_TRUE(tilted && flat);
  int moved = 0, compared = 0;
  for (std::size_t k = 0; k < flat->lines.size(); ++k) {
    for (std::size_t i = 0; i < flat->lines[k].ranges_m.size(); ++i) {
      if (flat->lines[k].status[i] != sensors::ReadingStatus::kValid ||
          tilted->lines[k].status[i] != sensors::ReadingStatus::kValid) {
        continue;
      }
      ++compared;
      moved += std::abs(flat->lines[k].ranges_m[i] - tilted->lines[k].ranges_m[i]) > 0.02;
    }
  }
  ASSERT_GT(compared, 500);
  EXPECT_GT(moved, compared / 2);
}

// A sensor whose only effect is a dropout with probability incidence / 90 deg: what the scanner
// takes for each beam's incidence shows in how often the beam drops out.
SimRigConfig IncidenceProbeConfig() {
  SimRigConfig config = QuietConfig();
  config.lms200.noise_sigma_m = 0.001;  // not the ideal sensor: dropouts on
  config.lms200.noise_per_m = 0.0;
  config.lms200.incidence_noise_gain = 0.0;
  config.lms200.dropout_far_per_m = 0.0;
  config.lms200.dropout_grazing_deg = 0.0;
  config.lms200.dropout_grazing_at_90 = 1.0;
  return config;
}

// The incidence the scanner derives from its extra rays, seen through grazing dropouts whose
// probability is the incidence / 90 deg: a level line on the wall at x = 3 m meets it at |theta|.
TEST(SimLineScanner, IncidenceFromTheHitsIsTheWallsGeometry) {
  auto rig = MakeRig(IncidenceProbeConfig());
  ASSERT_TRUE(rig->pitch_axis().MoveTo(0.0, kTimeout));
  // The same level line again and again; per centre angle, the beams within 2 deg of it.
  const std::vector<double> centres_deg = {-40.0, 10.0, 30.0, 50.0};
  std::vector<double> dropped(centres_deg.size(), 0.0), total(centres_deg.size(), 0.0),
      expected(centres_deg.size(), 0.0);
  for (int k = 0; k < 150; ++k) {
    Result<sensors::LaserLine> line = rig->scanner().NextLine(kTimeout);
    ASSERT_TRUE(line) << line.error().message;
    for (std::size_t c = 0; c < centres_deg.size(); ++c) {
      for (double d = -2.0; d <= 2.0; d += 0.5) {
        const double theta = centres_deg[c] + d;
        const auto i = static_cast<std::size_t>(std::lround((theta + 90.0) / 0.5));
        dropped[c] += line->status[i] == sensors::ReadingStatus::kNoReturn;
        total[c] += 1;
        expected[c] += std::abs(theta) / 90.0;
      }
    }
  }
  for (std::size_t c = 0; c < centres_deg.size(); ++c) {
    // 1350 draws: the binomial sigma is at most 0.014; 0.04 is about 3 of them.
    EXPECT_NEAR(dropped[c] / total[c], expected[c] / total[c], 0.04) << centres_deg[c] << " deg";
  }
}

// A beam that meets a face near its edge meets it at that face's incidence, whatever lies beside
// the edge. A pillar 5.5 cm wide faces the scanner 3 m ahead with a wall 5 m behind it; the beam
// at +0.5 deg meets the pillar 1.3 mm inside its edge, so its extra ray along the line, 2.6 mm
// further, passes the edge and hits the wall behind. Seen through grazing dropouts (probability:
// the incidence / 90 deg) as above: that beam is kept as often as its 0.5 deg incidence says.
TEST(SimLineScanner, ABeamNearAFacesEdgeMeetsItAtThatFacesIncidence) {
  constexpr char kPillarWorld[] = R"(
<mujoco model="pillar">
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="pillar" type="box" pos="3.05 0 1" size="0.05 0.0275 1"/>
    <geom name="wall" type="box" pos="8.05 0 1" size="0.05 5 1"/>
  </worldbody>
</mujoco>)";
  auto rig = SimRig::FromString(kPillarWorld, "/tmp", IncidenceProbeConfig());
  ASSERT_TRUE(rig->PlaceRobot(0.0, 0.0, 0.0));
  ASSERT_TRUE(rig->pitch_axis().MoveTo(0.0, kTimeout));
  const double laser_x = rig->sim().T_world_laser().translation().x();
  const auto beam = static_cast<std::size_t>(std::lround((0.5 + 90.0) / 0.5));
  int on_pillar = 0, dropped = 0;
  for (int k = 0; k < 150; ++k) {
    Result<sensors::LaserLine> line = rig->scanner().NextLine(kTimeout);
    ASSERT_TRUE(line) << line.error().message;
    if (line->status[beam] == sensors::ReadingStatus::kNoReturn) {
      ++dropped;
      continue;
    }
    // The pillar's face, not the wall behind it.
    EXPECT_NEAR(line->ranges_m[beam], (3.0 - laser_x) / std::cos(0.5 * kDeg), kRangeTolerance_m);
    ++on_pillar;
  }
  // 150 draws at p = 0.5 / 90: 0.8 expected; the grazing incidence the wall behind gave dropped
  // nearly every one.
  EXPECT_LE(dropped, 5);
  EXPECT_GE(on_pillar, 145);
}

}  // namespace
}  // namespace pitchlab::sim
