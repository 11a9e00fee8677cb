// FitHeightOffset against known offsets: a map of rough ground, the same ground seen again shifted
// up, plus clutter the map never saw.

#include "pitchlab/mission/height_fit.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

double Ground(double x, double y) { return 0.3 * std::sin(0.7 * x) + 0.2 * std::cos(0.5 * y); }

mapping::ElevationMap GroundMap() {
  mapping::ElevationMap map(mapping::GridGeometry::FromArea(-10, -10, 20, 20, 0.1));
  std::vector<Eigen::Vector3f> pts;
  for (double x = -9.98; x < 10; x += 0.04)
    for (double y = -9.98; y < 10; y += 0.04) pts.emplace_back(x, y, Ground(x, y));
  (void)map.InsertPoints(pts.data(), pts.size());
  return map;
}

TEST(HeightFit, RecoversTheShiftOfTheSameGroundDespiteClutter) {
  const mapping::ElevationMap map = GroundMap();
  const double dz = 0.42;  // odometry's height 0.42 m off
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Eigen::Vector3f> scan;
  for (double x = -5; x < 7; x += 0.05)
    for (double y = -8; y < 4; y += 0.05) scan.emplace_back(x, y, Ground(x, y) + dz + noise(rng));
  for (double x = 2; x < 4; x += 0.05)  // a 1 m box on the ground the map does not hold
    for (double y = -1; y < 1; y += 0.05) scan.emplace_back(x, y, Ground(x, y) + dz + 1.0);
  const std::optional<HeightOffset> fit = FitHeightOffset(map, scan);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->dz_m, dz, 0.005);  // the box's 400 cells in the mean would add 2.8 cm
  EXPECT_GT(fit->cells, 5000);
  EXPECT_LE(fit->cells, 120 * 120 - 20 * 20);  // the box's cells are not among them
}

TEST(HeightFit, WallCellsDoNotSetTheOffsetWhereTheyOutnumberTheGround) {
  // A flat floor z = 0 with a wall along y = 1 (0.1 m thick, 2 m high) that the map saw from far:
  // a few wall points per cell. The stop stands a step from it and sees the wall densely and only
  // 40 cells of floor; its pose is 0.1 m too high. The wall cells' means differ between the two
  // views by how much of the face each saw, and they outnumber the floor's.
  mapping::ElevationMap map(mapping::GridGeometry::FromArea(-5, -5, 10, 10, 0.1));
  std::vector<Eigen::Vector3f> seen;
  for (double x = -4.98; x < 5; x += 0.04)
    for (double y = -4.98; y < 0.95; y += 0.04) seen.emplace_back(x, y, 0.0f);
  for (double x = -4.98; x < 5; x += 0.02)
    for (double z = 0.0; z <= 0.3; z += 0.1) seen.emplace_back(x, 0.97f, z);
  (void)map.InsertPoints(seen.data(), seen.size());
  const double dz = 0.1;
  std::vector<Eigen::Vector3f> scan;
  for (double x = -2; x < 2; x += 0.02)
    for (double z = 0.0; z <= 2.0; z += 0.02) scan.emplace_back(x, 0.97f, z + dz);
  for (double x = -1; x < 1; x += 0.04)
    for (double y = 0.51; y < 0.7; y += 0.04) scan.emplace_back(x, y, dz);
  const std::optional<HeightOffset> fit = FitHeightOffset(map, scan, 20);
  ASSERT_TRUE(fit);
  EXPECT_NEAR(fit->dz_m, dz, 1e-5);
  EXPECT_EQ(fit->cells, 40);  // the floor's 20 x 2 cells (without the rule: 80, the wall's too)
}

TEST(HeightFit, TooLittleOverlapFitsNothing) {
  const mapping::ElevationMap map = GroundMap();
  std::vector<Eigen::Vector3f> strip;
  for (double x = 0; x < 2; x += 0.05) strip.emplace_back(x, 0.05, Ground(x, 0.05) - 0.25);
  for (double x = 0; x < 2; x += 0.05) strip.emplace_back(x, 0.06, Ground(x, 0.06) - 0.25);
  for (double x = 0; x < 2; x += 0.05) strip.emplace_back(x, 0.07, Ground(x, 0.07) - 0.25);
  ASSERT_TRUE(FitHeightOffset(map, strip, 10));  // 20 cells of 6 points: enough for 10
  EXPECT_NEAR(FitHeightOffset(map, strip, 10)->dz_m, -0.25, 0.01);
  EXPECT_FALSE(FitHeightOffset(map, strip));  // not for the default 50
  const std::vector<Eigen::Vector3f> off_map = {{50, 50, 0}, {60, 60, 1}};
  EXPECT_FALSE(FitHeightOffset(map, off_map));
}

}  // namespace
}  // namespace pitchlab::mission
