// FPFH (internal to mapping) against pcl::computePairFeatures' definition spelt out plainly, with
// std::atan2 and both acos: the fast path's angle bins come from a polynomial bracket and call
// atan2 only near a bin's edge, and must give every bin atan2 itself gives.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fast_pipeline.hpp"

namespace pitchlab::mapping {
namespace {

constexpr int kBins = 11;
constexpr float kPi = 3.14159265358979f;  // as fast_pipeline.cpp

int Bin(float unit) { return std::clamp(static_cast<int>(std::floor(unit * kBins)), 0, kBins - 1); }
int AngleBin(float angle) { return Bin((angle + kPi) / (2 * kPi)); }

TEST(Fpfh, ApproxAtan2IsWithinItsBoundInEveryQuadrantAndKeepsSignedZeros) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::uniform_real_distribution<float> scale(-6.0f, 6.0f);
  double worst = 0;
  for (int k = 0; k < 1000000; ++k) {
    const float s = std::pow(10.0f, scale(rng));
    const float y = u(rng) * s, x = u(rng) * s;
    worst = std::max(worst, std::abs(double(internal::ApproxAtan2(y, x)) -
                                     std::atan2(double(y), double(x))));
  }
  EXPECT_LT(worst, 5e-6);  // the bound AngleBinOfAtan2 relies on, with 25x room in its margin
  // Along the axes and the diagonals, as atan2 (signed zeros decide +-pi and +-0).
  for (const float y : {0.0f, -0.0f, 1.0f, -1.0f, 3e-20f, -3e-20f}) {
    for (const float x : {1.0f, -1.0f, 3e-20f, -3e-20f}) {
      const float want = std::atan2(y, x), got = internal::ApproxAtan2(y, x);
      EXPECT_NEAR(got, want, 5e-6) << "y " << y << " x " << x;
      EXPECT_EQ(std::signbit(got), std::signbit(want)) << "y " << y << " x " << x;
    }
  }
}

TEST(Fpfh, AngleBinsAreAtan2sEvenAtTheBinsEdges) {
  std::vector<std::pair<float, float>> yx;
  // Every bin edge (and +-pi) approached from both sides, closer than the bracket and beyond it.
  for (int e = 0; e <= kBins; ++e) {
    const double edge = -M_PI + 2 * M_PI * e / kBins;
    for (const double d : {0.0, 1e-8, 1e-7, 1e-6, 1e-5, 5e-5, 1e-4, 2e-4, 1e-3}) {
      for (const double sign : {-1.0, 1.0}) {
        for (const double r : {1e-3, 1.0, 7.5, 1e3}) {
          yx.emplace_back(float(r * std::sin(edge + sign * d)), float(r * std::cos(edge + sign * d)));
        }
      }
    }
  }
  // Zeros (atan2's signed zeros pick +-pi and +-0) and vectors too short for the polynomial.
  for (const float y : {0.0f, -0.0f, 3e-30f, -3e-30f, 1e-21f}) {
    for (const float x : {0.0f, -0.0f, 1.0f, -1.0f, 2e-30f, -5e-30f}) yx.emplace_back(y, x);
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int k = 0; k < 1000000; ++k) yx.emplace_back(u(rng), u(rng));
  int near_edge = 0;
  for (const auto& [y, x] : yx) {
    const int want = AngleBin(std::atan2(y, x));
    ASSERT_EQ(internal::AngleBinOfAtan2(y, x), want) << "y " << y << " x " << x;
    near_edge += AngleBin(internal::ApproxAtan2(y, x)) != want;
  }
  // The edge cases did reach the fallback: the approximation alone bins some of them elsewhere.
  EXPECT_GT(near_edge, 0);
}

// FPFH as pcl::FPFHEstimation defines it, in the plainest spelling: every neighbour within the
// radius (every stride-th where there are more than max_neighbors per stride), the pair features
// with std::acos and std::atan2, each keypoint's own SPFH plus its neighbours' weighted by 1 / d.
FeatureMatrix PlainFpfh(const PointCloud& cloud, const Normals& normals,
                        const VoxelHashIndex& index, float radius_m, int max_neighbors,
                        const std::vector<int>& keys) {
  const int n = static_cast<int>(cloud.size());
  FeatureMatrix spfh = FeatureMatrix::Zero(n, 3 * kBins);
  std::vector<std::vector<int>> used(n);
  for (int i = 0; i < n; ++i) {
    if (!normals[i].allFinite()) continue;
    std::vector<int> nn;
    index.Radius(cloud[i], radius_m, nn);
    const int stride = std::max<int>(1, static_cast<int>(nn.size()) / max_neighbors);
    for (std::size_t k = 0; k < nn.size(); k += stride) {
      if (nn[k] != i && normals[nn[k]].allFinite()) used[i].push_back(nn[k]);
    }
    for (int j : used[i]) {
      Eigen::Vector3f dp = cloud[j] - cloud[i];
      const float d = dp.norm();
      if (d <= 0) continue;
      Eigen::Vector3f a = normals[i], b = normals[j];
      const float angle1 = a.dot(dp) / d, angle2 = b.dot(dp) / d;
      float f3 = angle1;
      if (std::acos(std::fabs(angle1)) > std::acos(std::fabs(angle2))) {
        std::swap(a, b);
        dp = -dp;
        f3 = -angle2;
      }
      Eigen::Vector3f v = dp.cross(a);
      const float vn = v.norm();
      if (vn <= 0) continue;
      v /= vn;
      const Eigen::Vector3f w = a.cross(v);
      const float f1 = std::atan2(w.dot(b), a.dot(b)), f2 = v.dot(b);
      const float incr = 100.0f / static_cast<float>(used[i].size());
      spfh(i, AngleBin(f1)) += incr;
      spfh(i, kBins + Bin((f2 + 1) * 0.5f)) += incr;
      spfh(i, 2 * kBins + Bin((f3 + 1) * 0.5f)) += incr;
    }
  }
  FeatureMatrix fpfh = FeatureMatrix::Zero(static_cast<int>(keys.size()), 3 * kBins);
  for (std::size_t row = 0; row < keys.size(); ++row) {
    const int i = keys[row];
    if (used[i].empty()) continue;
    Eigen::RowVectorXf h = spfh.row(i);
    for (int j : used[i]) {
      const float d = (cloud[j] - cloud[i]).norm();
      if (d > 0) h += spfh.row(j) / (d * static_cast<float>(used[i].size()));
    }
    for (int s = 0; s < 3; ++s) {
      const float sum = h.segment(s * kBins, kBins).sum();
      if (sum > 0) h.segment(s * kBins, kBins) *= 100.0f / sum;
    }
    fpfh.row(static_cast<int>(row)) = h;
  }
  return fpfh;
}

TEST(Fpfh, IsThePlainDefinitionsBitForBit) {
  // A room's corner, a box on its floor and a slanted board, sampled with 1 cm noise at ~0.1 m:
  // every kind of pair angle, and more neighbours than max_neighbors in places (strides > 1).
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  PointCloud cloud;
  for (int k = 0; k < 6000; ++k) {
    const float a = 4 * u(rng), b = 3 * u(rng);
    switch (k % 5) {
      case 0: cloud.emplace_back(a, b, noise(rng)); break;             // floor
      case 1: cloud.emplace_back(a, noise(rng), b); break;             // wall
      case 2: cloud.emplace_back(noise(rng), b, a * 0.75f); break;     // wall
      case 3: cloud.emplace_back(1 + 0.5f * u(rng), 1 + 0.5f * u(rng), 0.4f + noise(rng)); break;
      default: cloud.emplace_back(2.5f + 0.6f * a / 4, b, 0.3f * b + noise(rng)); break;
    }
  }
  const float normal_r = 0.3f, feature_r = 0.5f;
  const VoxelHashIndex index(cloud, feature_r);
  const Normals normals = EstimateNormals(cloud, index, normal_r, Eigen::Vector3f(2, 1.5f, 1));
  std::vector<int> keys;
  for (int i = 0; i < static_cast<int>(cloud.size()); i += 3) keys.push_back(i);
  for (const int max_neighbors : {5, 40, 1000}) {  // strides > 1, mixed, all 1
    const FeatureMatrix fast = ComputeFpfh(cloud, normals, index, feature_r, max_neighbors, keys);
    const FeatureMatrix plain = PlainFpfh(cloud, normals, index, feature_r, max_neighbors, keys);
    ASSERT_EQ(fast.rows(), plain.rows());
    EXPECT_TRUE(fast == plain) << "max_neighbors " << max_neighbors << ": largest difference "
                               << (fast - plain).cwiseAbs().maxCoeff();
    EXPECT_GT(fast.rowwise().sum().minCoeff(), 299.0f);  // every key has a histogram
  }
}

TEST(Fpfh, TiedPairsAndFarCoordinatesAreThePlainDefinitions) {
  // A lattice on z = 0 with normals exactly up: every pair's two angles tie (both 0), so neither
  // point is PCL's source and each side's features are its own; some points lifted and tilted.
  PointCloud cloud;
  Normals normals;
  for (int x = 0; x < 30; ++x) {
    for (int y = 0; y < 30; ++y) {
      const bool lifted = (x * 7 + y * 3) % 11 == 0;
      cloud.emplace_back(0.1f * x, 0.1f * y, lifted ? 0.05f : 0.0f);
      normals.push_back(lifted ? Eigen::Vector3f(0.6f, 0, 0.8f) : Eigen::Vector3f(0, 0, 1));
    }
  }
  std::vector<int> keys;
  for (int i = 0; i < static_cast<int>(cloud.size()); i += 2) keys.push_back(i);
  // The same scene far from the origin (coordinates of 5 km, rounding at 0.5 mm).
  PointCloud far = cloud;
  for (Eigen::Vector3f& p : far) p += Eigen::Vector3f(5000, -3000, 0);
  for (const PointCloud* c : {&cloud, &far}) {
    const VoxelHashIndex index(*c, 0.35);
    for (const int max_neighbors : {8, 1000}) {
      const FeatureMatrix fast = ComputeFpfh(*c, normals, index, 0.35f, max_neighbors, keys);
      const FeatureMatrix plain = PlainFpfh(*c, normals, index, 0.35f, max_neighbors, keys);
      EXPECT_TRUE(fast == plain) << "max_neighbors " << max_neighbors << ": largest difference "
                                 << (fast - plain).cwiseAbs().maxCoeff();
    }
  }
}

}  // namespace
}  // namespace pitchlab::mapping
