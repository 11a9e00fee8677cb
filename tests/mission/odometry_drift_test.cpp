// Odometry's drift per metre, as registration measured it (mission/odometry_drift.hpp): the
// figure run.drift_per_m plans for.
#include "pitchlab/mission/odometry_drift.hpp"

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

// A stop after a drive of `driven_m` whose registered pose lies (dx, dy, dz) from odometry's.
StopRecord Stop(int index, double driven_m, double dx, double dy, double dz, bool merged = true) {
  StopRecord s;
  s.index = index;
  s.driven_m = driven_m;
  s.merge.merged = merged;
  s.T_world_base_odom.translation() = Eigen::Vector3d(5, -3, 1);
  s.T_world_base = s.T_world_base_odom;
  s.T_world_base.translation() += Eigen::Vector3d(dx, dy, dz);
  return s;
}

TEST(MeasureOdometryDrift, IsTheHorizontalOffsetPerMetreDrivenOverRegisteredDrives) {
  // Ten drives of 2 m drifting 0.02, 0.04, ... 0.2 m (3-4-5 triangles, 0.01 .. 0.1 m/m), each
  // also 0.3 m off in height (the drift is horizontal: height comes from the ground).
  std::vector<StopRecord> stops{Stop(0, 0.0, 0, 0, 0)};
  for (int k = 1; k <= 10; ++k) {
    const double off = 0.02 * k;
    stops.push_back(Stop(k, 2.0, 0.6 * off, -0.8 * off, 0.3));
  }
  const OdometryDrift d = MeasureOdometryDrift(stops);
  EXPECT_EQ(d.drives, 10u);
  EXPECT_NEAR(d.median_per_m, 0.05, 1e-12);  // the 5th of 10
  EXPECT_NEAR(d.p90_per_m, 0.09, 1e-12);     // the 9th
  EXPECT_NEAR(d.max_per_m, 0.10, 1e-12);
}

// The first stop (no drive), a stop that did not register (its pose is odometry's) and a drive
// shorter than half a metre (a turn, a back-off: the ratio would be registration error) are no
// measurement.
TEST(MeasureOdometryDrift, LeavesOutTheStartUnregisteredStopsAndShortDrives) {
  const std::vector<StopRecord> stops{Stop(0, 3.0, 1.0, 0, 0), Stop(1, 2.0, 0.9, 0, 0, false),
                                      Stop(2, 0.3, 0.2, 0, 0), Stop(3, 4.0, 0.0, 0.4, 0)};
  const OdometryDrift d = MeasureOdometryDrift(stops);
  EXPECT_EQ(d.drives, 1u);
  EXPECT_NEAR(d.median_per_m, 0.1, 1e-12);
  EXPECT_NEAR(d.p90_per_m, 0.1, 1e-12);
  EXPECT_NEAR(d.max_per_m, 0.1, 1e-12);
  const OdometryDrift none = MeasureOdometryDrift({Stop(0, 0.0, 0, 0, 0)});
  EXPECT_EQ(none.drives, 0u);
  EXPECT_EQ(none.p90_per_m, 0.0);
}

}  // namespace
}  // namespace pitchlab::mission
