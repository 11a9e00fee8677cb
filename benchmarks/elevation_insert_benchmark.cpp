// Elevation map insertion rate (issue 4 target: >= 20 M points/s on one core), against a baseline
// in the same run: per-cell std::vector of heights (one allocation per growth, statistics computed
// by re-reading every point), the naive way a map keeps its points.
//
//   benchmarks/elevation_insert_benchmark --benchmark_counters_tabular=true

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"

namespace {

using pitchlab::mapping::ElevationMap;
using pitchlab::mapping::GridGeometry;

constexpr double kCellM = 0.1;
constexpr int kSide = 1024;  // 102.4 m square map

// A scan-like cloud: 200 lines of 361 beams sweeping the ground around (0, 0) out to 30 m, in
// scan order (coherent), with hilly heights and 5 mm noise; repeated over 14 poses (~1 M points).
std::vector<Eigen::Vector3f> ScanLikeCloud() {
  std::mt19937 rng(42);
  std::normal_distribution<float> noise(0.0f, 0.005f);
  std::vector<Eigen::Vector3f> pts;
  for (int pose = 0; pose < 14; ++pose) {
    const float ox = -30.0f + 4.5f * pose, oy = 2.0f * std::sin(pose);
    for (int line = 0; line < 200; ++line) {
      const float range = 1.0f + 29.0f * line / 199.0f;
      for (int beam = 0; beam < 361; ++beam) {
        const float a = static_cast<float>(M_PI) * (beam / 360.0f - 0.5f);
        const float x = ox + range * std::cos(a), y = oy + range * std::sin(a);
        pts.emplace_back(x, y, 0.5f * std::sin(0.2f * x) * std::cos(0.15f * y) + noise(rng));
      }
    }
  }
  return pts;
}

const std::vector<Eigen::Vector3f>& Cloud() {
  static const std::vector<Eigen::Vector3f> cloud = ScanLikeCloud();
  return cloud;
}

GridGeometry Geometry() {
  return GridGeometry::FromArea(-51.2, -51.2, kSide * kCellM, kSide * kCellM, kCellM);
}

void BM_ElevationInsertPoints(benchmark::State& state) {
  const auto& cloud = Cloud();
  ElevationMap map(Geometry());
  for (auto _ : state) {
    benchmark::DoNotOptimize(map.InsertPoints(cloud.data(), cloud.size()));
  }
  state.counters["points_per_s"] =
      benchmark::Counter(double(cloud.size()) * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["bytes_per_cell"] = double(ElevationMap::kBytesPerCell);
}
BENCHMARK(BM_ElevationInsertPoints)->Unit(benchmark::kMillisecond);

void BM_ElevationInsertScanWithClearanceRays(benchmark::State& state) {
  const auto& cloud = Cloud();
  ElevationMap map(Geometry());
  for (auto _ : state) {
    // Each 72k-point block is one scan seen from its pose, the laser 0.55 m up.
    for (std::size_t first = 0; first < cloud.size(); first += 200 * 361) {
      const int pose = static_cast<int>(first / (200 * 361));
      const Eigen::Vector3f origin(-30.0f + 4.5f * pose, 2.0f * std::sin(pose), 0.55f);
      benchmark::DoNotOptimize(map.InsertScan(cloud.data() + first, 200 * 361, origin));
    }
  }
  state.counters["points_per_s"] =
      benchmark::Counter(double(cloud.size()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ElevationInsertScanWithClearanceRays)->Unit(benchmark::kMillisecond);

// Baseline: keep every height in a per-cell vector, then compute mean and std by re-reading.
void BM_BaselinePerCellVectors(benchmark::State& state) {
  const auto& cloud = Cloud();
  const GridGeometry g = Geometry();
  for (auto _ : state) {
    std::vector<std::vector<float>> cells(g.cell_count());
    for (const Eigen::Vector3f& p : cloud) {
      const auto c = g.IndexOf(p.x(), p.y());
      if (g.Contains(c)) cells[g.Linear(c)].push_back(p.z());
    }
    double checksum = 0;
    for (const auto& v : cells) {
      if (v.empty()) continue;
      double s = 0, s2 = 0;
      for (float z : v) s += z;
      const double mean = s / v.size();
      for (float z : v) s2 += (z - mean) * (z - mean);
      checksum += mean + std::sqrt(s2 / v.size());
    }
    benchmark::DoNotOptimize(checksum);
  }
  state.counters["points_per_s"] =
      benchmark::Counter(double(cloud.size()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BaselinePerCellVectors)->Unit(benchmark::kMillisecond);

void BM_ElevationComputeLayers(benchmark::State& state) {
  const auto& cloud = Cloud();
  ElevationMap map(Geometry());
  (void)map.InsertPoints(cloud.data(), cloud.size());
  for (auto _ : state) benchmark::DoNotOptimize(pitchlab::mapping::ComputeLayers(map));
  state.counters["cells_per_s"] = benchmark::Counter(
      double(map.geometry().cell_count()) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ElevationComputeLayers)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
