// LazyNormals (internal to mapping): each normal made when asked for is EstimateNormals' bit for
// bit, only the ones asked for are made, and asking again makes nothing.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fast_pipeline.hpp"

namespace pitchlab::mapping {
namespace {

TEST(LazyNormals, MakesWhatItIsAskedForAsEstimateNormalsDoes) {
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  PointCloud cloud;
  for (int k = 0; k < 4000; ++k) {
    const float a = u(rng), b = u(rng);
    if (k % 2) {
      cloud.emplace_back(a, b, 0.2f * a + noise(rng));  // a slope
    } else {
      cloud.emplace_back(a, noise(rng), b);  // a wall
    }
  }
  cloud.emplace_back(40, 40, 40);  // alone: too few neighbours, a NaN normal
  const VoxelHashIndex index(cloud, 0.3);
  const Eigen::Vector3f viewpoint(2, 3, 1.5);
  const Normals all = EstimateNormals(cloud, index, 0.3f, viewpoint);
  const LazyNormals lazy(cloud, index, 0.3f, viewpoint);
  EXPECT_EQ(lazy.made(), 0u);

  std::vector<int> asked = {-1, 7, 7, 4000, 3, -1};
  for (int i = 100; i < 3000; i += 7) asked.push_back(i);
  lazy.Make(asked);
  const std::size_t distinct = asked.size() - 3;  // two -1s and a repeated 7
  EXPECT_EQ(lazy.made(), distinct);
  for (const int i : asked) {
    if (i < 0) continue;
    if (std::isnan(all[i].x())) {
      EXPECT_TRUE(std::isnan(lazy[i].x())) << i;
    } else {
      EXPECT_EQ(lazy[i], all[i]) << i;  // bit for bit
    }
  }
  EXPECT_TRUE(std::isnan(lazy[4000].x()));
  lazy.Make(asked);  // all made already
  EXPECT_EQ(lazy.made(), distinct);
}

}  // namespace
}  // namespace pitchlab::mapping
