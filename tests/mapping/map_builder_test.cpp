// MapBuilder on a real simulated sequence through the office: the trajectory follows the ground
// truth, failed registrations are reported and never merged.

#include <gtest/gtest.h>

#include "pitchlab/mapping/map_builder.hpp"
#include "sim_scans.hpp"

namespace pitchlab::mapping {
namespace {

using testing::SimulatedScan;

constexpr double kMaxRotationError_deg = 0.5;
constexpr double kMaxTranslationError_m = 0.03;

struct Pose2 {
  double x_m, y_m, yaw_deg;
};
const Pose2 kOfficePath[] = {
    {-8, 0, 0}, {-7.4, 0.2, 8}, {-6.8, 0.3, 15}, {-6.2, 0.2, 10}, {-5.6, 0.0, 0}};

TEST(MapBuilder, AnOfficeSequenceFollowsTheGroundTruthAndGrowsTheMap) {
  MapBuilder builder{MapConfig{}};
  std::vector<sensors::Scan3D> scans;
  std::size_t map_points = 0;
  for (std::size_t i = 0; i < std::size(kOfficePath); ++i) {
    const Pose2& p = kOfficePath[i];
    scans.push_back(SimulatedScan("office", p.x_m, p.y_m, p.yaw_deg, 10 + i));
    Result<MergeStep> step = builder.Add(CloudFromScan(scans.back()));
    ASSERT_TRUE(step) << step.error().message;
    EXPECT_TRUE(step->merged) << "scan " << i << ": " << step->registration.reason;
    const std::size_t now = builder.MapCloud().size();
    EXPECT_GE(now, map_points);
    map_points = now;
  }
  ASSERT_EQ(builder.trajectory().size(), std::size(kOfficePath));
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const Eigen::Isometry3d truth = scans[0].T_world_base.inverse() * scans[i].T_world_base;
    const PoseError e = ComparePoses(builder.trajectory()[i].T_map_base, truth);
    EXPECT_LT(e.rotation_deg, kMaxRotationError_deg) << "scan " << i;
    EXPECT_LT(e.translation_m, kMaxTranslationError_m) << "scan " << i;
  }
}

TEST(MapBuilder, AScanFromAnotherWorldIsReportedAndNotMerged) {
  MapBuilder builder{MapConfig{}};
  ASSERT_TRUE(builder.Add(CloudFromScan(SimulatedScan("office", -8, 0, 0, 10))));
  const std::size_t before = builder.MapCloud().size();
  Result<MergeStep> step = builder.Add(CloudFromScan(SimulatedScan("terrain", 0, 0, 0)));
  ASSERT_TRUE(step) << step.error().message;
  EXPECT_FALSE(step->merged);
  EXPECT_FALSE(step->registration.success);
  EXPECT_FALSE(step->registration.reason.empty());
  EXPECT_EQ(builder.MapCloud().size(), before);
  EXPECT_EQ(builder.trajectory().size(), 1u);
  EXPECT_EQ(builder.scans_seen(), 2u);
}

TEST(MapBuilder, AnEmptyFirstScanIsAnError) {
  MapBuilder builder{MapConfig{}};
  Result<MergeStep> step = builder.Add({});
  ASSERT_FALSE(step);
  EXPECT_EQ(step.error().code, Error::Code::kInvalidArgument);
}

}  // namespace
}  // namespace pitchlab::mapping
