#include "pitchlab/sensors/pitching_scanner.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/pitch_unit.hpp"

namespace pitchlab::sensors {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// A pitch axis that goes to the servo step and reports the encoder, as the device would.
class FakeAxis : public PitchAxis {
 public:
  explicit FakeAxis(int fail_at_move = -1) : fail_at_move_(fail_at_move) {}
  Result<double> MoveTo(double pitch_rad, std::chrono::milliseconds) override {
    if (moves_++ == fail_at_move_) return Fail(Error::Code::kTimeout, "no answer");
    angle_rad_ = unit_.StepAngle(unit_.StepFor(pitch_rad));
    return unit_.EncoderAngle(angle_rad_);
  }
  Result<double> ReadEncoder() override { return unit_.EncoderAngle(angle_rad_); }
  double angle_rad_ = 0;

 private:
  PitchUnitModel unit_{PitchUnitConfig{}};
  int fail_at_move_;
  int moves_ = 0;
};

// A line scanner facing a wall 4 m ahead of the mirror at every pitch.
class FakeScanner : public LineScanner {
 public:
  Result<LaserLine> NextLine(std::chrono::milliseconds) override {
    std::vector<float> truth(static_cast<std::size_t>(model_.readings()), 4.0f);
    LaserLine line;
    model_.Measure(truth.data(), nullptr, nullptr, line);
    line.stamp_s = clock_s_;
    clock_s_ += model_.line_period_s();
    return line;
  }
  double clock_s_ = 0;

 private:
  Lms200Model model_{Lms200Config{}};
};

TEST(PitchingScanSource, SeedPatternGives200LinesAtEncoderPitch) {
  FakeAxis axis;
  FakeScanner scanner;
  PitchingScanSource source(scanner, axis, ScanPatternConfig{}, MountConfig{});
  int last_progress = 0;
  source.set_progress([&](int done, int total) {
    EXPECT_EQ(total, 200);
    last_progress = done;
  });
  Result<Scan3D> scan = source.Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_EQ(last_progress, 200);
  ASSERT_EQ(scan->lines.size(), 200u);
  EXPECT_EQ(scan->points.size() + scan->no_returns + scan->over_ranges, 200u * 361u);
  // First line: -40 deg commanded is step -89 (-40.05 deg), read to the encoder's 0.01 deg.
  EXPECT_NEAR(scan->lines.front().pitch_rad, -40.05 * kDeg, 0.005 * kDeg);
  EXPECT_NEAR(scan->lines.back().pitch_rad, 59.85 * kDeg, 0.005 * kDeg);  // step 133
  for (const LaserLine& line : scan->lines) {
    const double steps = line.pitch_rad / (0.45 * kDeg);
    EXPECT_NEAR(steps, std::round(steps), 0.02);  // every line sits on a servo step
  }
}

TEST(PitchingScanSource, ADeviceErrorNamesTheLineAndStopsTheScan) {
  FakeAxis axis(/*fail_at_move=*/17);
  FakeScanner scanner;
  PitchingScanSource source(scanner, axis, ScanPatternConfig{}, MountConfig{});
  Result<Scan3D> scan = source.Acquire();
  ASSERT_FALSE(scan);
  EXPECT_EQ(scan.error().code, Error::Code::kTimeout);
  EXPECT_NE(scan.error().message.find("line 17"), std::string::npos) << scan.error().message;
}

TEST(PitchingScanSource, AnAttitudeProbeDeskewsWhenItAnswersEveryLineAboveItsNoiseFloor) {
  FakeAxis axis;
  FakeScanner scanner;
  ScanPatternConfig pattern;
  pattern.lines = 10;
  PitchingScanSource source(scanner, axis, pattern, MountConfig{});
  // The base yaws 1 deg per line: the first line's wall points turn by 9 deg into the last frame.
  int reads = 0;
  source.set_attitude_probe([&]() -> std::optional<Eigen::Quaterniond> {
    return Eigen::Quaterniond(Eigen::AngleAxisd(reads++ * kDeg, Eigen::Vector3d::UnitZ()));
  });
  Result<Scan3D> scan = source.Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_EQ(reads, 10);
  EXPECT_TRUE(scan->deskewed);
  EXPECT_NEAR(scan->deskew_max_rad, 9 * kDeg, 1e-9);
  const Scan3D plain = AssembleScan(scan->lines, MountConfig{});
  const ScanPoint& p = scan->points.front();  // line 0
  const ScanPoint& q = plain.points.front();
  ASSERT_EQ(p.line, 0);
  const double turned = std::atan2(p.y, p.x) - std::atan2(q.y, q.x);
  EXPECT_NEAR(turned, -9 * kDeg, 1e-6);

  // A rotation below the sensor's noise floor is left alone, but still reported.
  reads = 0;
  source.set_attitude_probe(
      [&]() -> std::optional<Eigen::Quaterniond> {
        return Eigen::Quaterniond(Eigen::AngleAxisd(reads++ * kDeg, Eigen::Vector3d::UnitZ()));
      },
      10 * kDeg);
  scan = source.Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_FALSE(scan->deskewed);
  EXPECT_NEAR(scan->deskew_max_rad, 9 * kDeg, 1e-9);
  const Scan3D swept = AssembleScan(scan->lines, MountConfig{});
  EXPECT_NEAR(scan->points.front().y, swept.points.front().y, 1e-6);

  // No answer for one line: the scan stays as swept, never half corrected.
  reads = 0;
  source.set_attitude_probe([&]() -> std::optional<Eigen::Quaterniond> {
    if (reads++ == 4) return std::nullopt;
    return Eigen::Quaterniond::Identity();
  });
  scan = source.Acquire();
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_FALSE(scan->deskewed);
  EXPECT_EQ(reads, 5);  // not asked again after it had none
}

TEST(PitchingScanSource, RejectsAPatternWithoutLines) {
  FakeAxis axis;
  FakeScanner scanner;
  ScanPatternConfig pattern;
  pattern.lines = 0;
  EXPECT_THROW(PitchingScanSource(scanner, axis, pattern, MountConfig{}), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::sensors
