// GuessGridStarts (mapping/src): the starts a registration searches around a guess.

#include "guess_grid.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "pitchlab/mapping/registration.hpp"

namespace pitchlab::mapping {
namespace {

constexpr double kStep_m = 0.6;
constexpr double kStep_deg = 12.0;

TEST(GuessGridStarts, AboutTheSourcesOwnZTheyAreStepsAndTurnsInItsFrame) {
  const Eigen::Isometry3d guess = PoseFromXyzRpyDeg(1.2, -0.4, 0.05, 3.0, -2.0, 40.0);
  const std::vector<Eigen::Isometry3d> starts =
      GuessGridStarts(guess, kStep_m, kStep_deg, guess.linear().col(2));
  ASSERT_EQ(starts.size(), 26u);
  std::size_t k = 0;
  for (int ix = -1; ix <= 1; ++ix) {
    for (int iy = -1; iy <= 1; ++iy) {
      for (int iyaw = -1; iyaw <= 1; ++iyaw) {
        if (ix == 0 && iy == 0 && iyaw == 0) continue;
        const Eigen::Isometry3d expected =
            guess * PoseFromXyzRpyDeg(ix * kStep_m, iy * kStep_m, 0, 0, 0, iyaw * kStep_deg);
        EXPECT_TRUE(starts[k].isApprox(expected, 1e-12)) << ix << " " << iy << " " << iyaw;
        ++k;
      }
    }
  }
}

TEST(GuessGridStarts, AboutAMeasuredUpEveryStartKeepsTheGuesssTilt) {
  // The source stands 8 deg rolled and 5 deg pitched on a slope; the target frame's z is up.
  const Eigen::Isometry3d guess = PoseFromXyzRpyDeg(0.8, 0.3, 0.1, 8.0, -5.0, 25.0);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const std::vector<Eigen::Isometry3d> starts = GuessGridStarts(guess, kStep_m, kStep_deg, up);
  ASSERT_EQ(starts.size(), 26u);
  int turned = 0;
  for (const Eigen::Isometry3d& start : starts) {
    EXPECT_LT(TiltBetween(start, guess, up), 1e-9);
    // Steps are horizontal, one or both of two perpendicular kStep_m steps.
    const Eigen::Vector3d step = start.translation() - guess.translation();
    EXPECT_NEAR(step.dot(up), 0.0, 1e-12);
    const double n = step.norm();
    EXPECT_TRUE(n < 1e-12 || std::abs(n - kStep_m) < 1e-12 ||
                std::abs(n - kStep_m * std::sqrt(2.0)) < 1e-12)
        << n;
    // Turns are about up, by 0 or kStep_deg.
    const PoseError e = ComparePoses(start, guess);
    if (e.rotation_deg > 1e-9) {
      EXPECT_NEAR(e.rotation_deg, kStep_deg, 1e-9);
      ++turned;
    }
  }
  EXPECT_EQ(turned, 18);
  // The grid the source's own z would give tilts its turned starts off the guess's tilt: by
  // 2 sin(6 deg) x 9.4 deg, about 2 deg, four times the mission's 0.5 deg tilt tolerance.
  const std::vector<Eigen::Isometry3d> own =
      GuessGridStarts(guess, kStep_m, kStep_deg, guess.linear().col(2));
  double worst_deg = 0;
  for (const Eigen::Isometry3d& start : own)
    worst_deg = std::max(worst_deg, TiltBetween(start, guess, up));
  EXPECT_GT(worst_deg, 1.5);
}

}  // namespace
}  // namespace pitchlab::mapping
