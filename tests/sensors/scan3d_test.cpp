#include "pitchlab/sensors/scan3d.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace pitchlab::sensors {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kPointTolerance_m = 1e-9;

MountConfig SeedMount() {
  MountConfig m;
  m.t_base_mount_m = {0.10, 0.0, 0.45};
  m.t_mount_laser_m = {0.0, 0.0, 0.09};
  m.misalignment_rpy_rad.setZero();
  return m;
}

TEST(Eq1, AReadingLandsWhereHandComputationSays) {
  // rho 2 m, theta 30 deg, gamma 20 deg (nose down), worked by hand:
  // laser (1.7320508, 1, 0) -> mirror offset (.., .., 0.09) -> R_y(20 deg) -> + mount.
  const Eigen::Vector3d p = BeamPointInBase(2.0, 30 * kDeg, 20 * kDeg, SeedMount());
  EXPECT_NEAR(p.x(), 1.758377176, kPointTolerance_m);
  EXPECT_NEAR(p.y(), 1.000000000, kPointTolerance_m);
  EXPECT_NEAR(p.z(), -0.057823930, kPointTolerance_m);
}

TEST(Eq1, ZeroPitchIsTheScanPlaneLiftedToTheMirror) {
  const Eigen::Vector3d p = BeamPointInBase(3.0, 90 * kDeg, 0.0, SeedMount());
  EXPECT_NEAR(p.x(), 0.10, kPointTolerance_m);
  EXPECT_NEAR(p.y(), 3.0, kPointTolerance_m);
  EXPECT_NEAR(p.z(), 0.54, kPointTolerance_m);
}

TEST(Eq1, NinetyDegreesNoseDownLooksStraightDown) {
  MountConfig m = SeedMount();
  m.t_mount_laser_m.setZero();
  const Eigen::Vector3d p = BeamPointInBase(0.45, 0.0, 90 * kDeg, m);
  EXPECT_NEAR(p.x(), 0.10, kPointTolerance_m);
  EXPECT_NEAR(p.z(), 0.0, kPointTolerance_m);
}

TEST(Eq1, YawMisalignmentRotatesTheBeamInItsPlane) {
  MountConfig m = SeedMount();
  m.t_mount_laser_m.setZero();
  m.misalignment_rpy_rad = {0.0, 0.0, 1.0 * kDeg};
  const Eigen::Vector3d p = BeamPointInBase(5.0, 10 * kDeg, 0.0, m);
  EXPECT_NEAR(p.x(), 0.10 + 5.0 * std::cos(11 * kDeg), kPointTolerance_m);
  EXPECT_NEAR(p.y(), 5.0 * std::sin(11 * kDeg), kPointTolerance_m);
}

TEST(AssembleScan, KeepsValidReadingsCountsTheRestAndStampsByLine) {
  std::vector<LaserLine> lines(2);
  for (int l = 0; l < 2; ++l) {
    LaserLine& line = lines[l];
    line.stamp_s = 10.0 + l;
    line.duration_s = 0.02;
    line.pitch_rad = l * 10 * kDeg;
    line.angle_min_rad = -90 * kDeg;
    line.angle_increment_rad = 90 * kDeg;
    line.ranges_m = {1.0f, std::numeric_limits<float>::quiet_NaN(), 2.0f};
    line.status = {ReadingStatus::kValid, ReadingStatus::kNoReturn,
                   l == 0 ? ReadingStatus::kValid : ReadingStatus::kOverRange};
  }
  const MountConfig mount = SeedMount();
  const Scan3D scan = AssembleScan(lines, mount);
  ASSERT_EQ(scan.points.size(), 3u);
  EXPECT_EQ(scan.no_returns, 2u);
  EXPECT_EQ(scan.over_ranges, 1u);
  EXPECT_DOUBLE_EQ(scan.stamp_s, 10.0);
  EXPECT_NEAR(scan.duration_s, 1.02, 1e-12);
  const ScanPoint& last = scan.points.back();
  EXPECT_EQ(last.line, 1);
  EXPECT_EQ(last.beam, 0);
  EXPECT_DOUBLE_EQ(last.stamp_s, 11.0);
  const Eigen::Vector3d expected = BeamPointInBase(1.0, -90 * kDeg, 10 * kDeg, mount);
  EXPECT_NEAR(last.x, expected.x(), 1e-6);
  EXPECT_NEAR(last.y, expected.y(), 1e-6);
  EXPECT_NEAR(last.z, expected.z(), 1e-6);
  EXPECT_EQ(scan.lines.size(), 2u);
}

// Lines of flat ground 0.3 m below base_link's origin (z = -0.3 in the frame the base stands in at
// the last line), swept while the base rocks about its origin: line k's frame is turned by
// `rock(k)`, the last line's is not. Ranges are the exact ray-plane distances.
struct RockedSweep {
  std::vector<LaserLine> lines;
  std::vector<Eigen::Quaterniond> attitudes;  // base_link per line, in the last line's frame
};

