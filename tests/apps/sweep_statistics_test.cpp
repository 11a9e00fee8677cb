// The statistics behind `pitchlab bench --compare`, against answers known by hand.

#include "sweep_statistics.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace pitchlab::apps {
namespace {

TEST(Median, OddEvenAndEmpty) {
  EXPECT_DOUBLE_EQ(Median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4, 1, 3, 2}), 2.5);  // the mean of the middle two, as bench's table
  EXPECT_TRUE(std::isnan(Median({})));
}

// Fisher's tea-tasting table (3 of 4 right against 1 of 4): two-sided p = 34/70.
TEST(FisherExactTwoSided, TheTeaTastingTable) {
  EXPECT_NEAR(FisherExactTwoSided(3, 4, 1, 4), 34.0 / 70.0, 1e-12);
  EXPECT_NEAR(FisherExactTwoSided(1, 4, 3, 4), 34.0 / 70.0, 1e-12);  // symmetric
}

// 20 of 20 against 10 of 20: only tables as extreme as that one, both ways, count:
// 2 * C(20,20) C(20,10) / C(40,30) = 2 * 184756 / 847660528 = 0.000435920.
TEST(FisherExactTwoSided, AllAgainstHalf) {
  EXPECT_NEAR(FisherExactTwoSided(20, 20, 10, 20), 2.0 * 184756.0 / 847660528.0, 1e-12);
  EXPECT_DOUBLE_EQ(FisherExactTwoSided(20, 20, 20, 20), 1.0);  // nothing to tell apart
  EXPECT_NEAR(FisherExactTwoSided(20, 20, 19, 20), 1.0, 1e-12);
  EXPECT_THROW(FisherExactTwoSided(5, 4, 1, 4), std::invalid_argument);
  EXPECT_THROW(FisherExactTwoSided(-1, 4, 1, 4), std::invalid_argument);
}

std::vector<double> Range(double from, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(from + i);
  return v;
}

// Two sets of runs that do not overlap: every relabelling but the observed one (and its mirror)
// changes the medians by less, so p is the smallest the test can give, 1 / (resamples + 1), and
// the bootstrap's changes lie between the closest and the farthest pair of values, 91 and 109.
TEST(CompareMedians, SetsApartAreTold) {
  const MedianChange c = CompareMedians(Range(0, 10), Range(100, 10), 2000, 7);
  EXPECT_DOUBLE_EQ(c.median_a, 4.5);
  EXPECT_DOUBLE_EQ(c.median_b, 104.5);
  EXPECT_DOUBLE_EQ(c.change, 100.0);
  EXPECT_NEAR(c.p_value, 1.0 / 2001.0, 1e-12);
  EXPECT_GE(c.low, 91.0);
  EXPECT_LE(c.low, 100.0);
  EXPECT_GE(c.high, 100.0);
  EXPECT_LE(c.high, 109.0);
}

// The same runs on both sides: no change, every relabelling reaches it (p = 1), and the interval
// holds 0.
TEST(CompareMedians, TheSameRunsTwiceShowNoChange) {
  const std::vector<double> runs = {0.30, 0.25, 0.41, 0.28, 0.33, 0.36, 0.29, 0.31};
  const MedianChange c = CompareMedians(runs, runs);
  EXPECT_DOUBLE_EQ(c.change, 0.0);
  EXPECT_DOUBLE_EQ(c.p_value, 1.0);
  EXPECT_LT(c.low, 0.0);
  EXPECT_GT(c.high, 0.0);
}

// A shift of one unit between samples that overlap (0..19 against 1..20) is not a difference 20
// runs a side can show: p far above 0.05.
TEST(CompareMedians, AnOverlappingShiftIsNotSignificant) {
  const MedianChange c = CompareMedians(Range(0, 20), Range(1, 20));
  EXPECT_DOUBLE_EQ(c.change, 1.0);
  EXPECT_GT(c.p_value, 0.5);
  EXPECT_LT(c.low, 0.0);
}

TEST(CompareMedians, TheSameSeedGivesTheSameAnswer) {
  const MedianChange a = CompareMedians(Range(0, 15), Range(3, 12), 500, 42);
  const MedianChange b = CompareMedians(Range(0, 15), Range(3, 12), 500, 42);
  EXPECT_EQ(a.low, b.low);
  EXPECT_EQ(a.high, b.high);
  EXPECT_EQ(a.p_value, b.p_value);
}

TEST(CompareMedians, AnEmptySideIsRefused) {
  EXPECT_THROW(CompareMedians({}, {1.0}), std::invalid_argument);
  EXPECT_THROW(CompareMedians({1.0}, {1.0}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::apps
