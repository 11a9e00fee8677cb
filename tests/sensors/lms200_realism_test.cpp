// The LMS200 model's issue-16 effects against their formulas: range noise growing with range and
// incidence, dropouts at grazing incidence and long range, the mount error draw, determinism.

#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/sensors/lms200.hpp"

namespace pitchlab::sensors {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr int kLines = 200;  // 361 x 200 = 72,200 readings per case: one seed-pattern scan

// Only the effect under test: mm mode (1 mm quantization), no dropouts.
Lms200Config NoiseOnly() {
  Lms200Config c = Lms200Config::Measured();
  c.range_mode = Lms200RangeMode::kMm;
  c.dropout_grazing_at_90 = 0.0;
  c.dropout_far_per_m = 0.0;
  return c;
}

// The readings' error against the truth over kLines lines at one range and incidence:
// mean, standard deviation and the share of readings returned.
struct Sample {
  double mean = 0, sigma = 0, returned = 0;
};
Sample Measure(Lms200Model& model, double range_m, double incidence_deg) {
  const auto n = static_cast<std::size_t>(model.readings());
  const std::vector<float> truth(n, static_cast<float>(range_m));
  const std::vector<float> cosine(n, static_cast<float>(std::cos(incidence_deg * kDeg)));
  double sum = 0, sum2 = 0, count = 0;
  for (int k = 0; k < kLines; ++k) {
    LaserLine line;
    model.Measure(truth.data(), nullptr, nullptr, line, cosine.data());
    for (std::size_t i = 0; i < n; ++i) {
      if (line.status[i] != ReadingStatus::kValid) continue;
      const double e = line.ranges_m[i] - range_m;
      sum += e;
      sum2 += e * e;
      count += 1;
    }
  }
  Sample s;
  s.mean = sum / count;
  s.sigma = std::sqrt(sum2 / count - s.mean * s.mean);
  s.returned = count / (static_cast<double>(n) * kLines);
  return s;
}

TEST(Lms200Realism, NoiseSigmaIsTheDocumentedFormula) {
  Lms200Config c = NoiseOnly();
  c.noise_sigma_m = 0.003;
  c.noise_per_m = 0.002;
  c.incidence_noise_gain = 0.5;
  c.beam_divergence_deg = 0.25;
  const Lms200Model model(c);
  const double div = 0.25 * kDeg;
  // Head on: the constant and the range term add in quadrature.
  EXPECT_NEAR(model.NoiseSigma(4.0, 0.0), std::hypot(0.003, 0.008), 1e-12);
  // At 60 deg: the footprint (4 m x divergence) spans tan(60) of its width in depth.
  const double footprint = 0.5 * 4.0 * div * std::tan(60 * kDeg);
  EXPECT_NEAR(model.NoiseSigma(4.0, 60 * kDeg),
              std::sqrt(0.003 * 0.003 + 0.008 * 0.008 + footprint * footprint), 1e-12);
  // Beyond incidence_noise_max_deg (75 by default) the footprint term holds its value there.
  EXPECT_DOUBLE_EQ(model.NoiseSigma(4.0, 89 * kDeg), model.NoiseSigma(4.0, 75 * kDeg));
  EXPECT_GT(model.NoiseSigma(4.0, 75 * kDeg), model.NoiseSigma(4.0, 70 * kDeg));
  c.incidence_noise_max_deg = 85.0;
  const Lms200Model to_85(c);
  const double at_85 = 0.5 * 4.0 * div * std::tan(85 * kDeg);
  EXPECT_NEAR(to_85.NoiseSigma(4.0, 89 * kDeg),
              std::sqrt(0.003 * 0.003 + 0.008 * 0.008 + at_85 * at_85), 1e-12);
  // The ideal sensor has none.
  c.noise_sigma_m = 0.0;
  EXPECT_EQ(Lms200Model(c).NoiseSigma(4.0, 60 * kDeg), 0.0);
}

TEST(Lms200Realism, MeasuredNoiseGrowsWithRangeAndIncidenceAsTheFormulaSays) {
  Lms200Config c = NoiseOnly();
  c.noise_sigma_m = 0.003;
  c.noise_per_m = 0.002;
  c.incidence_noise_gain = 0.5;
  c.seed = 7;
  Lms200Model model(c);
  struct Case {
    double range_m, incidence_deg;
  };
  double last_sigma = 0;
  for (const Case& k :
       {Case{1.0, 0.0}, Case{4.0, 0.0}, Case{4.0, 45.0}, Case{4.0, 70.0}, Case{6.0, 70.0}}) {
    const Sample s = Measure(model, k.range_m, k.incidence_deg);
    // 1 mm quantization adds a uniform error of variance (1 mm)^2 / 12.
    const double expected =
        std::sqrt(std::pow(model.NoiseSigma(k.range_m, k.incidence_deg * kDeg), 2) + 1e-6 / 12);
    // 72,200 draws: the sample sigma's relative standard error is 1 / sqrt(2 n) = 0.26 %; 2 %
    // is 7 of them, the mean's standard error is 0.4 % of sigma, 3 % is 8 of them.
    EXPECT_NEAR(s.sigma, expected, 0.02 * expected) << k.range_m << " m, " << k.incidence_deg;
    EXPECT_NEAR(s.mean, 0.0, 0.03 * expected) << k.range_m << " m, " << k.incidence_deg;
    EXPECT_EQ(s.returned, 1.0);      // no dropouts configured
    EXPECT_GT(s.sigma, last_sigma);  // each case is noisier than the one before
    last_sigma = s.sigma;
  }
}

TEST(Lms200Realism, GrazingDropoutsFollowTheirRamp) {
  Lms200Config c = NoiseOnly();
  c.dropout_grazing_deg = 60.0;
  c.dropout_grazing_at_90 = 0.6;
  Lms200Model model(c);
  EXPECT_EQ(Measure(model, 3.0, 55.0).returned, 1.0);  // below the onset: none at all
  for (double incidence : {70.0, 80.0, 89.0}) {
    const double p = 0.6 * (incidence - 60.0) / 30.0;
    EXPECT_NEAR(model.DropoutProbability(3.0, incidence * kDeg), p, 1e-12);
    // Binomial over 72,200 readings: sigma <= 0.0019; 0.008 is over 4 of them.
    EXPECT_NEAR(Measure(model, 3.0, incidence).returned, 1.0 - p, 0.008) << incidence;
  }
}

TEST(Lms200Realism, FarDropoutsFollowTheirRamp) {
  Lms200Config c = NoiseOnly();
  c.dropout_far_m = 2.0;
  c.dropout_far_per_m = 0.05;
  Lms200Model model(c);
  EXPECT_EQ(Measure(model, 1.9, 0.0).returned, 1.0);
  EXPECT_NEAR(Measure(model, 6.0, 0.0).returned, 1.0 - 0.2, 0.008);  // 0.05 x 4 m
  // Ramps add, capped at certainty.
  c.dropout_grazing_deg = 0.0;
  c.dropout_grazing_at_90 = 1.0;
  EXPECT_DOUBLE_EQ(Lms200Model(c).DropoutProbability(6.0, 45 * kDeg), 0.5 + 0.2);
  EXPECT_DOUBLE_EQ(Lms200Model(c).DropoutProbability(8.0, 80 * kDeg), 1.0);
}

TEST(Lms200Realism, TheIdealSensorDropsNothing) {
  Lms200Config c = Lms200Config::Measured();
  c.noise_sigma_m = 0.0;
  c.dropout_far_per_m = 0.5;
  c.dropout_grazing_at_90 = 1.0;
  Lms200Model model(c);
  const Sample s = Measure(model, 6.0, 80.0);
  EXPECT_EQ(s.returned, 1.0);
  EXPECT_LT(s.sigma, 0.006);  // cm-mode quantization only
}

std::vector<LaserLine> Lines(const Lms200Config& c) {
  Lms200Model model(c);
  const auto n = static_cast<std::size_t>(model.readings());
  std::vector<float> truth(n), cosine(n);
  for (std::size_t i = 0; i < n; ++i) {
    truth[i] = static_cast<float>(1.0 + 0.05 * static_cast<double>(i));              // 1 .. 19 m
    cosine[i] = static_cast<float>(std::cos(0.25 * kDeg * static_cast<double>(i)));  // 0 .. 90
  }
  std::vector<LaserLine> lines(20);
  for (LaserLine& line : lines) model.Measure(truth.data(), nullptr, nullptr, line, cosine.data());
  return lines;
}

bool SameBytes(const std::vector<LaserLine>& a, const std::vector<LaserLine>& b) {
  for (std::size_t k = 0; k < a.size(); ++k) {
    const auto n = a[k].ranges_m.size();
    if (std::memcmp(a[k].ranges_m.data(), b[k].ranges_m.data(), n * sizeof(float)) != 0 ||
        a[k].status != b[k].status) {
      return false;
    }
  }
  return true;
}

TEST(Lms200Realism, TheSameSeedGivesTheSameBytesAnotherSeedOthers) {
  Lms200Config c = Lms200Config::Measured();
  c.dropout_grazing_at_90 = 0.3;
  c.seed = 42;
  EXPECT_TRUE(SameBytes(Lines(c), Lines(c)));
  Lms200Config other = c;
  other.seed = 43;
  EXPECT_FALSE(SameBytes(Lines(c), Lines(other)));
}

TEST(Lms200Realism, DropoutsRemoveReadingsWithoutChangingTheOthersNoise) {
  Lms200Config without = NoiseOnly();
  without.range_mode = Lms200RangeMode::kCm;  // Lines() reaches 19 m
  Lms200Config with = without;
  with.dropout_far_m = 1.0;
  with.dropout_far_per_m = 0.02;
  const std::vector<LaserLine> a = Lines(with), b = Lines(without);
  int dropped = 0, kept = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    for (std::size_t i = 0; i < a[k].ranges_m.size(); ++i) {
      ASSERT_EQ(b[k].status[i], ReadingStatus::kValid);
      if (a[k].status[i] != ReadingStatus::kValid) {
        ++dropped;
        continue;
      }
      ++kept;
      ASSERT_EQ(a[k].ranges_m[i], b[k].ranges_m[i]) << "line " << k << " beam " << i;
    }
  }
  EXPECT_GT(dropped, 0);
  EXPECT_GT(kept, dropped);
}

