// The chi-square CDF and quantile behind the pose graph's gates, against closed forms and
// published table values.

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "chi_square.hpp"

namespace pitchlab::mapping {
namespace {

TEST(ChiSquare, TwoDegreesOfFreedomFollowTheClosedForm) {
  // With 2 dof the CDF is 1 - exp(-x / 2).
  for (double x : {0.1, 1.0, 2.0, 5.0, 13.8, 30.0}) {
    EXPECT_NEAR(ChiSquareCdf(2, x), 1 - std::exp(-x / 2), 1e-13) << "x = " << x;
  }
  EXPECT_NEAR(ChiSquareQuantile(2, 0.5), 2 * std::log(2.0), 1e-9);
}

TEST(ChiSquare, OneDegreeOfFreedomIsASquaredNormal) {
  // P(Z^2 <= x) = erf(sqrt(x / 2)).
  for (double x : {0.01, 0.5, 1.0, 3.841, 10.0}) {
    EXPECT_NEAR(ChiSquareCdf(1, x), std::erf(std::sqrt(x / 2)), 1e-13) << "x = " << x;
  }
}

TEST(ChiSquare, QuantilesMatchPublishedTables) {
  // NIST/SEMATECH e-Handbook, table 1.3.6.7.4 (upper critical values), to the 3 decimals printed.
  EXPECT_NEAR(ChiSquareQuantile(1, 0.95), 3.841, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(3, 0.95), 7.815, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(3, 0.999), 16.266, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(6, 0.95), 12.592, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(6, 0.999), 22.458, 5e-4);
  EXPECT_NEAR(ChiSquareQuantile(6, 0.05), 1.635, 5e-4);
}

TEST(ChiSquare, QuantileInvertsTheCdf) {
  for (int dof : {1, 3, 6, 20}) {
    for (double p : {0.001, 0.3, 0.9, 0.9999}) {
      EXPECT_NEAR(ChiSquareCdf(dof, ChiSquareQuantile(dof, p)), p, 1e-9) << dof << " " << p;
    }
  }
}

TEST(ChiSquare, ArgumentsOutOfRangeThrow) {
  EXPECT_THROW(ChiSquareCdf(0, 1.0), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(6, 0.0), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(6, 1.0), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(6, std::nan("")), std::invalid_argument);
  EXPECT_THROW(ChiSquareQuantile(65, 0.5), std::invalid_argument);
  EXPECT_EQ(ChiSquareCdf(6, -1.0), 0.0);
}

}  // namespace
}  // namespace pitchlab::mapping
