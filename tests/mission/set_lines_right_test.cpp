// SetLinesRight on pitchlab's own scans: the simulated office from its start, with the pitch unit
// reporting each line's pitch off by the real 3DTK rig's error (pitch_unit.line_pitch_error_deg
// 0.9), with one that pitches on between a line's interlaced sweeps (sweep_lag_deg), and with a
// unit that reports its true pitch.

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mission/elevation_scan.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mission {
namespace {

sensors::Scan3D OfficeScan(double line_pitch_error_deg, double sweep_lag_deg = 0.0) {
  sim::SimRigConfig config;
  config.lms200 = sensors::Lms200Config::Legacy();
  config.pitch_unit.line_pitch_error_deg = line_pitch_error_deg;
  config.pitch_unit.sweep_lag_deg = sweep_lag_deg;
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

// The mean height of the odd readings' floor returns 1-3 m from the robot less the even ones'
// (base_link's z = 0 is the floor; returns within 0.15 m of it).
double OddOverEven(const sensors::Scan3D& scan) {
  double sum[2] = {0, 0};
  int n[2] = {0, 0};
  for (const sensors::ScanPoint& p : scan.points) {
    const double r = std::hypot(p.x, p.y);
    if (r < 1.0 || r > 3.0 || std::abs(p.z) > 0.15) continue;
    sum[p.beam % 2] += p.z;
    ++n[p.beam % 2];
  }
  return sum[1] / std::max(n[1], 1) - sum[0] / std::max(n[0], 1);
}

// A unit that pitches on 1 deg between the two interlaced sweeps of each 0.5 deg line: the odd
// sweep's floor lies off the even one's by 1 deg times its distance; each sweep set right on its
// own, the two agree and the floor is as flat as a unit without the lag leaves it.
TEST(SetLinesRight, EachInterlacedSweepIsSetRightOnItsOwn) {
  sensors::Scan3D scan = OfficeScan(0.0, 1.0);
  const double before = OddOverEven(scan);
  int after_n = 0, true_n = 0;
  const double true_pitch = FloorRms(OfficeScan(0.0), &true_n);
  const mapping::LinePitch r = SetLinesRight(scan, sim::SimRigConfig{}.robot.mount);
  ASSERT_TRUE(r.nodding) << r.note;
  EXPECT_EQ(r.sweeps_per_line, 2);
  EXPECT_LE(r.lines, scan.lines.size());
  // 1 deg at 1-3 m is 1.7-5.2 cm: 1.6 cm on average over this scan's floor returns there.
  EXPECT_GT(std::abs(before), 0.01);
  EXPECT_LT(std::abs(OddOverEven(scan)), 0.003);
  // Each sweep's turn is fitted to half a line's returns: its noise is sqrt(2) a whole line's,
  // and the floor is left within 2 mm (not 1) of the unit without the lag.
  EXPECT_LT(FloorRms(scan, &after_n), true_pitch + 0.002) << after_n << " vs " << true_n;
  bool both = false;
  for (const mapping::LineCorrection& c : r.line_corrections) both = both || c.sweep == 1;
  EXPECT_TRUE(both);
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
