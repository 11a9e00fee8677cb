// RectifyLinePitch on an analytic nodding scan of a corridor (floor 0.4 m below the laser, walls
// 1.2 m to either side, an end wall 8 m ahead, a ceiling 2 m up): lines cast at a true pitch that
// differs from the recorded one by a known pattern, as the real 3DTK rig's lines do.

#include "pitchlab/mapping/line_pitch.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace pitchlab::mapping {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180;
constexpr double kFloorZ = -0.4, kWallY = 1.2, kEndX = 8.0, kCeilingZ = 2.0;

// Distance along unit ray `d` from the origin to the corridor's first surface.
double RangeInCorridor(const Eigen::Vector3d& d) {
  double t = std::numeric_limits<double>::infinity();
  if (d.z() < 0) t = std::min(t, kFloorZ / d.z());
  if (d.z() > 0) t = std::min(t, kCeilingZ / d.z());
  if (d.y() != 0) t = std::min(t, kWallY / std::abs(d.y()));
  if (d.x() > 0) t = std::min(t, kEndX / d.x());
  return t;
}

// The direction of beam `azimuth` of a line pitched down by `pitch` about y.
Eigen::Vector3d Beam(double pitch, double azimuth) {
  return {std::cos(azimuth) * std::cos(pitch), std::sin(azimuth),
          -std::cos(azimuth) * std::sin(pitch)};
}

// The scan as recorded: each line's ranges measured at pitch + error(line) (or error(line,
// beam), beam counted from straight ahead), placed at the recorded pitch; lines every 0.5 deg
// from 30 deg up to 50 deg down, beams every `beam_deg` from straight ahead out to 89.5 deg.
template <typename Error>
std::vector<Eigen::Vector3f> NoddingScan(Error error, double noise_m, unsigned seed,
                                         double mirror_above_axis_m = 0, double beam_deg = 0.5) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::vector<Eigen::Vector3f> points;
  const int beams = static_cast<int>(89.5 / beam_deg);
  int line = 0;
  for (double pitch = -30 * kDeg; pitch <= 50.01 * kDeg; pitch += 0.5 * kDeg, ++line) {
    for (int beam = -beams; beam <= beams; ++beam) {
      const double az = beam * beam_deg * kDeg;
      double e = 0;
      if constexpr (std::is_invocable_v<Error, int, int>) {
        e = error(line, beam);
      } else {
        e = error(line);
      }
      const double r = RangeInCorridor(Beam(pitch + e, az)) + noise(rng);
      // The mirror turns with the mount about the axis at the origin (pitchlab's own scans, in
      // base_link, have it ~5 cm off the axis); the axis itself is the frame's y.
      const Eigen::Vector3d mirror(mirror_above_axis_m * std::sin(pitch), 0,
                                   mirror_above_axis_m * std::cos(pitch));
      points.push_back((mirror + r * Beam(pitch, az)).cast<float>());
    }
  }
  return points;
}

// The rig's pitch error pattern: a 0.8 deg wobble every 8 lines and a 1.5 deg jump at line 100
// (20 deg down: the lines from there on meet the floor within 1.1 m).
double Wobble(int line) {
  return 0.8 * kDeg * std::sin(2 * 3.14159265358979 * line / 8.0) + (line >= 100 ? -1.5 * kDeg : 0);
}

// Largest distance of the floor points within `radius_m` from their least-squares plane [m].
double FloorSpread(const std::vector<Eigen::Vector3f>& points, double radius_m) {
  std::vector<Eigen::Vector3d> floor;
  for (const Eigen::Vector3f& p : points) {
    if (p.z() < -0.25 && std::hypot(p.x(), p.y()) < radius_m && std::abs(p.y()) < kWallY - 0.1)
      floor.push_back(p.cast<double>());
  }
  Eigen::MatrixXd A(floor.size(), 3);
  Eigen::VectorXd z(floor.size());
  for (std::size_t k = 0; k < floor.size(); ++k) {
    A.row(k) << floor[k].x(), floor[k].y(), 1.0;
    z(k) = floor[k].z();
  }
  const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(z);
  return (z - A * plane).cwiseAbs().maxCoeff();
}

TEST(LinePitch, LinesOffByAWobbleAndAJumpLieOnOneFloorAgain) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(Wobble, 0.003, 1);
  const double before = FloorSpread(scan, 4.0);
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero());
  ASSERT_TRUE(r.nodding) << r.note;
  EXPECT_EQ(r.lines, 161u);
  EXPECT_GT(r.corrected, 60u);  // every line meeting the floor 0.5-4 m ahead: 5.7-38.7 deg down
  // Uncorrected, the wobble alone lifts and drops the floor by 0.8 deg x 1-4 m = 1.4-5.6 cm.
  EXPECT_GT(before, 0.03);
  // Corrected, what is left is the 3 mm range noise (4 sigma, plus the float coordinates).
  EXPECT_LT(FloorSpread(scan, 4.0), 0.015);
  EXPECT_LT(r.floor_rms_after_m, 0.004);
  EXPECT_GT(r.floor_rms_before_m, 0.01);
}

