#include "pitchlab/sensors/sensor_config.hpp"

#include <gtest/gtest.h>

namespace pitchlab::sensors {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

TEST(SensorConfig, EmptyDocumentGivesTheSeedDefaults) {
  const SensorConfig c = ParseSensorConfig("", "test.yaml");
  EXPECT_EQ(c.lms200.fov_deg, 180.0);
  EXPECT_EQ(c.lms200.resolution_deg, 0.5);
  EXPECT_EQ(c.scan.lines, 200);
  EXPECT_EQ(c.scan.pitch_end_deg - c.scan.pitch_start_deg, 100.0);
}

TEST(SensorConfig, ReadsEverySectionInUserUnits) {
  const SensorConfig c = ParseSensorConfig(R"(
lms200: {fov_deg: 100, resolution_deg: 0.25, range_mode: mm, noise_sigma_m: 0, baud: 38400}
pitch_unit: {step_deg: 0.9}
scan: {pitch_start_deg: -10, pitch_end_deg: 30, lines: 50}
mount: {t_base_mount_m: [0.2, 0, 0.5], misalignment_rpy_deg: [0, 0.5, 0]}
robot: {model: p3dx}   # another module's section: left alone
)",
                                           "test.yaml");
  EXPECT_EQ(c.lms200.range_mode, Lms200RangeMode::kMm);
  EXPECT_EQ(c.lms200.baud, 38400);
  EXPECT_EQ(c.pitch_unit.step_deg, 0.9);
  EXPECT_EQ(c.scan.lines, 50);
  EXPECT_DOUBLE_EQ(c.mount.t_base_mount_m.x(), 0.2);
  EXPECT_NEAR(c.mount.misalignment_rpy_rad.y(), 0.5 * kDeg, 1e-15);
}

TEST(SensorConfig, ErrorsNameTheFileTheFieldAndTheValue) {
  auto message = [](const char* yaml) {
    try {
      ParseSensorConfig(yaml, "my.yaml");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("lms200: {fov_deg: 270}").find("my.yaml: lms200.fov_deg = 270"),
            std::string::npos);
  EXPECT_NE(message("lms200: {fov: 180}").find("lms200.fov is not a known setting"),
            std::string::npos);
  EXPECT_NE(message("scan: {lines: many}").find("scan.lines has the wrong type ('many')"),
            std::string::npos);
  EXPECT_NE(message("lms200: {range_mode: km}").find("lms200.range_mode"), std::string::npos);
  EXPECT_NE(message("[1, 2").find("not valid YAML"), std::string::npos);
}

TEST(SensorConfig, WrittenYamlReadsBackTheSame) {
  SensorConfig c;
  c.lms200.seed = 1234567890123ULL;
  c.lms200.range_mode = Lms200RangeMode::kMm;
  c.mount.misalignment_rpy_rad = {0.001, -0.002, 0.003};
  const SensorConfig back = ParseSensorConfig(SensorConfigToYaml(c), "roundtrip");
  EXPECT_EQ(back.lms200.seed, c.lms200.seed);
  EXPECT_EQ(back.lms200.range_mode, c.lms200.range_mode);
  EXPECT_TRUE(back.mount.misalignment_rpy_rad.isApprox(c.mount.misalignment_rpy_rad, 1e-14));
  EXPECT_EQ(SensorConfigToYaml(back), SensorConfigToYaml(c));
}

TEST(SensorConfig, TheRealismKeysReadBackAndAreChecked) {
  const SensorConfig c = ParseSensorConfig(
      "lms200:\n  noise_per_m: 0.003\n  incidence_noise_gain: 0.7\n"
      "  incidence_noise_max_deg: 80\n  dropout_grazing_deg: 70\n  dropout_grazing_at_90: 0.2\n  "
      "dropout_far_m: 5\n"
      "  dropout_far_per_m: 0.004\n  mount_error_sigma_deg: 1.5\n",
      "realism.yaml");
  EXPECT_DOUBLE_EQ(c.lms200.noise_per_m, 0.003);
  EXPECT_DOUBLE_EQ(c.lms200.incidence_noise_gain, 0.7);
  EXPECT_DOUBLE_EQ(c.lms200.incidence_noise_max_deg, 80.0);
  EXPECT_DOUBLE_EQ(c.lms200.dropout_grazing_deg, 70.0);
  EXPECT_DOUBLE_EQ(c.lms200.dropout_grazing_at_90, 0.2);
  EXPECT_DOUBLE_EQ(c.lms200.dropout_far_m, 5.0);
  EXPECT_DOUBLE_EQ(c.lms200.dropout_far_per_m, 0.004);
  EXPECT_DOUBLE_EQ(c.lms200.mount_error_sigma_deg, 1.5);
  const SensorConfig back = ParseSensorConfig(SensorConfigToYaml(c), "roundtrip");
  EXPECT_EQ(SensorConfigToYaml(back), SensorConfigToYaml(c));
  EXPECT_DOUBLE_EQ(back.lms200.mount_error_sigma_deg, 1.5);
  auto message = [](const std::string& yaml) {
    try {
      ParseSensorConfig(yaml, "bad.yaml");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  for (const char* bad : {"noise_per_m: -1", "incidence_noise_gain: 11", "dropout_grazing_deg: 95",
                          "dropout_grazing_at_90: 2", "dropout_far_m: -3", "dropout_far_per_m: 1.5",
                          "mount_error_sigma_deg: 20"}) {
    const std::string text = std::string("lms200: {") + bad + "}";
    const std::string key = std::string(bad).substr(0, std::string(bad).find(':'));
    const std::string m = message(text);
    EXPECT_NE(m.find("bad.yaml"), std::string::npos) << bad << ": " << m;
    EXPECT_NE(m.find("lms200." + key), std::string::npos) << bad << ": " << m;
  }
  EXPECT_NE(message("lms200: {mount_error_sigma_deg: lots}").find("wrong type"), std::string::npos);
}

std::string ConfigError(const char* yaml) {
  try {
    ParseSensorConfig(yaml, "my.yaml");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(SensorConfig, AKeyGivenTwiceIsAnErrorNamingBothLines) {
  EXPECT_NE(ConfigError("lms200:\n  noise_sigma_m: 0.01\n  noise_sigma_m: 0.02\n")
                .find("my.yaml: lms200.noise_sigma_m is given twice (lines 2 and 3)"),
            std::string::npos)
      << ConfigError("lms200:\n  noise_sigma_m: 0.01\n  noise_sigma_m: 0.02\n");
  // In another module's section too: every config is read through here first.
  EXPECT_NE(ConfigError("seed: 1\nrun: {max_stops: 3}\nseed: 2\n").find("seed is given twice"),
            std::string::npos);
  EXPECT_NE(ConfigError("run: {weights: {a: 1, a: 2}}").find("run.weights.a is given twice"),
            std::string::npos);
}

TEST(SensorConfig, AnAbsurdRangeNoiseIsAnError) {
  EXPECT_NE(ConfigError("lms200: {noise_sigma_m: 1e9}").find("lms200.noise_sigma_m = 1e+09"),
            std::string::npos)
      << ConfigError("lms200: {noise_sigma_m: 1e9}");
  EXPECT_EQ(ConfigError("lms200: {noise_sigma_m: 0.02}"), "no error");
}

}  // namespace
}  // namespace pitchlab::sensors
