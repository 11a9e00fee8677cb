// SetLinesRight on pitchlab's own scans: the simulated office from its start, with the pitch unit
// reporting each line's pitch off by the real 3DTK rig's error (pitch_unit.line_pitch_error_deg
// 0.9) and with a unit that reports its true pitch.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mission/elevation_scan.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mission {
namespace {

sensors::Scan3D OfficeScan(double line_pitch_error_deg) {
  sim::SimRigConfig config;
  config.lms200 = sensors::Lms200Config::Legacy();
  config.pitch_unit.line_pitch_error_deg = line_pitch_error_deg;
  config.pitch_unit.seed = 3;
  sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/office.xml", config);
  EXPECT_TRUE(rig.PlaceAtDefaultStart());
  Result<sensors::Scan3D> scan = rig.Acquire();
  EXPECT_TRUE(scan) << (scan ? "" : scan.error().message);
  return scan ? *scan : sensors::Scan3D{};
}

// RMS about their mean of the heights of the floor returns 0.5-4 m from the robot (base_link's
// z = 0 is the floor the robot stands on; within 5 cm of it), and how many there were.
double FloorRms(const sensors::Scan3D& scan, int* count) {
  double sum = 0, ss = 0;
  *count = 0;
  for (const sensors::ScanPoint& p : scan.points) {
    const double r = std::hypot(p.x, p.y);
    if (r < 0.5 || r > 4.0 || std::abs(p.z) > 0.05) continue;
    sum += p.z;
    ss += double(p.z) * p.z;
    ++*count;
  }
  if (*count == 0) return NAN;
  const double mean = sum / *count;
  return std::sqrt(std::max(0.0, ss / *count - mean * mean));
}

TEST(SetLinesRight, TheServosLinePitchErrorLeavesTheSimulatedFloor) {
  sensors::Scan3D scan = OfficeScan(0.9);
  const sensors::Scan3D recorded = scan;
  int before_n = 0, after_n = 0, true_n = 0;
  const double before = FloorRms(scan, &before_n);
  const double true_pitch = FloorRms(OfficeScan(0.0), &true_n);
  const mapping::LinePitch r = SetLinesRight(scan, sim::SimRigConfig{}.robot.mount);
  const double after = FloorRms(scan, &after_n);
  ASSERT_TRUE(r.nodding) << r.note;
  EXPECT_GT(r.corrected, 60u) << r.note;  // every line meeting the floor 0.5-4 m ahead
  // 0.9 deg at 1-4 m lifts and drops the floor by 1.6-6.3 cm; set right, the floor is as flat as
  // a unit that reports its true pitch leaves it (its 5 mm range noise), within a millimetre.
  EXPECT_GT(before, 2 * true_pitch) << before_n << " floor returns";
  EXPECT_LT(after, true_pitch + 0.001) << after_n << " vs " << true_n << " floor returns";
  EXPECT_NEAR(r.rms_correction_rad * 180 / M_PI, 0.9, 0.35);
  // The ranges stay as measured: the laser turns with its line.
  ASSERT_EQ(scan.points.size(), recorded.points.size());
  for (std::size_t k = 0; k < scan.points.size(); k += 97) {
    EXPECT_EQ(scan.points[k].range_m, recorded.points[k].range_m);
  }
}

TEST(SetLinesRight, AUnitThatReportsItsTruePitchKeepsItsLines) {
  sensors::Scan3D scan = OfficeScan(0.0);
  const sensors::Scan3D recorded = scan;
  const mapping::LinePitch r = SetLinesRight(scan, sim::SimRigConfig{}.robot.mount);
  ASSERT_TRUE(r.nodding) << r.note;
  // 5 mm noise over a line's floor returns: a tenth of a degree at most.
  EXPECT_LT(r.max_correction_rad * 180 / M_PI, 0.15);
  double moved = 0;
  for (std::size_t k = 0; k < scan.points.size(); ++k) {
    if (recorded.points[k].range_m > 10) continue;
    moved = std::max<double>(moved, std::hypot(scan.points[k].x - recorded.points[k].x,
                                               scan.points[k].y - recorded.points[k].y,
                                               scan.points[k].z - recorded.points[k].z));
  }
  EXPECT_LT(moved, 0.015);  // 0.1 deg at 8 m
}

}  // namespace
}  // namespace pitchlab::mission