// Each corrected line is reported at its recorded pitch with the turn it got: from line to line
// the turns follow the error the lines were cast with. (Not line by line: a turn common to all
// lines, and one falling as 1 / distance ahead, are the floor plane's, and are left to it.)
TEST(LinePitch, ReportsEachLinesRecordedPitchAndTurn) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(Wobble, 0.003, 1);
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero());
  ASSERT_EQ(r.line_corrections.size(), r.corrected);
  // Beams every 0.5 deg: each line is two interlaced 1 deg sweeps, each reported on its own.
  ASSERT_EQ(r.sweeps_per_line, 2);
  double off_sq = 0, step_sq = 0;
  int steps = 0;
  for (std::size_t k = 0; k < r.line_corrections.size(); ++k) {
    const LineCorrection& c = r.line_corrections[k];
    // Recorded every 0.5 deg from 30 deg up: line (pitch + 30 deg) / 0.5 deg, to float rounding.
    const double line = (c.pitch_rad / kDeg + 30) / 0.5;
    EXPECT_NEAR(line, std::round(line), 1e-3);
    EXPECT_TRUE(c.sweep == 0 || c.sweep == 1) << c.sweep;
    if (k < 2) continue;
    // By pitch, then sweep: the same sweep of the line before lies two entries back.
    const LineCorrection& b = r.line_corrections[k - 2];
    const int l = static_cast<int>(std::round(line));
    ASSERT_GE(c.pitch_rad, r.line_corrections[k - 1].pitch_rad);
    if (b.sweep != c.sweep) continue;
    if (std::round((b.pitch_rad / kDeg + 30) / 0.5) != l - 1) continue;  // neighbours only
    // A line cast lower than recorded (a positive error) is turned down by as much.
    const double error_step = Wobble(l) - Wobble(l - 1);
    off_sq += std::pow((c.correction_rad - b.correction_rad) - error_step, 2);
    step_sq += error_step * error_step;
    ++steps;
  }
  ASSERT_GT(steps, 50);
  EXPECT_GT(std::sqrt(step_sq / steps), 0.4 * kDeg);   // the wobble's steps, and the jump
  EXPECT_LT(std::sqrt(off_sq / steps), 0.05 * kDeg);  // followed to a tenth of that
}

TEST(LinePitch, LinesAtTheirRecordedPitchStayWhereTheyAre) {
  const std::vector<Eigen::Vector3f> truth = NoddingScan([](int) { return 0.0; }, 0.003, 2);
  std::vector<Eigen::Vector3f> scan = truth;
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero());
  ASSERT_TRUE(r.nodding) << r.note;
  // Noise alone: a line's 3 mm noise over ~100 floor points at 1-4 m is a few hundredths of a
  // degree of pitch.
  EXPECT_LT(r.max_correction_rad, 0.1 * kDeg);
  double moved = 0;
  for (std::size_t k = 0; k < scan.size(); ++k) {
    if (truth[k].norm() < 10) moved = std::max(moved, double((scan[k] - truth[k]).norm()));
  }
  EXPECT_LT(moved, 0.01);  // at the end wall's 8 m, 0.07 deg is 1 cm
}

// A scan whose mirror sits off the pitch axis (pitchlab's own, in base_link): its lines' points do
// not share one elevation about the frame's y axis through the sensor, so it is not taken for a
// nodding scan in its own frame and nothing moves.
TEST(LinePitch, AScanWhoseLaserSitsOffThePitchAxisIsLeftAlone) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(Wobble, 0.003, 4, 0.05);
  const std::vector<Eigen::Vector3f> copy = scan;
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f(0, 0, 0.05f));
  EXPECT_FALSE(r.nodding) << r.lines << " lines";
  EXPECT_EQ(scan, copy);
}

