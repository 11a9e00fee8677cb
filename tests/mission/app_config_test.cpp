#include "pitchlab/mission/app_config.hpp"

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "scoped_temp_dir.hpp"

namespace pitchlab::mission {
namespace {

// LoadAppConfig reads files: one in a temporary folder of its own, removed after.
class ConfigFile {
 public:
  explicit ConfigFile(const std::string& text) : path_((dir_ / "app_config.yaml").string()) {
    std::ofstream(path_) << text;
  }
  const std::string& path() const { return path_; }

 private:
  test_support::ScopedTempDir dir_{"app_config"};  // before path_: made first
  std::string path_;
};

TEST(AppConfig, TheImuDeskewsByDefaultAndFollowsTheRunSeed) {
  const ConfigFile file("seed: 42\n");
  const AppConfig c = LoadAppConfig(file.path());
  EXPECT_TRUE(c.rig.imu.deskew);
  EXPECT_EQ(c.rig.imu.seed, 42u);
}

TEST(AppConfig, TheImuSectionIsReadAndWrittenBackAsUsed) {
  const ConfigFile file(
      "imu: {deskew: false, deskew_min_deg: 0.5, gyro_bias_dps: 0.02, gyro_noise_dps_rthz: "
      "0.05}\n");
  const AppConfig c = LoadAppConfig(file.path());
  EXPECT_FALSE(c.rig.imu.deskew);
  EXPECT_DOUBLE_EQ(c.rig.imu.deskew_min_deg, 0.5);
  EXPECT_DOUBLE_EQ(c.rig.imu.gyro_bias_dps, 0.02);
  EXPECT_DOUBLE_EQ(c.rig.imu.gyro_noise_dps_rthz, 0.05);
  const ConfigFile used(AppConfigToYaml(c));
  const AppConfig back = LoadAppConfig(used.path());
  EXPECT_FALSE(back.rig.imu.deskew);
  EXPECT_DOUBLE_EQ(back.rig.imu.deskew_min_deg, 0.5);
  EXPECT_DOUBLE_EQ(back.rig.imu.gyro_bias_dps, 0.02);
  EXPECT_DOUBLE_EQ(back.rig.imu.gyro_noise_dps_rthz, 0.05);
}

TEST(AppConfig, ABadImuSettingNamesTheFieldAndValue) {
  const auto message = [](const std::string& text) {
    const ConfigFile file(text);
    try {
      (void)LoadAppConfig(file.path());
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("imu: {deskw: true}\n").find("imu.deskw is not a known setting"),
            std::string::npos);
  EXPECT_NE(message("imu: {deskew: maybe}\n").find("imu.deskew must be true or false"),
            std::string::npos);
  EXPECT_NE(message("imu: {gyro_bias_dps: -1}\n").find("imu.gyro_bias_dps = -1 is invalid"),
            std::string::npos);
}

}  // namespace
}  // namespace pitchlab::mission
