#include "pitchlab/sensors/lms200.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace pitchlab::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kInf = std::numeric_limits<float>::infinity();

Lms200Config NoiseFree(Lms200RangeMode mode) {
  Lms200Config c;
  c.range_mode = mode;
  c.noise_sigma_m = 0.0;
  return c;
}

LaserLine MeasureConstant(Lms200Model& model, float range_m) {
  std::vector<float> truth(static_cast<std::size_t>(model.readings()), range_m);
  LaserLine line;
  model.Measure(truth.data(), nullptr, nullptr, line);
  return line;
}

TEST(Lms200, EveryVariantHasItsBeamCountAndAngles) {
  struct Case { double fov, res; int readings; int sweeps; };
  for (const Case& c : {Case{180, 1, 181, 1}, Case{180, 0.5, 361, 2}, Case{100, 1, 101, 1},
                        Case{100, 0.5, 201, 2}, Case{100, 0.25, 401, 4}}) {
    Lms200Config config;
    config.fov_deg = c.fov;
    config.resolution_deg = c.res;
    Lms200Model model(config);
    EXPECT_EQ(model.readings(), c.readings) << c.fov << "/" << c.res;
    EXPECT_EQ(model.interlaced_sweeps(), c.sweeps);
    EXPECT_NEAR(model.angle_min_rad(), -c.fov / 2 * kPi / 180, 1e-12);
    const double last = model.angle_min_rad() + (c.readings - 1) * model.angle_increment_rad();
    EXPECT_NEAR(last, c.fov / 2 * kPi / 180, 1e-12);
  }
}

// The LMS200's finer resolutions interlace 1 deg turns of its mirror: 0.5 deg is two sweeps,
// 0.25 deg four, 1 deg one; a step that is no whole fraction of a turn is one sweep.
TEST(Lms200, AFinerResolutionIsThatManyInterlacedTurns) {
  constexpr double kDeg = M_PI / 180.0;
  EXPECT_EQ(InterlacedSweeps(0.5 * kDeg), 2);
  EXPECT_EQ(InterlacedSweeps(0.25 * kDeg), 4);
  EXPECT_EQ(InterlacedSweeps(1.0 * kDeg), 1);
  EXPECT_EQ(InterlacedSweeps(0.4 * kDeg), 1);  // 2.5 beams a turn: no whole number of turns
  EXPECT_EQ(InterlacedSweeps(0.0), 1);
  EXPECT_EQ(InterlacedSweeps(0.5 * kDeg, 0.5 * kDeg), 1);  // a turn as fine as the beams
}

TEST(Lms200, RejectsSettingsTheDeviceDoesNotHave) {
  Lms200Config quarter_wide;
  quarter_wide.resolution_deg = 0.25;  // 0.25 deg exists only with the 100 deg field of view
  EXPECT_THROW(Lms200Model{quarter_wide}, std::invalid_argument);
  Lms200Config odd_fov;
  odd_fov.fov_deg = 270;
  EXPECT_THROW(Lms200Model{odd_fov}, std::invalid_argument);
  Lms200Config odd_baud;
  odd_baud.baud = 115200;
  EXPECT_THROW(Lms200Model{odd_baud}, std::invalid_argument);
  Lms200Config negative_noise;
  negative_noise.noise_sigma_m = -0.01;
  EXPECT_THROW(Lms200Model{negative_noise}, std::invalid_argument);
}

TEST(Lms200, CmModeQuantizesToCentimetres) {
  Lms200Model model(NoiseFree(Lms200RangeMode::kCm));
  const LaserLine line = MeasureConstant(model, 3.14159f);
  for (std::size_t i = 0; i < line.ranges_m.size(); ++i) {
    ASSERT_EQ(line.status[i], ReadingStatus::kValid);
    EXPECT_FLOAT_EQ(line.ranges_m[i], 3.14f);
  }
  EXPECT_DOUBLE_EQ(model.max_range_m(), 81.91);
}

TEST(Lms200, MmModeQuantizesToMillimetres) {
  Lms200Model model(NoiseFree(Lms200RangeMode::kMm));
  const LaserLine line = MeasureConstant(model, 3.14159f);
  EXPECT_FLOAT_EQ(line.ranges_m.front(), 3.142f);
  EXPECT_DOUBLE_EQ(model.max_range_m(), 8.191);
}

TEST(Lms200, BeyondTheModesMaximumIsFlaggedOverRangeNotZero) {
  Lms200Model mm(NoiseFree(Lms200RangeMode::kMm));
  const LaserLine far_mm = MeasureConstant(mm, 9.0f);  // within cm range, beyond mm range
  EXPECT_EQ(far_mm.status.front(), ReadingStatus::kOverRange);
  EXPECT_TRUE(std::isnan(far_mm.ranges_m.front()));
  Lms200Model cm(NoiseFree(Lms200RangeMode::kCm));
  EXPECT_EQ(MeasureConstant(cm, 9.0f).status.front(), ReadingStatus::kValid);
  EXPECT_EQ(MeasureConstant(cm, 90.0f).status.front(), ReadingStatus::kOverRange);
}

