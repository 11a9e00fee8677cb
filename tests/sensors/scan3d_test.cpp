#include "pitchlab/sensors/scan3d.hpp"

#include <cmath>
#include <limits>

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

}  // namespace
}  // namespace pitchlab::sensors
