// RegistrationConfig from YAML: defaults, every key readable, unknown keys and bad values named.

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration_config.hpp"

namespace pitchlab::mapping {
namespace {

std::string ErrorOf(const std::string& yaml) {
  try {
    ParseRegistrationConfig(yaml, "test.yaml");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(RegistrationConfig, DefaultsAreValid) { EXPECT_NO_THROW(RegistrationConfig{}.Validate()); }

TEST(RegistrationConfig, ReadsTheRegistrationSectionAndLeavesOthersAlone) {
  const RegistrationConfig c = ParseRegistrationConfig(
      "lms200: {fov_deg: 100}\n"
      "registration:\n  backend: pcl\n  features: narf\n  icp_voxel_m: 0.05\n"
      "  icp_max_iterations: 12\n  constant_velocity_fallback: false\n",
      "test.yaml");
  EXPECT_EQ(c.backend, RegistrationBackend::kPcl);
  EXPECT_EQ(c.features, FeatureKind::kNarf);
  EXPECT_DOUBLE_EQ(c.icp_voxel_m, 0.05);
  EXPECT_EQ(c.icp_max_iterations, 12);
  EXPECT_FALSE(c.constant_velocity_fallback);
}

TEST(RegistrationConfig, AnUnknownKeyIsAnErrorNamingIt) {
  EXPECT_EQ(ErrorOf("registration:\n  voxel_size: 0.1\n"),
            "test.yaml: registration.voxel_size is not a known setting");
}

// yaml-cpp answers the first of two equal keys: the second, the one a user appended, would be
// dropped without a word (issue 18).
TEST(RegistrationConfig, AKeyGivenTwiceIsAnErrorNamingBothLines) {
  EXPECT_EQ(ErrorOf("registration:\n  icp_voxel_m: 0.1\n  icp_voxel_m: 0.2\n"),
            "test.yaml: registration.icp_voxel_m is given twice (lines 2 and 3); keep one");
}

TEST(RegistrationConfig, AWrongTypeOrValueIsAnErrorNamingFieldAndValue) {
  EXPECT_EQ(ErrorOf("registration: {icp_max_iterations: lots}"),
            "test.yaml: registration.icp_max_iterations has the wrong type ('lots')");
  EXPECT_NE(ErrorOf("registration: {icp_voxel_m: -1}").find("registration.icp_voxel_m = -1"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {backend: gpu}").find("must be fast or pcl ('gpu')"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {narf_support_m: 0}").find("registration.narf_support_m = 0"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {sac_hypotheses: 0}").find("registration.sac_hypotheses = 0"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {guess_search_deg: 90}").find("must be in [0, 90)"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {carry_max_m: -0.1}").find("registration.carry_max_m = -0.1"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {guess_degeneracy_ratio: 1}").find("must be in [0, 1)"),
            std::string::npos);
  EXPECT_NE(ErrorOf("registration: {confined_scene_voxels: -1}")
                .find("registration.confined_scene_voxels = -1"),
            std::string::npos);
}

TEST(RegistrationConfig, YamlRoundTripGivesTheSameConfig) {
  RegistrationConfig c;
  c.backend = RegistrationBackend::kPcl;
  c.sac_iterations = 1234;
  c.max_rmse_m = 0.07;
  const RegistrationConfig back = ParseRegistrationConfig(RegistrationConfigToYaml(c), "rt");
  EXPECT_EQ(back.backend, c.backend);
  EXPECT_EQ(back.sac_iterations, 1234);
  EXPECT_DOUBLE_EQ(back.max_rmse_m, 0.07);
  EXPECT_EQ(RegistrationConfigToYaml(back), RegistrationConfigToYaml(c));
}

TEST(VoxelDownsample, KeepsOneCentroidPerVoxelAndDropsNonFinitePoints) {
  const PointCloud cloud = {{0.01f, 0.01f, 0.01f},
                            {0.03f, 0.03f, 0.03f},
                            {0.55f, 0.0f, 0.0f},
                            {std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f}};
  const PointCloud out = VoxelDownsample(cloud, 0.1);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out[0].x() + out[1].x(), 0.02 + 0.55, 1e-6);
}

}  // namespace
}  // namespace pitchlab::mapping
