// Re-posing the maps after a pose-graph optimisation (issue 20 target: 40 scans <= 0.2 s, map
// cloud and elevation map): 40 simulated scans along the office's corridor (the seed pattern,
// 361 x 200 readings, kept within the mission's 10 m map range, MissionConfig::map_range_m; the
// map frame's poses are the stops' shifted to start near the origin), all moved to new poses at
// once: ScanVoxelMap::Repose (the map cloud from the scans kept at the 0.1 m map voxel, as
// MapBuilder keeps them) and PerScanElevationMap::Repose (every scan re-inserted with its rays,
// then the contributions combined). Iterations alternate between two pose sets 1 cm / 0.1 deg
// apart, so every scan moves every time. The elevation map is timed with the scans as cast
// (first argument 0) and with the 2 cm voxel copies MapBuilder's loop closure keeps (20,
// LoopClosureConfig::scan_voxel_m: half the points of a simulated office scan within 10 m, 28-37k
// of 67k), re-inserted on one thread or up to two (second argument,
// PerScanElevationMap::set_threads).
//
//   build/benchmarks/repose_benchmark --benchmark_counters_tabular=true --benchmark_repetitions=5
//
// Times are wall and the process's CPU (all threads: the elevation map re-inserts scans on more
// than one). The label of the elevation map's runs is a fingerprint of the map after a re-pose to
// each of the two pose sets (FNV-1a over every cell's bytes): a change that keeps the maps the
// same bit for bit keeps it.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "pitchlab/mapping/per_scan_elevation_map.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mapping/scan_voxel_map.hpp"
#include "pitchlab/sensors/scan3d.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace {

using pitchlab::mapping::PerScanElevationMap;
using pitchlab::mapping::PointCloud;
using pitchlab::mapping::ScanVoxelMap;

constexpr int kScans = 40;
constexpr double kMapRangeM = 10.0;  // MissionConfig::map_range_m
constexpr double kDeg = 3.14159265358979323846 / 180;
// Where the default mount puts the laser in base_link.
const Eigen::Vector3f kSensorBase =
    pitchlab::sensors::MountConfig{}.BaseToLaser(0.0).translation().cast<float>();

// The simulated office's corridor (y in [-1, 1]), a stop every 0.45 m from x = -9 m, each scan
// the default SimRig's (the seed pattern), in base_link, within the map range.
PointCloud Scan(pitchlab::sim::SimRig& rig, int k) {
  auto placed =
      rig.PlaceRobot(-9.0 + 0.45 * k, 0.3 * std::sin(0.5 * k), 10 * std::sin(0.3 * k) * kDeg);
  if (!placed) throw std::runtime_error("office: " + placed.error().message);
  auto scan = rig.Acquire();
  if (!scan) throw std::runtime_error("office: " + scan.error().message);
  PointCloud cloud;
  for (const pitchlab::sensors::ScanPoint& p : scan->points) {
    if (p.range_m <= kMapRangeM) cloud.emplace_back(p.x, p.y, p.z);
  }
  return cloud;
}

// Stop k's pose in the map, `shift` [m] (and 10 * shift [deg]) off.
Eigen::Isometry3d StopPose(int k, double shift) {
  Eigen::Isometry3d T = pitchlab::mapping::PoseFromXyzRpyDeg(0.45 * k, 0.3 * std::sin(0.5 * k), 0,
                                                             0, 0, 10 * std::sin(0.3 * k));
  T.translation() += Eigen::Vector3d(shift, shift, 0);
  T.rotate(Eigen::AngleAxisd(10 * shift * kDeg, Eigen::Vector3d::UnitZ()));
  return T;
}

struct Fixture {
  std::vector<PointCloud> scans;
  Fixture() {
    pitchlab::sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/office.xml", {});
    for (int k = 0; k < kScans; ++k) scans.push_back(Scan(rig, k));
  }
};
const Fixture& Scans() {
  static const Fixture f;
  return f;
}

// The office (20 x 15 m) in the map frame of the first stop, with a margin.
pitchlab::mapping::GridGeometry Area() {
  return pitchlab::mapping::GridGeometry::FromArea(-3, -9, 24, 18, 0.1);
}

void BM_ReposeMapCloud(benchmark::State& state) {
  ScanVoxelMap map(0.1, true);  // MapConfig::map_voxel_m
  std::vector<Eigen::Isometry3d> poses[2];
  for (int k = 0; k < kScans; ++k) {
    map.Add(Scans().scans[k], StopPose(k, 0));
    poses[0].push_back(StopPose(k, 0.01));
    poses[1].push_back(StopPose(k, 0));
  }
  int flip = 0;
  for (auto _ : state) {
    if (!map.Repose(poses[flip])) state.SkipWithError("repose failed");
    flip ^= 1;
  }
  state.counters["scans"] = kScans;
  state.counters["voxels"] = static_cast<double>(map.Cloud().size());
}
BENCHMARK(BM_ReposeMapCloud)->Unit(benchmark::kMillisecond);

// FNV-1a over the bytes of every cell (CellStats has no padding: 4 + 14 x 4 bytes).
std::uint32_t Fingerprint(const pitchlab::mapping::ElevationMap& map) {
  static_assert(sizeof(pitchlab::mapping::CellStats) == 60, "no padding in CellStats");
  std::uint32_t h = 2166136261u;
  for (const pitchlab::mapping::CellStats& c : map.cells()) {
    unsigned char bytes[sizeof c];
    std::memcpy(bytes, &c, sizeof c);
    for (unsigned char b : bytes) h = (h ^ b) * 16777619u;
  }
  return h;
}

void BM_ReposeElevationMap(benchmark::State& state) {
  const double voxel_m = state.range(0) / 1000.0;  // [mm] -> [m]; 0: the scans as cast
  PerScanElevationMap map(Area());
  map.set_threads(static_cast<unsigned>(state.range(1)));
  std::vector<std::pair<std::size_t, Eigen::Isometry3d>> poses[2];
  std::size_t points = 0;
  for (int k = 0; k < kScans; ++k) {
    const PointCloud scan = voxel_m > 0
                                ? pitchlab::mapping::VoxelDownsample(Scans().scans[k], voxel_m)
                                : Scans().scans[k];
    points += scan.size();
    if (!map.Insert(k, scan, kSensorBase, StopPose(k, 0))) state.SkipWithError("insert failed");
    poses[0].emplace_back(k, StopPose(k, 0.01));
    poses[1].emplace_back(k, StopPose(k, 0));
  }
  int flip = 0;
  for (auto _ : state) {
    const auto moved = map.Repose(poses[flip]);
    if (!moved || *moved != kScans) state.SkipWithError("not every scan moved");
    flip ^= 1;
  }
  std::uint32_t fingerprint[2];
  for (int k = 0; k < 2; ++k) {
    if (!map.Repose(poses[k])) state.SkipWithError("repose failed");
    fingerprint[k] = Fingerprint(map.map());
  }
  char label[32];
  std::snprintf(label, sizeof label, "map %08x/%08x", fingerprint[0], fingerprint[1]);
  state.SetLabel(label);
  state.counters["scans"] = kScans;
  state.counters["points_per_scan"] = static_cast<double>(points) / kScans;
}
BENCHMARK(BM_ReposeElevationMap)
    ->ArgsProduct({{0, 20}, {1, 2}})
    ->ArgNames({"voxel_mm", "threads"})
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