TEST(Lms200, NothingHitIsFlaggedNoReturn) {
  Lms200Model model(NoiseFree(Lms200RangeMode::kCm));
  const LaserLine line = MeasureConstant(model, kInf);
  EXPECT_EQ(line.status.front(), ReadingStatus::kNoReturn);
  EXPECT_TRUE(std::isnan(line.ranges_m.front()));
}

TEST(Lms200, NoiseHasTheConfiguredMeanAndSigma) {
  Lms200Config config = Lms200Config::Legacy();  // constant noise, no dropouts
  config.range_mode = Lms200RangeMode::kMm;  // 1 mm unit: quantization adds 0.29 mm sigma
  config.noise_sigma_m = 0.005;
  config.range_bias_m = 0.002;
  config.seed = 7;
  Lms200Model model(config);
  constexpr float kTrue_m = 4.0f;
  double sum = 0, sum_sq = 0;
  int n = 0;
  for (int k = 0; k < 300; ++k) {  // 300 lines x 361 readings
    const LaserLine line = MeasureConstant(model, kTrue_m);
    for (float r : line.ranges_m) {
      sum += r - kTrue_m;
      sum_sq += (r - kTrue_m) * (r - kTrue_m);
      ++n;
    }
  }
  const double mean = sum / n;
  const double sigma = std::sqrt(sum_sq / n - mean * mean);
  constexpr double kMeanTolerance_m = 1e-4;   // ~ 5 standard errors of the mean
  constexpr double kSigmaTolerance_m = 1e-4;  // quantization and sampling
  EXPECT_NEAR(mean, 0.002, kMeanTolerance_m);
  EXPECT_NEAR(sigma, std::sqrt(0.005 * 0.005 + 0.001 * 0.001 / 12), kSigmaTolerance_m);
}

TEST(Lms200, SameSeedGivesTheSameReadingsAndAnotherSeedDoesNot) {
  Lms200Config config;
  config.seed = 42;
  Lms200Model a(config), b(config);
  config.seed = 43;
  Lms200Model c(config);
  const LaserLine la = MeasureConstant(a, 5.0f), lb = MeasureConstant(b, 5.0f),
                  lc = MeasureConstant(c, 5.0f);
  EXPECT_EQ(0, std::memcmp(la.ranges_m.data(), lb.ranges_m.data(), la.ranges_m.size() * 4));
  EXPECT_NE(0, std::memcmp(la.ranges_m.data(), lc.ranges_m.data(), la.ranges_m.size() * 4));
}

TEST(Lms200, LineTimingFollowsMirrorRateAndBaud) {
  Lms200Config config;  // 180 deg / 0.5 deg: two interlaced turns of a 75 Hz mirror
  Lms200Model fast(config);
  EXPECT_EQ(fast.telegram_bytes(), 10 + 2 * 361);
  EXPECT_NEAR(fast.transfer_time_s(), 732 * 10 / 500000.0, 1e-12);
  EXPECT_NEAR(fast.line_period_s(), 2 / 75.0 + 732 * 10 / 500000.0, 1e-12);
  EXPECT_NEAR(fast.measurement_time_s(), (1 + 0.5) / 75.0, 1e-12);
  config.baud = 38400;
  Lms200Model slow(config);
  EXPECT_NEAR(slow.line_period_s() - fast.line_period_s(), 7320 / 38400.0 - 7320 / 500000.0,
              1e-12);
  // The seed's 200-line scan at 500 kbaud: about 8.3 s, "up to ~9 s" in DESIGN.md.
  EXPECT_NEAR(200 * fast.line_period_s(), 8.26, 0.05);
}

TEST(Lms200, MixedPixelsBlendBothSurfacesAtADepthEdge) {
  Lms200Config config = NoiseFree(Lms200RangeMode::kMm);
  config.mixed_pixels = true;
  Lms200Model model(config);
  const auto n = static_cast<std::size_t>(model.readings());
  std::vector<float> centre(n, 2.0f), lo(n, 2.0f), hi(n, 2.0f);
  hi[10] = 5.0f;  // beam 10 straddles an edge between 2 m and 5 m
  LaserLine line;
  model.Measure(centre.data(), lo.data(), hi.data(), line);
  EXPECT_FLOAT_EQ(line.ranges_m[10], 3.0f);
  EXPECT_FLOAT_EQ(line.ranges_m[11], 2.0f);
}

}  // namespace
}  // namespace pitchlab::sensors
