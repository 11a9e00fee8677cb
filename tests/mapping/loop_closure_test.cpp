// MapBuilder with loop closure (issue 20) on a simulated office sequence that drives 4 m along the
// corridor, turns about, comes back and turns to face where it began: loops are accepted, none is
// wrong against the truth, the final pose is no worse than without loop closure, and the map cloud
// is the one the optimised poses give.

#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>
#include <vector>

#include "pitchlab/mapping/map_builder.hpp"
#include "pitchlab/mapping/trajectory_metrics.hpp"
#include "sim_scans.hpp"

namespace pitchlab::mapping {
namespace {

using testing::SimulatedScan;

// Differences below the LMS200's mm-mode range resolution (1 mm) cannot be told apart.
constexpr double kRangeResolutionM = 0.001;

struct Stop {
  double x_m, y_m, yaw_deg;
};
const Stop kRoute[] = {{-8, 0, 0},   {-7, 0, 0},   {-6, 0, 0},   {-5, 0, 0},   {-4, 0, 0},
                       {-4, 0, 90},  {-4, 0, 180}, {-5, 0, 180}, {-6, 0, 180}, {-7, 0, 180},
                       {-8, 0, 180}, {-8, 0, 270}, {-8, 0, 360}};

const std::vector<sensors::Scan3D>& Scans() {
  static const std::vector<sensors::Scan3D> scans = [] {
    std::vector<sensors::Scan3D> out;
    for (std::size_t k = 0; k < std::size(kRoute); ++k) {
      out.push_back(
          SimulatedScan("office", kRoute[k].x_m, kRoute[k].y_m, kRoute[k].yaw_deg, 300 + k));
    }
    return out;
  }();
  return scans;
}

// T_map_base of scan k: the map is the first scan's base_link.
Eigen::Isometry3d Truth(std::size_t k) {
  return Scans()[0].T_world_base.inverse() * Scans()[k].T_world_base;
}

MapConfig Config(bool loops) {
  MapConfig config;
  config.sensor_base = sensors::MountConfig{}.BaseToLaser(0.0).translation().cast<float>();
  config.loop_closure.enabled = loops;
  return config;
}

// Merges the route with odometry that slips: each step's true motion lengthened by 3 % and turned
// by 1 deg per metre, bounded to twice that plus 2 cm / 0.2 deg.
MapBuilder Merge(bool loops) {
  MapBuilder builder(Config(loops));
  std::size_t last = 0;
  for (std::size_t k = 0; k < Scans().size(); ++k) {
    std::optional<Eigen::Isometry3d> odometry;
    std::optional<GuessUncertainty> bound;
    if (k > 0) {
      const Eigen::Isometry3d motion = Truth(last).inverse() * Truth(k);
      const double length = motion.translation().norm();
      Eigen::Isometry3d slipped = motion;
      slipped.translation() *= 1.03;
      slipped.rotate(Eigen::AngleAxisd(length * M_PI / 180, Eigen::Vector3d::UnitZ()));
      odometry = builder.trajectory().back().T_map_base * slipped;
      bound = GuessUncertainty{2 * 0.03 * length + 0.02, 2 * length + 0.2};
    }
    Result<MergeStep> step = builder.Add(CloudFromScan(Scans()[k]), odometry, bound);
    EXPECT_TRUE(step) << step.error().message;
    if (step && step->merged) last = k;
  }
  return builder;
}

double FinalError(const MapBuilder& builder) {
  const TrajectoryPose& last = builder.trajectory().back();
  return ComparePoses(last.T_map_base, Truth(last.scan_index)).translation_m;
}

PointCloud Sorted(PointCloud c) {
  std::sort(c.begin(), c.end(), [](const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  });
  return c;
}

TEST(LoopClosure, AnOfficeRoundTripClosesLoopsNoneWrongAndEndsNoWorse) {
  const MapBuilder plain = Merge(false);
  const MapBuilder looped = Merge(true);
  ASSERT_EQ(looped.trajectory().size(), Scans().size());
  ASSERT_EQ(plain.trajectory().size(), Scans().size());
  EXPECT_EQ(plain.loop_closures().registered, 0u);

  const LoopClosureCounts c = looped.loop_closures();
  EXPECT_GE(c.accepted, 1u);
  EXPECT_EQ(c.registered, c.registration_failed + c.accepted + c.rejected);
  const std::vector<LoopClosure> loops = looped.accepted_loops();
  ASSERT_EQ(loops.size(), c.accepted);
  for (const LoopClosure& l : loops) {
    EXPECT_TRUE(l.to_scan_index > l.from_scan_index);
    EXPECT_FALSE(IsWrongLoopClosure(l.T_from_to,
                                    Truth(l.from_scan_index).inverse() * Truth(l.to_scan_index)))
        << "loop " << l.from_scan_index << " -> " << l.to_scan_index;
  }
  const double with = FinalError(looped), without = FinalError(plain);
  EXPECT_LE(with, without + kRangeResolutionM) << "with " << with << " m, without " << without;
  std::printf(
      "final pose error: %.4f m with loop closure (%zu accepted, %zu refused, %zu "
      "registrations failed), %.4f m without\n",
      with, c.accepted, c.rejected, c.registration_failed, without);

  // The map cloud is the one the optimised poses give, point for point.
  ScanVoxelMap at_optimum(Config(true).map_voxel_m, false);
  for (const TrajectoryPose& p : looped.trajectory()) {
    at_optimum.Add(CloudFromScan(Scans()[p.scan_index]), p.T_map_base);
  }
  EXPECT_EQ(Sorted(looped.MapCloud()), Sorted(at_optimum.Cloud()));
}

TEST(LoopClosure, AnInformationScaleOutsideItsRangeIsRefusedNamingTheField) {
  MapConfig config = Config(true);
  config.loop_closure.information_scale = 0;
  try {
    MapBuilder builder(config);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("loop_closure.information_scale"), std::string::npos)
        << e.what();
  }
  config.loop_closure.information_scale = 0.1;
  config.loop_closure.max_registrations = 0;
  EXPECT_THROW(MapBuilder{config}, std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mapping
