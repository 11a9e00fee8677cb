// VoxelHashIndex (internal to mapping) against a brute-force search over every point: the same
// neighbours in the same order, the same nearest point, ties included.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "voxel_hash.hpp"

namespace pitchlab::mapping {
namespace {

// The index's order: by cell key, then by the point's index in the cloud.
std::vector<int> CellOrder(const PointCloud& cloud, float cell) {
  std::vector<std::pair<std::uint64_t, int>> keyed;
  for (int i = 0; i < static_cast<int>(cloud.size()); ++i) {
    keyed.emplace_back(CellKey(cloud[i], 1.0f / cell), i);
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> order;
  for (const auto& [key, i] : keyed) order.push_back(i);
  return order;
}

std::vector<int> BruteRadius(const PointCloud& cloud, const std::vector<int>& order,
                             const Eigen::Vector3f& q, float r) {
  std::vector<int> out;
  for (int i : order) {
    if ((cloud[i] - q).squaredNorm() <= r * r) out.push_back(i);
  }
  return out;
}

std::pair<int, float> BruteNearest(const PointCloud& cloud, const std::vector<int>& order,
                                   const Eigen::Vector3f& q, float max_m) {
  int best = -1;
  float d2 = max_m * max_m;
  for (int i : order) {
    const float d = (cloud[i] - q).squaredNorm();
    if (d < d2) {
      d2 = d;
      best = i;
    }
  }
  return {best, d2};
}

// Points on a quarter-cell lattice (many exactly on cell faces and equally far from a query,
// some repeated) around `centre`, plus scattered ones.
PointCloud LatticeCloud(const Eigen::Vector3f& centre, float cell, std::mt19937& rng) {
  std::uniform_int_distribution<int> step(-12, 12);
  std::uniform_real_distribution<float> u(-3 * cell, 3 * cell);
  PointCloud cloud;
  for (int i = 0; i < 1500; ++i) {
    cloud.push_back(centre + 0.25f * cell * Eigen::Vector3f(step(rng), step(rng), step(rng)));
  }
  for (int i = 0; i < 1500; ++i) cloud.push_back(centre + Eigen::Vector3f(u(rng), u(rng), u(rng)));
  return cloud;
}

TEST(VoxelHashIndex, FindsWhatASearchOfEveryPointFinds) {
  std::mt19937 rng(7);
  for (const auto& [centre, cell] :
       {std::tuple{Eigen::Vector3f(0, 0, 0), 0.1f}, std::tuple{Eigen::Vector3f(23.4f, -7.7f, 1.2f), 0.2f},
        std::tuple{Eigen::Vector3f(-0.3f, 0.05f, -0.01f), 0.004f}}) {
    const PointCloud cloud = LatticeCloud(centre, cell, rng);
    const VoxelHashIndex index(cloud, cell);
    const std::vector<int> order = CellOrder(cloud, cell);
    std::uniform_int_distribution<int> step(-12, 12);
    std::uniform_real_distribution<float> u(-3 * cell, 3 * cell);
    int found = 0;
    for (int k = 0; k < 2000; ++k) {
      const Eigen::Vector3f q =
          k % 2 ? Eigen::Vector3f(centre + 0.25f * cell * Eigen::Vector3f(step(rng), step(rng), step(rng)))
                : Eigen::Vector3f(centre + Eigen::Vector3f(u(rng), u(rng), u(rng)));
      for (const float r : {cell, 0.5f * cell, 0.26f * cell}) {
        std::vector<int> got;
        index.Radius(q, r, got);
        ASSERT_EQ(got, BruteRadius(cloud, order, q, r)) << "query " << q.transpose() << " r " << r;
        std::vector<Eigen::Vector3f> points;  // RadiusPoints: the same points, the same order
        index.RadiusPoints(q, r, points);
        ASSERT_EQ(points.size(), got.size());
        for (std::size_t n = 0; n < got.size(); ++n) ASSERT_EQ(points[n], cloud[got[n]]);
        float d2 = -1;
        const int nearest = index.Nearest(q, r, d2);
        const auto [want, want_d2] = BruteNearest(cloud, order, q, r);
        ASSERT_EQ(nearest, want) << "query " << q.transpose() << " r " << r;
        if (want >= 0) {
          EXPECT_EQ(d2, want_d2);
          ++found;
        }
      }
    }
    EXPECT_GT(found, 1000);  // the queries do land near points
  }
}

TEST(VoxelHashIndex, AnEmptyCloudFindsNothing) {
  const VoxelHashIndex index(PointCloud{}, 0.1);
  std::vector<int> got;
  index.Radius(Eigen::Vector3f::Zero(), 0.1f, got);
  EXPECT_TRUE(got.empty());
  float d2 = 0;
  EXPECT_EQ(index.Nearest(Eigen::Vector3f::Zero(), 0.1f, d2), -1);
}

}  // namespace
}  // namespace pitchlab::mapping
