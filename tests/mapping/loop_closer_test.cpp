// EdgeInformation (mapping/src/loop_closer.hpp): a registration's edge weight is the inverse of its
// covariance times the scale, so a corridor's registration, whose information leaves the axis
// free, still gives the pose graph a positive definite weight that bounds the axis by its guess.

#include <gtest/gtest.h>

#include "loop_closer.hpp"

namespace pitchlab::mapping {
namespace {

// A corridor along x: the fit constrains every direction but x (information zero there); the
// registration kept x at an odometry guess bounded to 0.3 m, which its covariance says.
RegistrationResult CorridorRegistration() {
  RegistrationResult r;
  r.information = Matrix6d::Zero();
  r.information.diagonal() << 1e8, 1e8, 1e8, 0.0, 1e5, 1e5;  // [1/rad^2], [1/m^2]
  r.covariance = Matrix6d::Zero();
  r.covariance.diagonal() << 1e-8, 1e-8, 1e-8, 0.3 * 0.3, 1e-5, 1e-5;
  return r;
}

TEST(EdgeInformation, IsTheScaledInverseOfTheCovarianceAndBoundsAFreeAxisByItsGuess) {
  const RegistrationResult r = CorridorRegistration();
  Result<Matrix6d> w = EdgeInformation(r, 0.1);
  ASSERT_TRUE(w) << w.error().message;
  EXPECT_NEAR((*w)(3, 3), 0.1 / (0.3 * 0.3), 1e-9);  // the axis: 0.3 m, then scaled
  EXPECT_NEAR((*w)(4, 4), 0.1 * 1e5, 1e-3);
  EXPECT_NEAR((*w)(0, 0), 0.1 * 1e8, 1e-1);
  // The pose graph takes this weight and refuses the information itself.
  PoseGraph graph;
  ASSERT_TRUE(graph.AddNode(Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(graph.AddNode(Eigen::Isometry3d::Identity()));
  PoseGraphEdge edge{0, 1, Eigen::Isometry3d::Identity(), r.information, EdgeKind::kSequential};
  EXPECT_FALSE(graph.AddEdge(edge));
  edge.information = *w;
  EXPECT_TRUE(graph.AddEdge(edge));
}

TEST(EdgeInformation, ARegistrationWithoutACovarianceIsAnError) {
  RegistrationResult r;  // no ICP result scored: covariance zero
  Result<Matrix6d> w = EdgeInformation(r, 0.1);
  ASSERT_FALSE(w);
  EXPECT_NE(w.error().message.find("not positive definite"), std::string::npos)
      << w.error().message;
}

}  // namespace
}  // namespace pitchlab::mapping

namespace pitchlab::mapping {
namespace {

// A loop edge needs the pairwise inlier share even when scan-to-map runs looser (the mission's
// 15 %: office loops at 15-18 % inliers were 1.6-2.4 deg off), and keeps no direction at the
// graph's guess; a stricter caller's share stays.
TEST(LoopRegistrationConfig, NeedsThePairwiseInlierShareAndCarriesNothingFromTheGuess) {
  RegistrationConfig mission;
  mission.min_inlier_ratio = 0.15;
  mission.carry_max_m = 2.0;
  mission.carry_max_deg = 10.0;
  const RegistrationConfig loop = LoopRegistrationConfig(mission);
  EXPECT_DOUBLE_EQ(loop.min_inlier_ratio, RegistrationConfig{}.min_inlier_ratio);
  EXPECT_EQ(loop.carry_max_m, 0.0);
  EXPECT_EQ(loop.carry_max_deg, 0.0);
  RegistrationConfig strict;
  strict.min_inlier_ratio = 0.5;
  EXPECT_DOUBLE_EQ(LoopRegistrationConfig(strict).min_inlier_ratio, 0.5);
}

}  // namespace
}  // namespace pitchlab::mapping