TEST(Lms200Realism, TheMountErrorDrawIsNormalPerAxisAndFixedBySeed) {
  Lms200Config c = Lms200Config::Measured();
  c.mount_error_sigma_deg = 0.5;
  const int n = 4000;
  double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
  for (int s = 0; s < n; ++s) {
    c.seed = static_cast<std::uint64_t>(s);
    const std::array<double, 3> e = DrawMountErrorRpyRad(c);
    for (int a = 0; a < 3; ++a) {
      sum[a] += e[a];
      sum2[a] += e[a] * e[a];
    }
  }
  const double sigma = 0.5 * kDeg;
  for (int a = 0; a < 3; ++a) {
    const double mean = sum[a] / n, sd = std::sqrt(sum2[a] / n - mean * mean);
    EXPECT_NEAR(mean, 0.0, 4 * sigma / std::sqrt(n)) << "axis " << a;
    // Relative standard error of a sample sigma over 4000 draws: 1.1 %; 5 % is 4.5 of them.
    EXPECT_NEAR(sd, sigma, 0.05 * sigma) << "axis " << a;
  }
  c.seed = 9;
  EXPECT_EQ(DrawMountErrorRpyRad(c), DrawMountErrorRpyRad(c));
  c.mount_error_sigma_deg = 0.0;
  EXPECT_EQ(DrawMountErrorRpyRad(c), (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(Lms200Realism, LegacyIsTheConstantNoiseModel) {
  const Lms200Config legacy = Lms200Config::Legacy();
  const Lms200Model model(legacy);
  EXPECT_DOUBLE_EQ(model.NoiseSigma(20.0, 80 * kDeg), 0.005);
  EXPECT_DOUBLE_EQ(model.DropoutProbability(30.0, 89 * kDeg), 0.0);
  EXPECT_FALSE(legacy.mixed_pixels);
  EXPECT_EQ(DrawMountErrorRpyRad(legacy), (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(Lms200Realism, RejectsOutOfRangeSettingsNamingTheField) {
  auto message = [](void (*set)(Lms200Config&)) -> std::string {
    Lms200Config c = Lms200Config::Measured();
    set(c);
    try {
      c.Validate();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message([](Lms200Config& c) { c.noise_per_m = -0.001; }).find("noise_per_m"),
            std::string::npos);
  EXPECT_NE(
      message([](Lms200Config& c) { c.incidence_noise_gain = NAN; }).find("incidence_noise_gain"),
      std::string::npos);
  EXPECT_NE(message([](Lms200Config& c) {
              c.incidence_noise_max_deg = 90;
            }).find("incidence_noise_max_deg"),
            std::string::npos);
  EXPECT_NE(
      message([](Lms200Config& c) { c.dropout_grazing_deg = 90; }).find("dropout_grazing_deg"),
      std::string::npos);
  EXPECT_NE(
      message([](Lms200Config& c) { c.dropout_grazing_at_90 = 1.5; }).find("dropout_grazing_at_90"),
      std::string::npos);
  EXPECT_NE(message([](Lms200Config& c) { c.dropout_far_m = -1; }).find("dropout_far_m"),
            std::string::npos);
  EXPECT_NE(message([](Lms200Config& c) { c.dropout_far_per_m = 2; }).find("dropout_far_per_m"),
            std::string::npos);
  EXPECT_NE(
      message([](Lms200Config& c) { c.mount_error_sigma_deg = 12; }).find("mount_error_sigma_deg"),
      std::string::npos);
  EXPECT_EQ(message([](Lms200Config&) {}), "");  // the defaults are valid
}

}  // namespace
}  // namespace pitchlab::sensors
