#include "pitchlab/sensors/pitch_unit.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace pitchlab::sensors {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

TEST(PitchUnit, CommandedAngleGoesToTheNearestServoStep) {
  PitchUnitModel unit{PitchUnitConfig{}};
  EXPECT_EQ(unit.StepFor(10.0 * kDeg), 22);  // 10 / 0.45 = 22.2
  EXPECT_NEAR(unit.StepAngle(22), 9.9 * kDeg, 1e-12);
  EXPECT_EQ(unit.StepFor(-0.2 * kDeg), 0);
  EXPECT_EQ(unit.StepFor(-0.3 * kDeg), -1);
}

TEST(PitchUnit, StepsStayInsideTheMechanicalLimits) {
  PitchUnitConfig config;
  config.min_deg = -30;
  config.max_deg = 45;
  PitchUnitModel unit(config);
  EXPECT_LE(unit.StepAngle(unit.StepFor(80 * kDeg)), 45 * kDeg + 1e-12);
  EXPECT_GE(unit.StepAngle(unit.StepFor(-80 * kDeg)), -30 * kDeg - 1e-12);
  EXPECT_EQ(unit.StepFor(80 * kDeg), 100);  // 45 / 0.45
}

TEST(PitchUnit, EncoderReadsTheTrueAngleToOneCount) {
  PitchUnitConfig config;
  config.encoder_counts_per_rev = 4096;
  PitchUnitModel unit(config);
  const double count = 2 * 3.14159265358979323846 / 4096;
  for (double a : {0.0, 0.123, -0.5, 1.2}) {
    const double read = unit.EncoderAngle(a);
    EXPECT_LE(std::abs(read - a), count / 2 + 1e-15);
    EXPECT_NEAR(std::remainder(read, count), 0.0, 1e-12);
  }
}

TEST(PitchUnit, MoveTimeIsSlewPlusSettle) {
  PitchUnitConfig config;
  config.max_speed_dps = 90;
  config.settle_s = 0.02;
  PitchUnitModel unit(config);
  EXPECT_NEAR(unit.MoveTime(0, 45 * kDeg), 0.5 + 0.02, 1e-12);
}

TEST(PitchUnit, RejectsImpossibleConfigs) {
  PitchUnitConfig config;
  config.step_deg = 0;
  EXPECT_THROW(PitchUnitModel{config}, std::invalid_argument);
  config = {};
  config.min_deg = 10;
  config.max_deg = 5;
  EXPECT_THROW(PitchUnitModel{config}, std::invalid_argument);
}

// The reported pitch of lines 0.52 deg apart over the 3DTK rig's sweep (-48 .. +67 deg).
std::vector<double> SweepErrorsDeg(const PitchUnitModel& unit) {
  std::vector<double> e;
  for (double a = -48.0; a <= 67.0; a += 0.52) e.push_back(unit.LinePitchError(a * kDeg) / kDeg);
  return e;
}

TEST(PitchUnit, ReportsItsTruePitchUnlessGivenALinePitchError) {
  PitchUnitModel unit{PitchUnitConfig{}};
  for (double a : {-0.7, 0.0, 0.31, 1.1}) {
    EXPECT_EQ(unit.LinePitchError(a), 0.0);
    EXPECT_EQ(unit.ReportedAngle(a), unit.EncoderAngle(a));
  }
}

TEST(PitchUnit, ALinePitchErrorWobblesAndJumpsAsTheRealRigsDoes) {
  PitchUnitConfig config;
  config.line_pitch_error_deg = 0.9;  // the real rig's RMS
  config.seed = 7;
  const PitchUnitModel unit(config);
  const std::vector<double> e = SweepErrorsDeg(unit);
  double ss = 0, max_jump = 0;
  for (std::size_t k = 0; k < e.size(); ++k) {
    ss += e[k] * e[k];
    if (k > 0) max_jump = std::max(max_jump, std::abs(e[k] - e[k - 1]));
  }
  const double rms = std::sqrt(ss / e.size());
  EXPECT_GT(rms, 0.6);  // 27 steps and wobbles over the sweep: the RMS is near its 0.9
  EXPECT_LT(rms, 1.2);
  // Neighbouring lines jump by up to 2-3 deg at a step; within a step they move by the wobble's
  // slope at most, 2 pi x 0.9 / 4.2 x 0.52 = 0.7 deg.
  EXPECT_GT(max_jump, 1.5);
  // The same pitch gives the same error, whatever was asked before (the real error repeats at the
  // same pitches from scan to scan); ReportedAngle reads the angle off by it.
  EXPECT_EQ(unit.LinePitchError(0.2), PitchUnitModel(config).LinePitchError(0.2));
  EXPECT_NEAR(unit.ReportedAngle(0.2), 0.2 + unit.LinePitchError(0.2),
              2 * 3.14159265358979 / 36000);
  config.seed = 8;
  EXPECT_NE(SweepErrorsDeg(PitchUnitModel(config)), e);
}

TEST(PitchUnit, RejectsANegativeLinePitchErrorOrPeriod) {
  PitchUnitConfig config;
  config.line_pitch_error_deg = -0.1;
  EXPECT_THROW(PitchUnitModel{config}, std::invalid_argument);
  config = {};
  config.line_pitch_error_period_deg = 0;
  EXPECT_THROW(PitchUnitModel{config}, std::invalid_argument);
}

TEST(PitchUnit, RejectsASweepLagBelowZeroOrAboveFiveDegrees) {
  PitchUnitConfig config;
  config.sweep_lag_deg = 0.16;  // the real 3DTK rig's mean
  EXPECT_NO_THROW(PitchUnitModel{config});
  for (const double bad : {-0.1, 5.5}) {
    config.sweep_lag_deg = bad;
    try {
      PitchUnitModel model{config};
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("sweep_lag_deg"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace pitchlab::sensors