// The same scan with its lines given (as pitchlab's own Scan3D knows them): each line is turned
// about the pitch axis, not about the mirror, and the floor is flat again.
TEST(LinePitch, AScanThatKnowsItsLinesIsSetRightAboutThePitchAxis) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(Wobble, 0.003, 4, 0.05);
  constexpr std::uint32_t kBeams = 359;  // -89.5 .. 89.5 deg every 0.5 deg
  ASSERT_EQ(scan.size() % kBeams, 0u);
  std::vector<std::vector<std::uint32_t>> lines(scan.size() / kBeams);
  for (std::uint32_t k = 0; k < scan.size(); ++k) lines[k / kBeams].push_back(k);
  const double before = FloorSpread(scan, 4.0);
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero(), lines);
  EXPECT_EQ(r.lines, 161u);
  EXPECT_GT(r.corrected, 60u) << r.note;
  EXPECT_GT(before, 0.03);
  EXPECT_LT(FloorSpread(scan, 4.0), 0.015);
  EXPECT_LT(r.floor_rms_after_m, 0.004);
  // An index past the points is a caller's error, named.
  lines[0].push_back(static_cast<std::uint32_t>(scan.size()));
  EXPECT_THROW(RectifyLinePitch(scan, Eigen::Vector3f::Zero(), lines), std::invalid_argument);
}

// The 3DTK rig's lines: at 0.5 deg an LMS200 line is two 1 deg sweeps of its mirror, taken one
// turn apart while the servo moves on. The second sweep lags 0.2 deg, and where the servo jumps
// (line 100, 1.5 deg) it jumps between the two sweeps of that line: half of it at the old pitch,
// half at the new, as the real scan002's line at 11.5 deg down met the floor at 2.2 and 3.3 m.
double SweepWobble(int line, int beam) {
  const bool second = (beam % 2 + 2) % 2 == 1;
  const bool jumped = line > 100 || (line == 100 && second);
  return 0.8 * kDeg * std::sin(2 * 3.14159265358979 * line / 8.0) + (second ? 0.2 * kDeg : 0) +
         (jumped ? -1.5 * kDeg : 0);
}

TEST(LinePitch, EachInterlacedSweepOfALineIsSetRightOnItsOwn) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(SweepWobble, 0.003, 5);
  std::vector<Eigen::Vector3f> whole_lines = scan;
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero());
  ASSERT_TRUE(r.nodding) << r.note;
  EXPECT_EQ(r.sweeps_per_line, 2);
  EXPECT_LT(FloorSpread(scan, 4.0), 0.015);
  EXPECT_LT(r.floor_rms_after_m, 0.004);
  // Taken as whole lines (sweeps as wide as the beams), line 100's two halves cannot both lie
  // on the floor: 1.5 deg at 1.1 m is 2.9 cm.
  LinePitchConfig whole;
  whole.sweep_step_rad = 0.5 * kDeg;
  const LinePitch w = RectifyLinePitch(whole_lines, Eigen::Vector3f::Zero(), whole);
  EXPECT_EQ(w.sweeps_per_line, 1);
  EXPECT_GT(FloorSpread(whole_lines, 4.0), 0.025);
}

// At 0.25 deg an LMS200 line is four sweeps: each a step of 0.1 deg behind the one before.
TEST(LinePitch, AQuarterDegreeLineIsFourSweeps) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(
      [](int line, int beam) { return Wobble(line) + 0.1 * kDeg * ((beam % 4 + 4) % 4); }, 0.003,
      7, 0, 0.25);
  const double before = FloorSpread(scan, 4.0);
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero());
  ASSERT_TRUE(r.nodding) << r.note;
  EXPECT_EQ(r.sweeps_per_line, 4);
  EXPECT_GT(before, 0.03);
  EXPECT_LT(FloorSpread(scan, 4.0), 0.015);
  EXPECT_LT(r.floor_rms_after_m, 0.004);
}

// Beams 1 deg apart are one turn of the mirror: nothing to split.
TEST(LinePitch, ALineOfOneSweepIsNotSplit) {
  std::vector<Eigen::Vector3f> scan = NoddingScan(Wobble, 0.003, 6, 0, 1.0);
  const LinePitch r = RectifyLinePitch(scan, Eigen::Vector3f::Zero());
  ASSERT_TRUE(r.nodding) << r.note;
  EXPECT_EQ(r.sweeps_per_line, 1);
  EXPECT_GT(r.corrected, 60u);
  EXPECT_LT(FloorSpread(scan, 4.0), 0.015);
}

TEST(LinePitch, ACloudThatIsNotMadeOfLinesIsLeftAlone) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  std::vector<Eigen::Vector3f> cloud;
  for (int k = 0; k < 20000; ++k) cloud.emplace_back(u(rng), u(rng), -0.4f + 0.01f * u(rng));
  const std::vector<Eigen::Vector3f> copy = cloud;
  const LinePitch r = RectifyLinePitch(cloud, Eigen::Vector3f::Zero());
  EXPECT_FALSE(r.nodding);
  EXPECT_EQ(r.corrected, 0u);
  EXPECT_NE(r.note.find("not a nodding scan"), std::string::npos) << r.note;
  EXPECT_EQ(cloud, copy);
}

}  // namespace
}  // namespace pitchlab::mapping
