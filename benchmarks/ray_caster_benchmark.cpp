// Ray casters on a full LMS200 3D scan (361 beams x 200 lines = 72,200 rays) from 0.5 m above the
// ground: Embree in coherent packets, Embree one rtcIntersect1 per ray (baseline) and mj_ray, on an
// urban and a terrain scene. One iteration = one full scan. Targets: Embree packets >= 20 M rays/s
// on one core (<= 4 ms per scan) and >= 100x mj_ray on the terrain.
// The scenes are PITCHLAB_WORLDS_DIR/{urban,terrain}.xml when generated, else inline look-alikes.

#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pitchlab/sensors/ray_caster.hpp"

namespace {

namespace fs = std::filesystem;
using pitchlab::sensors::RayCaster;
using pitchlab::sensors::RayCasterOptions;

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr float kMaxRange_m = 81.91f;  // LMS200 cm mode
constexpr double kLaserHeight_m = 0.5;

// Inline urban look-alike: 60 x 60 m ground, seeded blocks of buildings, poles, bollards, trees.
std::string UrbanMjcf() {
  std::mt19937 rng(20120917);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::ostringstream xml;
  xml << "<mujoco><worldbody><geom type='plane' size='30 30 1'/>\n";
  for (int i = 0; i < 120; ++i) {  // buildings, kept 4 m clear of the origin
    double x = -28 + 56 * u(rng), y = -28 + 56 * u(rng);
    if (std::abs(x) < 6 && std::abs(y) < 6) x += 12;
    xml << "<geom type='box' pos='" << x << ' ' << y << " 5' euler='0 0 " << 90 * u(rng)
        << "' size='" << 1 + 3 * u(rng) << ' ' << 1 + 3 * u(rng) << ' ' << 2 + 8 * u(rng)
        << "'/>\n";
  }
  for (int i = 0; i < 150; ++i) {
    const double x = -28 + 56 * u(rng), y = -28 + 56 * u(rng);
    if (std::hypot(x, y) < 2) continue;
    if (i % 3 == 0) {
      xml << "<geom type='cylinder' pos='" << x << ' ' << y << " 3' size='0.1 3'/>\n";
    } else if (i % 3 == 1) {
      xml << "<geom type='capsule' pos='" << x << ' ' << y << " 0.5' size='0.15 0.35'/>\n";
    } else {
      xml << "<geom type='sphere' pos='" << x << ' ' << y << " 3' size='1.2'/>"
          << "<geom type='cylinder' pos='" << x << ' ' << y << " 1' size='0.2 1'/>\n";
    }
  }
  xml << "</worldbody></mujoco>\n";
  return xml.str();
}

// Inline terrain look-alike: a 60 x 60 m, 601 x 601 heightfield of seeded hills.
std::string TerrainMjcf(const fs::path& dir) {
  constexpr int kN = 601;
  std::ofstream out(dir / "hills.bin", std::ios::binary);
  const std::int32_t dims[2] = {kN, kN};
  out.write(reinterpret_cast<const char*>(dims), sizeof(dims));
  for (int r = 0; r < kN; ++r) {
    for (int c = 0; c < kN; ++c) {
      const double x = 60.0 * c / (kN - 1), y = 60.0 * r / (kN - 1);
      const float z = static_cast<float>(0.5 + 0.25 * std::sin(0.31 * x) * std::cos(0.23 * y) +
                                         0.15 * std::sin(0.9 * x + 0.7 * y) +
                                         0.05 * std::sin(3.1 * x) * std::sin(2.7 * y));
      out.write(reinterpret_cast<const char*>(&z), sizeof(z));
    }
  }
  return "<mujoco><asset><hfield name='hills' file='hills.bin' size='30 30 6 1'/></asset>"
         "<worldbody><geom type='hfield' hfield='hills' pos='0 0 -3'/></worldbody></mujoco>";
}

// A loaded world and the ray pattern of one full scan from its start pose.
struct Scene {
  mjModel* model = nullptr;
  mjData* data = nullptr;
  std::string source;
  std::vector<float> origins, directions;
  std::size_t rays() const { return origins.size() / 3; }
};

mjModel* Load(const fs::path& file) {
  char error[1000] = "";
  mjModel* model = mj_loadXML(file.c_str(), nullptr, error, sizeof(error));
  if (model == nullptr) throw std::runtime_error("loading " + file.string() + ": " + error);
  return model;
}

// Start pose: the world's `pitchlab:default_start` (x y yaw_deg) or the origin, 0.5 m above the
// surface found by mj_ray straight down. Then 361 x 200 LMS200 directions (Eq. 1).
void MakeScanPattern(Scene* s) {
  double x = 0, y = 0, yaw = 0;
  const int start = mj_name2id(s->model, mjOBJ_NUMERIC, "pitchlab:default_start");
  if (start >= 0 && s->model->numeric_size[start] >= 3) {
    const mjtNum* v = s->model->numeric_data + s->model->numeric_adr[start];
    x = v[0];
    y = v[1];
    yaw = v[2] * kDegToRad;
  }
  const mjtNum top[3] = {x, y, 200.0}, down[3] = {0, 0, -1};
  int geom = -1;
  const mjtNum drop = mj_ray(s->model, s->data, top, down, nullptr, 1, -1, &geom);
  const double z = (drop >= 0 ? top[2] - drop : 0.0) + kLaserHeight_m;
  for (int line = 0; line < 200; ++line) {
    const double pitch = (-40.0 + 100.0 * line / 199) * kDegToRad;
    for (int beam = 0; beam < 361; ++beam) {
      const double bearing = (-90.0 + 0.5 * beam) * kDegToRad + yaw;
      s->origins.insert(s->origins.end(), {float(x), float(y), float(z)});
      s->directions.insert(s->directions.end(),
                           {float(std::cos(pitch) * std::cos(bearing)),
                            float(std::cos(pitch) * std::sin(bearing)), float(std::sin(pitch))});
    }
  }
}

const Scene& GetScene(const std::string& name) {
  static std::map<std::string, Scene> scenes;
  auto it = scenes.find(name);
  if (it != scenes.end()) return it->second;
  Scene s;
  const fs::path world = fs::path(PITCHLAB_WORLDS_DIR) / (name + ".xml");
  if (fs::exists(world) && fs::file_size(world) > 0) {
    s.model = Load(world);
    s.source = world.string();
  } else {
    const fs::path dir = fs::temp_directory_path() / ("pitchlab_ray_bench_" + name);
    fs::create_directories(dir);
    std::ofstream(dir / "world.xml") << (name == "terrain" ? TerrainMjcf(dir) : UrbanMjcf());
    s.model = Load(dir / "world.xml");
    s.source = "inline " + name;
  }
  s.data = mj_makeData(s.model);
  mj_forward(s.model, s.data);
  MakeScanPattern(&s);
  return scenes.emplace(name, std::move(s)).first->second;
}

enum class Caster { kEmbreePackets, kEmbreeSingle, kMjRay };

void BM_FullScan(benchmark::State& state, const std::string& scene_name, Caster kind) {
  const Scene& scene = GetScene(scene_name);
  RayCasterOptions options;
  options.coherent_packets = kind == Caster::kEmbreePackets;
  const std::unique_ptr<RayCaster> caster =
      kind == Caster::kMjRay
          ? pitchlab::sensors::MakeMujocoRayCaster(scene.model, scene.data, options)
          : pitchlab::sensors::MakeEmbreeRayCaster(scene.model, scene.data, options);
  const std::size_t n = scene.rays();
  std::vector<float> range(n);
  std::vector<int> geom(n);
  for (auto _ : state) {
    caster->Cast(scene.origins.data(), scene.directions.data(), n, kMaxRange_m, range.data(),
                 geom.data());
    benchmark::DoNotOptimize(range.data());
    benchmark::ClobberMemory();
  }
  std::size_t hits = 0;
  for (float r : range) hits += std::isfinite(r) ? 1 : 0;
  state.counters["rays_per_s"] =
      benchmark::Counter(double(n), benchmark::Counter::kIsIterationInvariantRate);
  // Seconds per full scan (printed with an SI prefix, e.g. 1.2ms).
  state.counters["time_per_scan"] = benchmark::Counter(
      1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["hit_fraction"] = double(hits) / double(n);
  state.SetLabel(scene.source);
}

// mj_ray on a 601 x 601 heightfield takes seconds per scan: a few iterations only.
BENCHMARK_CAPTURE(BM_FullScan, urban_embree_packets, std::string("urban"), Caster::kEmbreePackets)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FullScan, urban_embree_rtcIntersect1, std::string("urban"),
                  Caster::kEmbreeSingle)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FullScan, urban_mj_ray, std::string("urban"), Caster::kMjRay)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK_CAPTURE(BM_FullScan, terrain_embree_packets, std::string("terrain"),
                  Caster::kEmbreePackets)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FullScan, terrain_embree_rtcIntersect1, std::string("terrain"),
                  Caster::kEmbreeSingle)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FullScan, terrain_mj_ray, std::string("terrain"), Caster::kMjRay)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);

// Building the Embree caster for a world, as every run does once at set-up (and once more for its
// ground truth unless cached): CPU of all threads, Embree's builders being TBB's.
void BM_BuildEmbreeCaster(benchmark::State& state, const std::string& scene_name) {
  const Scene& scene = GetScene(scene_name);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        pitchlab::sensors::MakeEmbreeRayCaster(scene.model, scene.data, RayCasterOptions{}));
  }
  state.SetLabel(scene.source);
}
BENCHMARK_CAPTURE(BM_BuildEmbreeCaster, urban, std::string("urban"))
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();
BENCHMARK_CAPTURE(BM_BuildEmbreeCaster, terrain, std::string("terrain"))
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime();

}  // namespace

BENCHMARK_MAIN();
