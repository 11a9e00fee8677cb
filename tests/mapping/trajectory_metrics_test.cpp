// ATE, RPE and the wrong-loop test against answers computed by hand.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mapping/trajectory_metrics.hpp"

namespace pitchlab::mapping {
namespace {

using Poses = std::vector<Eigen::Isometry3d>;

constexpr double kExact = 1e-12;  // hand answers are exact up to double rounding [m], [deg]
constexpr double kPi = 3.14159265358979323846;

Eigen::Isometry3d At(double x, double y, double z, double yaw_deg = 0) {
  return PoseFromXyzRpyDeg(x, y, z, 0, 0, yaw_deg);
}

TEST(AbsoluteTrajectoryError, UnalignedIsTheRmsOfThePositionErrors) {
  const Poses truth{At(0, 0, 0), At(1, 0, 0), At(2, 0, 0)};
  const Poses estimate{At(0, 0, 0), At(1, 0.3, 0), At(2, 0, 0.4, 3)};
  const auto ate = AbsoluteTrajectoryErrorUnaligned(estimate, truth);
  ASSERT_TRUE(ate) << ate.error().message;
  EXPECT_EQ(ate->poses, 3);
  EXPECT_NEAR(ate->rmse_m, std::sqrt((0.09 + 0.16) / 3), kExact);  // errors 0, 0.3, 0.4 m
  EXPECT_NEAR(ate->max_m, 0.4, kExact);
  EXPECT_NEAR(ate->rotation_rmse_deg, std::sqrt(9.0 / 3), 1e-9);  // 0, 0, 3 deg
  EXPECT_TRUE(ate->T_truth_estimate.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(AbsoluteTrajectoryError, AlignmentRemovesARigidOffsetOnly) {
  // The estimate is the truth scaled by 1.1 about the centroid (which no rigid motion undoes:
  // by symmetry the best one is the identity, leaving 0.1 m at each of the four points), then
  // moved by G. Aligned: 0.1 m RMSE and the alignment G^-1.
  const Poses truth{At(1, 0, 0), At(0, 1, 0), At(-1, 0, 0), At(0, -1, 0)};
  const Eigen::Isometry3d G = PoseFromXyzRpyDeg(3, -2, 0.5, 5, -4, 30);
  Poses estimate;
  for (const auto& T : truth) {
    Eigen::Isometry3d scaled = T;
    scaled.translation() *= 1.1;
    estimate.push_back(G * scaled);
  }
  const auto aligned = AbsoluteTrajectoryErrorAligned(estimate, truth);
  ASSERT_TRUE(aligned) << aligned.error().message;
  EXPECT_NEAR(aligned->rmse_m, 0.1, 1e-9);
  EXPECT_NEAR(aligned->max_m, 0.1, 1e-9);
  EXPECT_NEAR(aligned->rotation_rmse_deg, 0, 1e-6);
  EXPECT_TRUE(aligned->T_truth_estimate.isApprox(G.inverse(), 1e-9));
  const auto unaligned = AbsoluteTrajectoryErrorUnaligned(estimate, truth);
  ASSERT_TRUE(unaligned);
  EXPECT_GT(unaligned->rmse_m, 3.0);  // G moves every point by more than 3 m
}

TEST(RelativePoseError, PerStopComparesConsecutiveMotions) {
  // Step 0 -> 1 is 0.1 m too long, step 1 -> 2 right: errors 0.1 and 0 m.
  const Poses truth{At(0, 0, 0), At(1, 0, 0), At(2, 0, 0)};
  const Poses estimate{At(0, 0, 0), At(1.1, 0, 0), At(2.1, 0, 0)};
  const auto rpe = RelativePoseErrorPerStop(estimate, truth);
  ASSERT_TRUE(rpe) << rpe.error().message;
  EXPECT_EQ(rpe->pairs, 2);
  EXPECT_NEAR(rpe->translation_rmse, std::sqrt(0.01 / 2), kExact);
  EXPECT_NEAR(rpe->translation_max, 0.1, kExact);
  EXPECT_NEAR(rpe->rotation_rmse_deg, 0, kExact);
}

TEST(RelativePoseError, PerStopSeesAHeadingErrorInTheNextStep) {
  // Stop 1 turned 2 deg: step 0 -> 1 is off by 2 deg, step 1 -> 2 by -2 deg and, seen from the
  // turned stop, its 1 m forward step lands 2 sin(1 deg) m from the true one.
  const Poses truth{At(0, 0, 0), At(1, 0, 0), At(2, 0, 0)};
  const Poses estimate{At(0, 0, 0), At(1, 0, 0, 2), At(2, 0, 0)};
  const auto rpe = RelativePoseErrorPerStop(estimate, truth);
  ASSERT_TRUE(rpe);
  const double chord_m = 2 * std::sin(1.0 * kPi / 180);
  EXPECT_NEAR(rpe->translation_max, chord_m, 1e-12);
  EXPECT_NEAR(rpe->translation_rmse, std::sqrt(chord_m * chord_m / 2), 1e-12);
  EXPECT_NEAR(rpe->rotation_rmse_deg, 2, 1e-9);
  EXPECT_NEAR(rpe->rotation_max_deg, 2, 1e-9);
}

TEST(RelativePoseError, PerMetreDividesBySegmentsOfTruePath) {
  // Stops 0.5 m apart, 1 m segments: (0, 2), (1, 3), (2, 4). Only the last stop is 0.2 m long.
  const Poses truth{At(0, 0, 0), At(0.5, 0, 0), At(1, 0, 0), At(1.5, 0, 0), At(2, 0, 0)};
  const Poses estimate{At(0, 0, 0), At(0.5, 0, 0), At(1, 0, 0), At(1.5, 0, 0), At(2.2, 0, 0)};
  const auto rpe = RelativePoseErrorPerMetre(estimate, truth, 1.0);
  ASSERT_TRUE(rpe) << rpe.error().message;
  EXPECT_EQ(rpe->pairs, 3);
  EXPECT_NEAR(rpe->translation_rmse, std::sqrt(0.04 / 3), 1e-12);  // 0, 0, 0.2 m per 1 m
  EXPECT_NEAR(rpe->translation_max, 0.2, 1e-12);
  // 2 m segments: one pair (0, 4), 0.2 m over 2 m.
  const auto two = RelativePoseErrorPerMetre(estimate, truth, 2.0);
  ASSERT_TRUE(two);
  EXPECT_EQ(two->pairs, 1);
  EXPECT_NEAR(two->translation_rmse, 0.1, 1e-12);
}

TEST(RelativePoseError, PerMetreRefusesAPathShorterThanOneSegment) {
  const Poses truth{At(0, 0, 0), At(0.5, 0, 0)};
  const auto rpe = RelativePoseErrorPerMetre(truth, truth, 1.0);
  ASSERT_FALSE(rpe);
  EXPECT_NE(rpe.error().message.find("shorter than one segment"), std::string::npos);
  EXPECT_FALSE(RelativePoseErrorPerMetre(truth, truth, 0.0));
  EXPECT_FALSE(RelativePoseErrorPerMetre(truth, truth, std::nan("")));
}

TEST(TrajectoryMetrics, BadInputIsAnErrorNamingIt) {
  const Poses two{At(0, 0, 0), At(1, 0, 0)};
  const Poses three{At(0, 0, 0), At(1, 0, 0), At(2, 0, 0)};
  const auto mismatch = AbsoluteTrajectoryErrorUnaligned(two, three);
  ASSERT_FALSE(mismatch);
  EXPECT_NE(mismatch.error().message.find("2 estimated poses but 3 true ones"), std::string::npos);
  EXPECT_FALSE(AbsoluteTrajectoryErrorAligned({}, {}));
  EXPECT_FALSE(RelativePoseErrorPerStop({At(0, 0, 0)}, {At(0, 0, 0)}));
  Poses bad = two;
  bad[1].translation().x() = std::nan("");
  const auto nan = RelativePoseErrorPerStop(bad, two);
  ASSERT_FALSE(nan);
  EXPECT_NE(nan.error().message.find("pose 1 is not finite"), std::string::npos);
}

TEST(WrongLoopClosure, IsMoreThanOneCellOrOneDegreeOffTheTruth) {
  const Eigen::Isometry3d truth = PoseFromXyzRpyDeg(2, 1, 0, 0, 0, 45);
  EXPECT_FALSE(IsWrongLoopClosure(truth * At(0.09, 0, 0), truth));
  EXPECT_TRUE(IsWrongLoopClosure(truth * At(0.06, 0.06, 0.06), truth));  // 0.104 m
  EXPECT_FALSE(IsWrongLoopClosure(truth * At(0, 0, 0, 0.9), truth));
  EXPECT_TRUE(IsWrongLoopClosure(truth * PoseFromXyzRpyDeg(0, 0, 0, 1.1, 0, 0), truth));
  EXPECT_FALSE(IsWrongLoopClosure(truth, truth));
}

}  // namespace
}  // namespace pitchlab::mapping
