#include "pitchlab/sensors/pitch_unit.hpp"

#include <cmath>

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

}  // namespace
}  // namespace pitchlab::sensors
