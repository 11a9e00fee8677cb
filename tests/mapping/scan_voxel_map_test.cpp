// ScanVoxelMap (the merged map cloud): re-posed, it is the map built from scratch with the scans
// at the new poses, point for point.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mapping/scan_voxel_map.hpp"

namespace pitchlab::mapping {
namespace {

// Random points in a 6 x 6 x 2 m box around base_link.
PointCloud RandomScan(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  PointCloud cloud;
  for (int i = 0; i < 3000; ++i) cloud.emplace_back(u(rng), u(rng), u(rng) / 3);
  return cloud;
}

PointCloud Sorted(PointCloud c) {
  std::sort(c.begin(), c.end(), [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  });
  return c;
}

TEST(ScanVoxelMap, ARePosedMapIsTheMapBuiltAtTheNewPosesPointForPoint) {
  ScanVoxelMap map(0.1, true);
  std::vector<Eigen::Isometry3d> moved;
  for (int k = 0; k < 4; ++k) {
    map.Add(RandomScan(k), PoseFromXyzRpyDeg(0.5 * k, 0, 0, 0, 0, 10 * k));
    moved.push_back(PoseFromXyzRpyDeg(0.5 * k + 0.03, 0.02 * k, 0, 0, 0, 10 * k + 0.5));
  }
  const PointCloud before = Sorted(map.Cloud());
  ASSERT_TRUE(map.Repose(moved));
  ScanVoxelMap scratch(0.1, false);
  for (int k = 0; k < 4; ++k) scratch.Add(RandomScan(k), moved[k]);
  const PointCloud after = Sorted(map.Cloud());
  EXPECT_EQ(after, Sorted(scratch.Cloud()));
  EXPECT_NE(after, before);  // the poses moved the map
}

TEST(ScanVoxelMap, RePosingWithoutKeptScansOrWithTheWrongNumberOfPosesIsAnError) {
  ScanVoxelMap kept(0.1, true), not_kept(0.1, false);
  kept.Add(RandomScan(1), Eigen::Isometry3d::Identity());
  not_kept.Add(RandomScan(1), Eigen::Isometry3d::Identity());
  const PointCloud before = Sorted(kept.Cloud());
  Result<void> wrong = kept.Repose({Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity()});
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().message.find("2 poses for 1 scans"), std::string::npos)
      << wrong.error().message;
  EXPECT_EQ(Sorted(kept.Cloud()), before);
  EXPECT_FALSE(not_kept.Repose({Eigen::Isometry3d::Identity()}));
  EXPECT_THROW(ScanVoxelMap(0.0, true), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mapping
