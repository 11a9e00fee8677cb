// The mount calibrated by the floor on pitchlab's own scans: the simulated office from its start,
// the LMS200 mounted off by a drawn roll, pitch and yaw (Lms200Config::mount_error_sigma_deg).

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/mapping/mount_from_floor.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kDeg = M_PI / 180.0;

sensors::Lms200Config MountedOff(double sigma_deg, std::uint64_t seed) {
  sensors::Lms200Config lms = sensors::Lms200Config::Legacy();
  lms.mount_error_sigma_deg = sigma_deg;
  lms.seed = seed;
  return lms;
}

sensors::Scan3D OfficeScan(const sensors::Lms200Config& lms) {
  sim::SimRigConfig config;
  config.lms200 = lms;
  sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/office.xml", config);
  EXPECT_TRUE(rig.PlaceAtDefaultStart());
  Result<sensors::Scan3D> scan = rig.Acquire();
  EXPECT_TRUE(scan) << (scan ? "" : scan.error().message);
  return scan ? *scan : sensors::Scan3D{};
}

// The tilt of the floor 0.5-4 m from the laser in base_link [rad].
double FloorTilt(const sensors::Scan3D& scan, const sensors::MountConfig& mount) {
  Result<mapping::GroundLevel> level = mapping::FitGroundLevel(
      mapping::CloudFromScan(scan), mount.BaseToLaser(0.0).translation().cast<float>());
  EXPECT_TRUE(level) << (level ? "" : level.error().message);
  return level ? level->tilt_rad : NAN;
}

// At 0.5 deg per axis, seed 7 draws roll 0.30, pitch 0.29, yaw -0.08 deg; seed 9 a yaw (-0.93)
// larger than its roll (-0.74), which a floor levelled by one rotation read as roll.
class CalibrateMount : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(CalibrateMount, TheDrawnMountErrorIsFoundAndTheScanIsTheTrueMountsOne) {
  const sensors::Lms200Config lms = MountedOff(0.5, GetParam());
  const std::array<double, 3> rpy = sensors::DrawMountErrorRpyRad(lms);
  const Eigen::Vector3d drawn(rpy[0], rpy[1], rpy[2]);
  ASSERT_GT(drawn.norm(), 0.3 * kDeg);
  const sensors::MountConfig nominal = sim::SimRigConfig{}.robot.mount;
  sensors::Scan3D scan = OfficeScan(lms);
  Result<mapping::MountFromFloor> found = mapping::CalibrateMountFromFloor(scan, nominal);
  ASSERT_TRUE(found) << found.error().message;
  // Roll and pitch to 0.03 deg; yaw, told only by how the floor's sideways slope changes from
  // line to line, to 0.1 deg.
  EXPECT_NEAR(found->correction_rpy_rad.x(), drawn.x(), 0.03 * kDeg);
  EXPECT_NEAR(found->correction_rpy_rad.y(), drawn.y(), 0.03 * kDeg);
  EXPECT_NEAR(found->correction_rpy_rad.z(), drawn.z(), 0.1 * kDeg);
  sensors::ReassembleScan(scan, nominal, found->mount);
  EXPECT_LT(FloorTilt(scan, nominal), 0.02 * kDeg);
  // The same scene on the true mount: every point, the walls' too, within millimetres.
  sensors::MountConfig truth = nominal;
  truth.misalignment_rpy_rad += drawn;
  sensors::Scan3D want = scan;
  sensors::ReassembleScan(want, found->mount, truth);
  ASSERT_EQ(scan.points.size(), want.points.size());
  double worst_m = 0;
  for (std::size_t k = 0; k < scan.points.size(); ++k) {
    const sensors::ScanPoint &a = scan.points[k], &b = want.points[k];
    worst_m = std::max(worst_m, double((Eigen::Vector3f(a.x, a.y, a.z) -
                                        Eigen::Vector3f(b.x, b.y, b.z)).norm()));
  }
  EXPECT_LT(worst_m, 0.02);  // 0.1 deg at 10 m: 1.7 cm
}

INSTANTIATE_TEST_SUITE_P(Seeds, CalibrateMount, ::testing::Values(7u, 9u));

TEST(CalibrateMountOffice, ATrueMountIsLeftAlone) {
  const sensors::MountConfig nominal = sim::SimRigConfig{}.robot.mount;
  Result<mapping::MountFromFloor> found =
      mapping::CalibrateMountFromFloor(OfficeScan(MountedOff(0.0, 7)), nominal);
  ASSERT_TRUE(found) << found.error().message;
  EXPECT_LT(found->correction_rpy_rad.norm(), 0.03 * kDeg);
}

}  // namespace
}  // namespace pitchlab::mission
