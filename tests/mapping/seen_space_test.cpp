// SeenSpace (mapping/src): free-space violations against a scan of known, flat geometry.

#include "seen_space.hpp"

#include <gtest/gtest.h>

namespace pitchlab::mapping {
namespace {

constexpr double kBin_deg = 1.0;

// Two walls seen from the origin: x = +5 and x = -5 (behind the sensor: azimuth wraps there), each
// y in [-3, 3], z in [-1, 2], every 2 cm (a 1 deg bin at 5 m is 8.7 cm wide).
PointCloud TwoWalls() {
  PointCloud out;
  for (const float x : {5.0f, -5.0f}) {
    for (float y = -3.0f; y <= 3.0f; y += 0.02f) {
      for (float z = -1.0f; z <= 2.0f; z += 0.02f) out.emplace_back(x, y, z);
    }
  }
  return out;
}

int ViolationsOf(const SeenSpace& seen, const Eigen::Vector3f& p) {
  return seen.Violations({p}, Eigen::Isometry3d::Identity());
}

TEST(SeenSpace, APointInFrontOfTheWallLiesInSpaceTheScanSawThrough) {
  const SeenSpace seen(TwoWalls(), Eigen::Vector3f::Zero(), kBin_deg);
  EXPECT_EQ(ViolationsOf(seen, {3.0f, 0.0f, 0.5f}), 1);
  EXPECT_EQ(ViolationsOf(seen, {3.0f, 1.0f, -0.4f}), 1);
  EXPECT_EQ(ViolationsOf(seen, {-3.0f, 0.0f, 0.5f}), 1);  // azimuth 180 deg: the bins wrap
  EXPECT_EQ(ViolationsOf(seen, {-3.0f, -0.01f, 0.5f}), 1);
}

TEST(SeenSpace, OnTheWallBehindItOrWithinTheMarginIsNoViolation) {
  const SeenSpace seen(TwoWalls(), Eigen::Vector3f::Zero(), kBin_deg);
  EXPECT_EQ(ViolationsOf(seen, {5.0f, 0.0f, 0.5f}), 0);  // on the wall
  EXPECT_EQ(ViolationsOf(seen, {7.0f, 0.0f, 0.5f}), 0);  // occluded by it
  // Within the default margin_m + margin_fraction x range (0.1 + 0.03 x 4.8 m) of the wall.
  EXPECT_EQ(ViolationsOf(seen, {4.8f, 0.0f, 0.5f}), 0);
  EXPECT_EQ(ViolationsOf(seen, {4.7f, 0.0f, 0.5f}), 1);
}

TEST(SeenSpace, WhereTheScanSawNothingOrTooNearItSaysNothing) {
  const SeenSpace seen(TwoWalls(), Eigen::Vector3f::Zero(), kBin_deg);
  EXPECT_EQ(ViolationsOf(seen, {0.0f, 3.0f, 0.5f}), 0);  // to the side: no return there
  EXPECT_EQ(ViolationsOf(seen, {3.0f, 0.0f, 3.0f}), 0);  // above the wall
  // Towards the wall's top edge: the bin has a return, the one above does not.
  EXPECT_EQ(ViolationsOf(seen, {2.5f, 0.0f, 0.995f}), 0);
  EXPECT_EQ(ViolationsOf(seen, {2.5f, 0.0f, 0.9f}), 1);
  EXPECT_EQ(ViolationsOf(seen, {1.2f, 0.0f, 0.1f}), 0);  // nearer than the default min_range_m
  EXPECT_EQ(ViolationsOf(seen, {0.0f, 0.0f, 0.0f}), 0);  // the sensor itself
}

TEST(SeenSpace, CountsThePointsAPosePutsInFrontOfTheWall) {
  const SeenSpace seen(TwoWalls(), Eigen::Vector3f::Zero(), kBin_deg);
  // A patch of wall seen from elsewhere: where it belongs it violates nothing; moved 1 m towards
  // the sensor every point does; moved 1 m along the wall (a flat direction) none does.
  PointCloud patch;
  for (float y = -0.5f; y <= 0.5f; y += 0.1f) {
    for (float z = 0.0f; z <= 1.0f; z += 0.1f) patch.emplace_back(0.0f, y, z);
  }
  const auto at = [](double x, double y) {
    return Eigen::Isometry3d(Eigen::Translation3d(x, y, 0.0));
  };
  EXPECT_EQ(seen.Violations(patch, at(5.0, 0.0)), 0);
  EXPECT_EQ(seen.Violations(patch, at(4.0, 0.0)), static_cast<int>(patch.size()));
  EXPECT_EQ(seen.Violations(patch, at(5.0, 1.0)), 0);
}

TEST(SeenSpace, TheSensorNeedNotBeAtTheOrigin) {
  // The same walls seen from 0.55 m up: a point 2 m in front of the wall violates, measured from
  // there.
  PointCloud walls = TwoWalls();
  const Eigen::Vector3f sensor(0.1f, 0.0f, 0.55f);
  const SeenSpace seen(walls, sensor, kBin_deg);
  EXPECT_EQ(ViolationsOf(seen, {3.0f, 0.0f, 0.55f}), 1);
  EXPECT_EQ(ViolationsOf(seen, {5.0f, 0.0f, 0.55f}), 0);
}

}  // namespace
}  // namespace pitchlab::mapping
