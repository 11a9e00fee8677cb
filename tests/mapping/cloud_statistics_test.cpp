// MeasureCloud on clouds of known spacing and noise, and RegistrationConfig::Resolve on what it
// measures.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pitchlab/mapping/cloud_statistics.hpp"
#include "pitchlab/mapping/registration_config.hpp"

namespace pitchlab::mapping {
namespace {

// A floor 2 m below the sensor, sampled on a square grid of `spacing_m`, heights with Gaussian
// noise `sigma_m`: the plane-fit residual is that noise, the nearest neighbour that spacing.
PointCloud NoisyFloor(double spacing_m, double sigma_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  PointCloud out;
  const int n = static_cast<int>(std::lround(6.0 / spacing_m));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      out.emplace_back(-3 + i * spacing_m, -3 + j * spacing_m,
                       -2.0 + (sigma_m > 0 ? noise(rng) : 0.0));
  return out;
}

TEST(MeasureCloud, ANoisyFloorMeasuresItsSpacingNoiseAndRange) {
  const CloudStatistics s = MeasureCloud(NoisyFloor(0.02, 0.003, 1), Eigen::Vector3f::Zero());
  EXPECT_EQ(s.points, 301u * 301u);
  EXPECT_NEAR(s.spacing_m, 0.02, 0.002);
  // 32 points fit their own plane: three of their degrees of freedom go to it (sqrt(29/32)).
  EXPECT_NEAR(s.noise_m, 0.003 * std::sqrt(29.0 / 32.0), 0.0004);
  // Median distance from a sensor 2 m above a 6 x 6 m floor: half its area lies within
  // r = sqrt(18 / pi) = 2.39 m of the point under the sensor.
  EXPECT_NEAR(s.median_range_m, std::hypot(2.0, std::sqrt(18.0 / 3.14159265358979)), 0.02);
  EXPECT_GT(s.noise_samples, 900u);
}

TEST(MeasureCloud, EveryLengthScalesWithTheCloud) {
  const PointCloud floor = NoisyFloor(0.02, 0.003, 2);
  const CloudStatistics one = MeasureCloud(floor, Eigen::Vector3f::Zero());
  for (const float k : {0.01f, 10.0f}) {
    PointCloud scaled = floor;
    for (Eigen::Vector3f& p : scaled) p *= k;
    const CloudStatistics s = MeasureCloud(scaled, Eigen::Vector3f::Zero());
    EXPECT_NEAR(s.spacing_m, k * one.spacing_m, 1e-3 * k * one.spacing_m);
    EXPECT_NEAR(s.noise_m, k * one.noise_m, 1e-3 * k * one.noise_m);
    EXPECT_NEAR(s.median_range_m, k * one.median_range_m, 1e-4 * k * one.median_range_m);
  }
}

TEST(MeasureCloud, TooFewOrNonFinitePointsSayNothing) {
  PointCloud few(10, Eigen::Vector3f(1, 2, 3));
  few.push_back(Eigen::Vector3f(NAN, 0, 0));
  const CloudStatistics s = MeasureCloud(few, Eigen::Vector3f::Zero());
  EXPECT_EQ(s.points, 10u);
  EXPECT_EQ(s.noise_m, 0.0);
  EXPECT_EQ(s.spacing_m, 0.0);
}

TEST(Resolve, LengthsFollowTheScaleAndGatesTheNoise) {
  CloudStatistics robot;  // what an LMS200 scan measures
  robot.median_range_m = 2.0;
  robot.noise_m = 0.0034;
  const RegistrationConfig defaults;
  const RegistrationConfig r = defaults.Resolve(robot, robot);
  EXPECT_DOUBLE_EQ(r.length_scale, 1.0);
  EXPECT_DOUBLE_EQ(r.icp_voxel_m, defaults.icp_voxel_m);
  EXPECT_DOUBLE_EQ(r.inlier_distance_m, r.icp_voxel_m);  // 3 sigma of 4.8 mm < 0.1 m
  EXPECT_DOUBLE_EQ(r.max_rmse_m, r.inlier_distance_m / std::sqrt(3.0));
  EXPECT_DOUBLE_EQ(r.free_space_margin_m, 0.1);

  CloudStatistics tiny = robot;  // the same scene a hundred times smaller
  tiny.median_range_m *= 0.01;
  tiny.noise_m *= 0.01;
  const RegistrationConfig t = defaults.Resolve(tiny, tiny);
  EXPECT_NEAR(t.length_scale, 0.01, 1e-12);
  EXPECT_NEAR(t.icp_voxel_m, 0.01 * defaults.icp_voxel_m, 1e-12);
  EXPECT_NEAR(t.constraint_translation_m, 0.01 * defaults.constraint_translation_m, 1e-12);
  EXPECT_NEAR(t.inlier_distance_m, 0.01 * r.inlier_distance_m, 1e-12);

  CloudStatistics noisy = robot;  // a noisy sensor close to a wall: the gates widen
  noisy.noise_m = 0.05;
  noisy.median_range_m = 0.5;
  const RegistrationConfig n = defaults.Resolve(noisy, robot);
  EXPECT_DOUBLE_EQ(n.length_scale, 1.0);  // sqrt(14.7 x 0.25) = 1.9: still the nearest decade
  EXPECT_NEAR(n.inlier_distance_m, 3 * std::hypot(0.05, 0.0034), 1e-12);

  RegistrationConfig fixed;  // a given gate is kept (times the scale)
  fixed.max_rmse_m = 0.02;
  EXPECT_NEAR(fixed.Resolve(tiny, tiny).max_rmse_m, 0.0002, 1e-12);

  CloudStatistics synthetic = robot;  // no noise: the range alone sets the scale
  synthetic.noise_m = 0;
  synthetic.median_range_m = 20.0;
  EXPECT_DOUBLE_EQ(defaults.Resolve(synthetic, synthetic).length_scale, 10.0);
}

TEST(Resolve, AutoReadsAndWritesAsAuto) {
  const RegistrationConfig c = ParseRegistrationConfig(
      "registration: {length_scale: auto, max_rmse_m: 0.04, inlier_distance_m: auto}\n", "t");
  EXPECT_TRUE(std::isnan(c.length_scale));
  EXPECT_DOUBLE_EQ(c.max_rmse_m, 0.04);
  EXPECT_TRUE(std::isnan(c.inlier_distance_m));
  const RegistrationConfig back = ParseRegistrationConfig(RegistrationConfigToYaml(c), "back");
  EXPECT_TRUE(std::isnan(back.length_scale));
  EXPECT_DOUBLE_EQ(back.max_rmse_m, 0.04);
  EXPECT_THROW(ParseRegistrationConfig("registration: {icp_voxel_m: auto}\n", "t"),
               std::invalid_argument);
  EXPECT_THROW(ParseRegistrationConfig("registration: {length_scale: -1}\n", "t"),
               std::invalid_argument);
}

// A 2 x 2 m floor at 1 cm spacing against itself moved up: every point is within 5 cm at a 3 cm
// lift and none at 6 cm; points beyond reach count against it, NaN points never count.
TEST(ShareWithin, CountsTheSourcePointsTheTransformPutsNearTheTarget) {
  PointCloud floor;
  for (int i = 0; i < 200; ++i) {
    for (int j = 0; j < 200; ++j) floor.emplace_back(0.01f * i, 0.01f * j, 0.0f);
  }
  const auto lift = [](double z) {
    return Eigen::Isometry3d(Eigen::Translation3d(0, 0, z));
  };
  EXPECT_DOUBLE_EQ(ShareWithin(floor, floor, lift(0.03), 0.05), 1.0);
  EXPECT_DOUBLE_EQ(ShareWithin(floor, floor, lift(0.06), 0.05), 0.0);
  PointCloud half = floor;
  for (Eigen::Vector3f& p : half) p.x() += 1.0f;  // x 1-2.99 m against 0-1.99 m
  EXPECT_NEAR(ShareWithin(floor, half, lift(0.0), 0.05), 105.0 / 200, 1e-9);  // x <= 2.04 m
  PointCloud with_nan = {floor[0], Eigen::Vector3f::Constant(NAN)};
  EXPECT_DOUBLE_EQ(ShareWithin(floor, with_nan, lift(0.0), 0.05), 0.5);
  EXPECT_DOUBLE_EQ(ShareWithin(floor, {}, lift(0.0), 0.05), 0.0);
}

}  // namespace
}  // namespace pitchlab::mapping
