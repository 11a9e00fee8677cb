// CalibrateMountFromFloor against scans of a known floor taken on a known, misaligned mount: the
// lines are ray-cast analytically, so the answer is the misalignment the scan was taken with.

#include "pitchlab/mapping/mount_from_floor.hpp"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::mapping {
namespace {

constexpr double kDeg = M_PI / 180.0;

sensors::MountConfig Nominal() {
  sensors::MountConfig m;
  m.t_base_mount_m = {0.10, 0.0, 0.45};
  m.t_mount_laser_m = {0.0, 0.0, 0.09};
  m.misalignment_rpy_rad.setZero();
  return m;
}

// A nodding sweep (pitch -10..60 deg in 1 deg steps, beams -90..90 deg in 0.5 deg) over the
// floor z = `floor_z` of base_link, tilted by `floor_roll` about x, and a wall at x = 6 m, taken
// on `truth` and assembled on `assumed`, ranges with `noise_m` Gaussian noise.
sensors::Scan3D Sweep(const sensors::MountConfig& truth, const sensors::MountConfig& assumed,
                      double noise_m, double floor_roll = 0.0, double floor_z = 0.0) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, noise_m);
  const Eigen::Vector3d n_floor(0.0, -std::sin(floor_roll), std::cos(floor_roll));
  std::vector<sensors::LaserLine> lines;
  for (int l = 0; l <= 70; ++l) {
    sensors::LaserLine line;
    line.stamp_s = 0.05 * l;
    line.pitch_rad = (l - 10) * kDeg;
    line.angle_min_rad = -90 * kDeg;
    line.angle_increment_rad = 0.5 * kDeg;
    const Eigen::Isometry3d T = truth.BaseToLaser(line.pitch_rad);
    for (int i = 0; i <= 360; ++i) {
      const double theta = line.Angle(i);
      const Eigen::Vector3d d = T.linear() * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0);
      const Eigen::Vector3d o = T.translation();
      double range = INFINITY;
      if (n_floor.dot(d) < 0) range = (floor_z - n_floor.dot(o)) / n_floor.dot(d);
      if (d.x() > 0) range = std::min(range, (6.0 - o.x()) / d.x());
      if (range <= 20.0) {
        line.ranges_m.push_back(static_cast<float>(range + noise(rng)));
        line.status.push_back(sensors::ReadingStatus::kValid);
      } else {
        line.ranges_m.push_back(NAN);
        line.status.push_back(sensors::ReadingStatus::kNoReturn);
      }
    }
    lines.push_back(std::move(line));
  }
  return sensors::AssembleScan(std::move(lines), assumed);
}

TEST(MountFromFloor, TheRollPitchAndYawTheScanWasTakenWithAreFound) {
  const sensors::MountConfig nominal = Nominal();
  sensors::MountConfig truth = nominal;
  truth.misalignment_rpy_rad = {0.3 * kDeg, -0.25 * kDeg, -0.45 * kDeg};
  const sensors::Scan3D scan = Sweep(truth, nominal, 0.0);
  Result<MountFromFloor> found = CalibrateMountFromFloor(scan, nominal);
  ASSERT_TRUE(found) << found.error().message;
  EXPECT_LT((found->correction_rpy_rad - truth.misalignment_rpy_rad).cwiseAbs().maxCoeff(),
            0.002 * kDeg);
  EXPECT_NEAR(found->floor_z_m, 0.0, 1e-4);
  EXPECT_LE(found->residual_m, 1e-4);  // the floor on sigma, far below any laser's noise
  EXPECT_TRUE(found->mount.misalignment_rpy_rad.isApprox(truth.misalignment_rpy_rad, 1e-3));
  EXPECT_GT(found->tilt_before_rad, 0.2 * kDeg);

  // Re-assembled on the mount found, the scan is the one the true mount gives: the wall at 6 m
  // too, which the floor never saw. A rotation levelling the floor leaves it leaning (the
  // yaw read as roll on the floor lines turns the level lines' wall).
  sensors::Scan3D fixed = scan;
  sensors::ReassembleScan(fixed, nominal, found->mount);
  const sensors::Scan3D want = Sweep(truth, truth, 0.0);
  double worst_m = 0;
  for (std::size_t k = 0; k < fixed.points.size(); ++k) {
    const sensors::ScanPoint &a = fixed.points[k], &b = want.points[k];
    worst_m = std::max(worst_m, double(std::abs(a.x - b.x) + std::abs(a.y - b.y) + std::abs(a.z - b.z)));
  }
  EXPECT_LT(worst_m, 1e-3);
}

TEST(MountFromFloor, NoiseOfTheMeasuredModelLeavesHundredthsOfADegree) {
  const sensors::MountConfig nominal = Nominal();
  sensors::MountConfig truth = nominal;
  truth.misalignment_rpy_rad = {-0.2 * kDeg, 0.35 * kDeg, 0.3 * kDeg};
  // 8 mm: the measured model's range noise 4 m out at grazing incidence (Lms200Config::Measured).
  const sensors::Scan3D scan = Sweep(truth, nominal, 0.008);
  Result<MountFromFloor> found = CalibrateMountFromFloor(scan, nominal);
  ASSERT_TRUE(found) << found.error().message;
  const Eigen::Vector3d error = found->correction_rpy_rad - truth.misalignment_rpy_rad;
  EXPECT_LT(error.cwiseAbs().maxCoeff(), 0.03 * kDeg);
  // The stated sigmas are of the size of the error made.
  for (int k = 0; k < 3; ++k) {
    EXPECT_LT(std::abs(error[k]), 4 * found->sigma_rpy_rad[k] + 0.005 * kDeg) << k;
    EXPECT_LT(found->sigma_rpy_rad[k], 0.02 * kDeg) << k;
  }
  // Range noise along rays that meet the floor at 8-60 deg: heights scatter by a fraction of it.
  EXPECT_GT(found->residual_m, 0.001);
  EXPECT_LT(found->residual_m, 0.008);
}

TEST(MountFromFloor, ATrueMountStaysAndAFloorTooSteepOrNoLinesIsRefused) {
  const sensors::MountConfig nominal = Nominal();
  Result<MountFromFloor> found = CalibrateMountFromFloor(Sweep(nominal, nominal, 0.002), nominal);
  ASSERT_TRUE(found) << found.error().message;
  EXPECT_LT(found->correction_rpy_rad.norm(), 0.01 * kDeg);

  // A robot on its plane, the floor around it 5 deg off: more than a mount is off.
  Result<MountFromFloor> steep =
      CalibrateMountFromFloor(Sweep(nominal, nominal, 0.002, 5 * kDeg), nominal);
  ASSERT_FALSE(steep);
  EXPECT_NE(steep.error().message.find("more than a mount error"), std::string::npos);

  sensors::Scan3D no_lines = Sweep(nominal, nominal, 0.002);
  no_lines.lines.clear();
  Result<MountFromFloor> refused = CalibrateMountFromFloor(no_lines, nominal);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("no lines"), std::string::npos);
}

}  // namespace
}  // namespace pitchlab::mapping