RockedSweep SweepFlatGroundWhileRocking(const MountConfig& mount) {
  constexpr int kLines = 40;
  constexpr double kGround_m = -0.3;
  RockedSweep sweep;
  for (int k = 0; k < kLines; ++k) {
    // Up to 3 deg of roll and 2 deg of pitch, back to level at the last line.
    const double phase = 1.0 - double(k) / (kLines - 1);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(3 * kDeg * phase, Eigen::Vector3d::UnitX()) *
                               Eigen::AngleAxisd(-2 * kDeg * phase, Eigen::Vector3d::UnitY()));
    LaserLine line;
    line.stamp_s = 0.1 * k;
    line.pitch_rad = (10 + k) * kDeg;  // looking down at the ground ahead
    line.angle_min_rad = -60 * kDeg;
    line.angle_increment_rad = 5 * kDeg;
    const Eigen::Isometry3d T = Eigen::Isometry3d(q) * mount.BaseToLaser(line.pitch_rad);
    for (int i = 0; i <= 24; ++i) {
      const double theta = line.Angle(i);
      const Eigen::Vector3d dir = T.linear() * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0);
      line.ranges_m.push_back(static_cast<float>((kGround_m - T.translation().z()) / dir.z()));
      line.status.push_back(ReadingStatus::kValid);
    }
    sweep.lines.push_back(std::move(line));
    sweep.attitudes.push_back(q);
  }
  return sweep;
}

TEST(AssembleScan, DeskewedByTheSensedAttitudeFlatGroundIsFlat) {
  const MountConfig mount = SeedMount();
  const RockedSweep sweep = SweepFlatGroundWhileRocking(mount);
  const Scan3D bent = AssembleScan(sweep.lines, mount);
  const Scan3D deskewed = AssembleScan(sweep.lines, mount, sweep.attitudes);
  ASSERT_EQ(deskewed.points.size(), bent.points.size());
  EXPECT_FALSE(bent.deskewed);
  EXPECT_TRUE(deskewed.deskewed);
  EXPECT_NEAR(deskewed.deskew_max_rad, std::hypot(3.0, 2.0) * kDeg, 0.01 * kDeg);
  double bent_worst_m = 0, deskewed_worst_m = 0;
  for (std::size_t k = 0; k < bent.points.size(); ++k) {
    bent_worst_m = std::max(bent_worst_m, std::abs(bent.points[k].z + 0.3));
    deskewed_worst_m = std::max(deskewed_worst_m, std::abs(deskewed.points[k].z + 0.3));
  }
  EXPECT_GT(bent_worst_m, 0.05);      // the rock bends the uncorrected ground by centimetres
  EXPECT_LT(deskewed_worst_m, 1e-5);  // float ranges and points
}

TEST(AssembleScan, SensorOriginIsTheMirrorAtZeroPitch) {
  // SeedMount: pitch axis at (0.10, 0, 0.45), mirror 0.09 above it: where a zero-pitch beam starts.
  const Scan3D scan = AssembleScan({}, SeedMount());
  ASSERT_TRUE(scan.sensor_origin);
  EXPECT_TRUE(scan.sensor_origin->isApprox(Eigen::Vector3d(0.10, 0.0, 0.54), kPointTolerance_m));
  EXPECT_TRUE(BeamPointInBase(0.0, 0.0, 0.0, SeedMount()).isApprox(*scan.sensor_origin));
}

TEST(AssembleScan, RejectsAttitudesThatAreNotOnePerLine) {
  const MountConfig mount = SeedMount();
  RockedSweep sweep = SweepFlatGroundWhileRocking(mount);
  sweep.attitudes.pop_back();
  EXPECT_THROW((void)AssembleScan(sweep.lines, mount, sweep.attitudes), std::invalid_argument);
}

TEST(ReassembleScan, IsTheScanTheOtherMountAssembles) {
  const MountConfig nominal = SeedMount();
  MountConfig off = nominal;
  off.misalignment_rpy_rad = {0.4 * kDeg, -0.3 * kDeg, 0.5 * kDeg};
  off.t_mount_laser_m = {0.01, 0.0, 0.1};
  const RockedSweep sweep = SweepFlatGroundWhileRocking(nominal);
  Scan3D scan = AssembleScan(sweep.lines, nominal);
  const Scan3D want = AssembleScan(sweep.lines, off);
  ReassembleScan(scan, nominal, off);
  ASSERT_EQ(scan.points.size(), want.points.size());
  double worst_m = 0;
  for (std::size_t k = 0; k < scan.points.size(); ++k) {
    const ScanPoint &a = scan.points[k], &b = want.points[k];
    worst_m = std::max(worst_m, (Eigen::Vector3d(a.x, a.y, a.z) - Eigen::Vector3d(b.x, b.y, b.z))
                                    .cwiseAbs()
                                    .maxCoeff());
    EXPECT_EQ(a.range_m, b.range_m);
  }
  EXPECT_LT(worst_m, 1e-5);  // float points
  ASSERT_TRUE(scan.sensor_origin);
  EXPECT_TRUE(scan.sensor_origin->isApprox(*want.sensor_origin, 1e-12));
  // A point of a line the scan does not hold: refused, nothing moved.
  scan.points.front().line = static_cast<std::uint16_t>(scan.lines.size());
  const Scan3D before = scan;
  EXPECT_THROW(ReassembleScan(scan, off, nominal), std::invalid_argument);
  EXPECT_EQ(scan.points.back().x, before.points.back().x);
}

}  // namespace
}  // namespace pitchlab::sensors
