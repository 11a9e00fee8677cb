// MountTiltFromFloor and TurnAboutMount on pitchlab's own scans: the simulated office from its
// start, the LMS200 mounted off by a drawn roll and pitch (Lms200Config::mount_error_sigma_deg).

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/mission/elevation_scan.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kDeg = M_PI / 180.0;

sensors::Lms200Config MountedOff(double sigma_deg) {
  sensors::Lms200Config lms = sensors::Lms200Config::Legacy();
  lms.mount_error_sigma_deg = sigma_deg;
  lms.seed = 7;
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
  std::vector<Eigen::Vector3f> points;
  for (const sensors::ScanPoint& p : scan.points) points.emplace_back(p.x, p.y, p.z);
  Result<mapping::GroundLevel> level =
      mapping::FitGroundLevel(points, mount.BaseToLaser(0.0).translation().cast<float>());
  EXPECT_TRUE(level) << (level ? "" : level.error().message);
  return level ? level->tilt_rad : NAN;
}

TEST(LevelMount, TheDrawnMountTiltIsFoundAndTurnedOut) {
  const sensors::Lms200Config lms = MountedOff(0.5);
  const std::array<double, 3> rpy = sensors::DrawMountErrorRpyRad(lms);
  const double drawn = std::hypot(rpy[0], rpy[1]);  // roll and pitch: what a floor shows
  ASSERT_GT(drawn, 0.2 * kDeg);
  const sensors::MountConfig mount = sim::SimRigConfig{}.robot.mount;
  sensors::Scan3D scan = OfficeScan(lms);
  EXPECT_NEAR(FloorTilt(scan, mount), drawn, 0.05 * kDeg);

  Result<Eigen::Matrix3d> fix = MountTiltFromFloor(scan, mount);
  ASSERT_TRUE(fix) << fix.error().message;
  EXPECT_NEAR(Eigen::AngleAxisd(*fix).angle(), drawn, 0.05 * kDeg);
  TurnAboutMount(scan, mount, *fix);
  EXPECT_LT(FloorTilt(scan, mount), 0.02 * kDeg);
  // The laser stays where it is: the turn is about the mount, 0.45 m over the floor it levels.
  Result<Eigen::Matrix3d> again = MountTiltFromFloor(scan, mount);
  ASSERT_TRUE(again);
  EXPECT_LT(Eigen::AngleAxisd(*again).angle(), 0.02 * kDeg);
}

TEST(LevelMount, ATrueMountIsLeftAloneAndAFloorTooSteepIsNoMountError) {
  const sensors::MountConfig mount = sim::SimRigConfig{}.robot.mount;
  sensors::Scan3D scan = OfficeScan(MountedOff(0.0));
  Result<Eigen::Matrix3d> fix = MountTiltFromFloor(scan, mount);
  ASSERT_TRUE(fix) << fix.error().message;
  EXPECT_LT(Eigen::AngleAxisd(*fix).angle(), 0.02 * kDeg);
  // The same floor 5 deg off: more than a mount is off, refused with the reason.
  TurnAboutMount(scan, mount, Eigen::AngleAxisd(5 * kDeg, Eigen::Vector3d::UnitY()).matrix());
  Result<Eigen::Matrix3d> tilted = MountTiltFromFloor(scan, mount);
  ASSERT_FALSE(tilted);
  EXPECT_NE(tilted.error().message.find("more than a mount error"), std::string::npos);
}

}  // namespace
}  // namespace pitchlab::mission
