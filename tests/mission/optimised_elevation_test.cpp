// With loop closure on, the elevation map the robot plans on follows the pose graph's optimised
// poses (issue 20): after a run whose loops moved poses, the map is the one built from scratch
// with every stop's scan at its final pose, bit for bit, and not the one at the poses as they
// were registered.

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mapping/per_scan_elevation_map.hpp"
#include "pitchlab/mission/elevation_scan.hpp"
#include "pitchlab/mission/sim_mission.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

// Cells whose statistics differ in any field (== on floats: +inf equals +inf, no NaN here).
std::size_t DifferingCells(const mapping::ElevationMap& a, const mapping::ElevationMap& b) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < a.cells().size(); ++k) {
    const mapping::CellStats& x = a.at(k);
    const mapping::CellStats& y = b.at(k);
    n += !(x.count == y.count && x.mean_x == y.mean_x && x.mean_y == y.mean_y &&
           x.mean_z == y.mean_z && x.c_xx == y.c_xx && x.c_xy == y.c_xy && x.c_xz == y.c_xz &&
           x.c_yy == y.c_yy && x.c_yz == y.c_yz && x.c_zz == y.c_zz && x.min_z == y.min_z &&
           x.max_z == y.max_z && x.clearance_z == y.clearance_z);
  }
  return n;
}

// The map from scratch: the registered stops' scans at the poses `final` picks (true:
// T_world_base_final), then the views of the stops that did not register, at their odometry poses
// (no graph node moves them), in stop order, on the cells no registered scan saw.
mapping::ElevationMap Rebuilt(const SimMissionSpec& spec, const MissionResult& r, bool final) {
  const sensors::MountConfig& mount = spec.config.rig.robot.mount;
  const auto input = [&](const StopRecord& s) {
    return ElevationScanOf(s.scan, spec.settings.mission.map_range_m, mount,
                           spec.config.rig.lms200.beam_divergence_deg * M_PI / 180.0,
                           r.elevation.geometry().cell_m);
  };
  mapping::PerScanElevationMap scans(r.elevation.geometry());
  for (const StopRecord& s : r.stops) {
    if (!s.merge.merged) continue;
    const ElevationScan in = input(s);
    const auto inserted = scans.Insert(s.merge.scan_index, in.points_base, in.sensor_base,
                                       final ? s.T_world_base_final : s.T_world_base, in.ground_base);
    EXPECT_TRUE(inserted) << inserted.error().message;
  }
  mapping::ElevationMap map = scans.map();
  for (const StopRecord& s : r.stops) {
    if (s.merge.merged) continue;
    const Eigen::Isometry3f T = s.T_world_base.cast<float>();
    std::vector<Eigen::Vector3f> points;
    for (const Eigen::Vector3f& p : input(s).points_base) points.push_back(T * p);
    const Eigen::Vector3f laser =
        (s.T_world_base * mount.BaseToLaser(0.0)).translation().cast<float>();
    const auto merged = map.Merge(ViewOver(map.geometry(), points, laser),
                                  mapping::ElevationMap::MergeCells::kUnknown);
    EXPECT_TRUE(merged) << merged.error().message;
  }
  return map;
}

TEST(RunSimMission, WithLoopClosureThePlannersMapIsTheOneRebuiltAtTheOptimisedPoses) {
  const test_support::ScopedTempDir dir("optimised_elevation");
  // The office corridor (start -8, 0 facing east) to -6.5, 0, on to -4.5, 0 and back: the
  // route tests/integration/route_cli_test.cpp drives, whose stop at the far waypoint closes
  // loops to the first stops.
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 2);
  spec.world_file = fs::path(PITCHLAB_WORLDS_DIR) / "office.xml";
  spec.via_m = {Eigen::Vector2d(-6.5, 0)};
  spec.goal_m = Eigen::Vector2d(-4.5, 0);
  spec.round_trip = true;
  spec.settings.mission.registration.loop_closure.enabled = true;
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  bool reposed = false;
  for (const StopRecord& s : run.result.stops) reposed = reposed || s.merge.reposed;
  ASSERT_TRUE(reposed) << "no loop moved a pose: nothing to test";
  ASSERT_GE(run.result.loop_counts.accepted, 1u);
  EXPECT_EQ(DifferingCells(run.result.elevation, Rebuilt(spec, run.result, true)), 0u);
  // Not vacuous: the poses as registered give another map.
  EXPECT_GT(DifferingCells(run.result.elevation, Rebuilt(spec, run.result, false)), 0u);
}

}  // namespace
}  // namespace pitchlab::mission
