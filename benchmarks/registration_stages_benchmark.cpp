// What a stop's registration costs in a mission, split as the mission splits it: the target made
// beside the drive (RegistrationTarget::Prepare: the map's voxel grids, the ICP target's hashes and
// normals, the feature cloud's normals and FPFH) and the registration of the new scan against it
// (the scan's side, feature matching, consensus, ICP, checks). The scans are simulated in the urban
// world as a mission sees them (the measured LMS200 model, the default config): two scans 2.5 m
// apart merged as the map, the third registered to it with odometry 0.2 m / 2 deg off.
//
//   build/benchmarks/registration_stages_benchmark --benchmark_repetitions=5 \
//       --benchmark_report_aggregates_only=true
//
// Compare two builds by running both alternately: on a shared machine the minimum of repetitions
// is the figure that compares code, not the machine's moments.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace {

using pitchlab::mapping::PointCloud;
using pitchlab::mapping::RegistrationConfig;
using pitchlab::mapping::RegistrationPrior;
using pitchlab::mapping::RegistrationTarget;

struct Scans {
  PointCloud map;           // two scans in the first's base frame
  Eigen::Vector3f map_sensor;
  PointCloud source;        // the third, in its own base frame
  Eigen::Vector3f source_sensor;
  Eigen::Isometry3d T_map_source;  // the truth
};

pitchlab::sensors::Scan3D ScanAt(pitchlab::sim::SimRig& rig, double x, double y, double yaw_deg) {
  auto pose = rig.PlaceRobot(x, y, yaw_deg * M_PI / 180.0);
  if (!pose) {
    std::fprintf(stderr, "registration_stages_benchmark: %s\n", pose.error().message.c_str());
    std::exit(1);
  }
  auto scan = rig.Acquire();
  if (!scan) {
    std::fprintf(stderr, "registration_stages_benchmark: %s\n", scan.error().message.c_str());
    std::exit(1);
  }
  return *scan;
}

const Scans& UrbanScans() {
  static const Scans scans = [] {
    pitchlab::sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/urban.xml",
                              pitchlab::sim::SimRigConfig{});
    const auto a = ScanAt(rig, 0.0, 0.0, 0.0), b = ScanAt(rig, 2.5, 0.0, 0.0),
               c = ScanAt(rig, 5.0, 0.3, 5.0);
    Scans s;
    s.map = pitchlab::mapping::CloudFromScan(a);
    const Eigen::Isometry3f T_ab = (a.T_world_base.inverse() * b.T_world_base).cast<float>();
    for (const Eigen::Vector3f& p : pitchlab::mapping::CloudFromScan(b)) s.map.push_back(T_ab * p);
    s.map_sensor = a.sensor_origin.value_or(Eigen::Vector3d(0.1, 0, 0.55)).cast<float>();
    s.source = pitchlab::mapping::CloudFromScan(c);
    s.source_sensor = c.sensor_origin.value_or(Eigen::Vector3d(0.1, 0, 0.55)).cast<float>();
    s.T_map_source = a.T_world_base.inverse() * c.T_world_base;
    return s;
  }();
  return scans;
}

void BM_PrepareTarget(benchmark::State& state) {
  const Scans& s = UrbanScans();
  const RegistrationConfig config;
  for (auto _ : state) {
    RegistrationTarget target(s.map, s.map_sensor);
    target.Prepare(config);
    benchmark::DoNotOptimize(target);
  }
  state.counters["map_points"] = static_cast<double>(s.map.size());
}
BENCHMARK(BM_PrepareTarget)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RegisterToPreparedTarget(benchmark::State& state) {
  const Scans& s = UrbanScans();
  const RegistrationConfig config;
  RegistrationPrior prior;
  const Eigen::Isometry3d off = Eigen::Translation3d(0.15, -0.13, 0.0) *
                                Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ());
  prior.odometry = s.T_map_source * off;
  prior.source_sensor = s.source_sensor;
  prior.target_sensor = s.map_sensor;
  bool ok = true;
  for (auto _ : state) {
    state.PauseTiming();  // a fresh target each time: what ICP reads of it is made as it reads
    RegistrationTarget target(s.map, s.map_sensor);
    target.Prepare(config);
    state.ResumeTiming();
    auto result = pitchlab::mapping::Register(target, s.source, prior, config);
    ok = ok && result && result->success;
    benchmark::DoNotOptimize(result);
  }
  if (!ok) state.SkipWithError("the registration failed: the benchmark measures a success");
  state.counters["source_points"] = static_cast<double>(s.source.size());
}
BENCHMARK(BM_RegisterToPreparedTarget)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
