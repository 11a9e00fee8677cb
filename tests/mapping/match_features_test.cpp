// MatchFeatures (internal to mapping) against a plain double loop over every pair: the same
// mutual nearest neighbours, ties going to the first row, with more source rows than one block.

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "fast_pipeline.hpp"

namespace pitchlab::mapping {
namespace {

std::vector<std::pair<int, int>> Brute(const FeatureMatrix& s, const FeatureMatrix& t) {
  const auto dist = [&](int i, int j) {  // as MatchFeatures computes it
    return -2.0f * s.row(i).dot(t.row(j)) + s.row(i).squaredNorm() + t.row(j).squaredNorm();
  };
  std::vector<int> best_t(s.rows(), -1), best_s(t.rows(), -1);
  for (int i = 0; i < s.rows(); ++i) {
    float best = std::numeric_limits<float>::max();
    for (int j = 0; j < t.rows(); ++j) {
      if (s.row(i).squaredNorm() > 0 && t.row(j).squaredNorm() > 0 && dist(i, j) < best) {
        best = dist(i, j), best_t[i] = j;
      }
    }
  }
  for (int j = 0; j < t.rows(); ++j) {
    float best = std::numeric_limits<float>::max();
    for (int i = 0; i < s.rows(); ++i) {
      if (s.row(i).squaredNorm() > 0 && t.row(j).squaredNorm() > 0 && dist(i, j) < best) {
        best = dist(i, j), best_s[j] = i;
      }
    }
  }
  std::vector<std::pair<int, int>> out;
  for (int i = 0; i < s.rows(); ++i) {
    if (best_t[i] >= 0 && best_s[best_t[i]] == i) out.emplace_back(i, best_t[i]);
  }
  return out;
}

TEST(MatchFeatures, FindsTheMutualNearestNeighboursOfAPlainLoopTiesToTheFirstRow) {
  std::mt19937 rng(5);
  // Few distinct values: many exact ties. 700 source rows: three blocks of 256.
  std::uniform_int_distribution<int> value(0, 3);
  FeatureMatrix s(700, 33), t(300, 33);
  for (int i = 0; i < s.rows(); ++i)
    for (int c = 0; c < 33; ++c) s(i, c) = static_cast<float>(value(rng));
  for (int j = 0; j < t.rows(); ++j)
    for (int c = 0; c < 33; ++c) t(j, c) = static_cast<float>(value(rng));
  s.row(3).setZero();  // rows without a feature are skipped
  t.row(7).setZero();
  for (int i = 400; i < 420; ++i) s.row(i) = t.row(i - 400);  // exact matches, across blocks
  s.row(650) = t.row(5);  // a later duplicate of row 405: row 405 keeps the match
  std::vector<std::pair<int, int>> got;
  for (const Correspondence& c : MatchFeatures(s, t)) got.emplace_back(c.source, c.target);
  EXPECT_EQ(got, Brute(s, t));
  EXPECT_GE(got.size(), 19u);
}

TEST(MatchFeatures, ASideWithoutRowsMatchesNothing) {
  const FeatureMatrix some = FeatureMatrix::Ones(5, 36), none(0, 36);
  EXPECT_TRUE(MatchFeatures(some, none).empty());
  EXPECT_TRUE(MatchFeatures(none, some).empty());
  EXPECT_TRUE(MatchFeatures(none, none).empty());
}

}  // namespace
}  // namespace pitchlab::mapping
