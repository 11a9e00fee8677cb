// Test fixture, not a test: builds the small synthetic run (a map, a cloud, trajectories) that
// run_report_test and report_browser_test write a report from and assert on.
#include "synthetic_report.hpp"

#include <cmath>
#include <stdexcept>

#include "pitchlab/mission/map_figure.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "report_scene.hpp"

namespace pitchlab::mission::testing {
namespace {

constexpr double kCell_m = 0.1;
constexpr double kSlope = 0.05;  // the plane rises 5 cm per metre along x

bool InBlock(double x, double y) { return x > 3 && x < 5 && y > 2 && y < 6; }

double Height(double x, double y) { return kSlope * x + (InBlock(x, y) ? 0.5 : 0.0); }

mapping::ElevationLayers Layers(int side) {
  mapping::ElevationLayers L;
  L.geometry = mapping::GridGeometry::FromArea(-1, -1, side * kCell_m, side * kCell_m, kCell_m);
  const std::size_t n = L.geometry.cell_count();
  L.state.assign(n, mapping::CellState::kObserved);
  L.mean_z.assign(n, 0.0f);
  for (int j = 0; j < L.geometry.size_y; ++j) {
    for (int i = 0; i < L.geometry.size_x; ++i) {
      const Eigen::Vector2d c = L.geometry.CenterOf({i, j});
      const std::size_t k = L.geometry.Linear({i, j});
      L.mean_z[k] = static_cast<float>(Height(c.x(), c.y()));
      if (c.y() > 0.7 * side * kCell_m) L.state[k] = mapping::CellState::kUnknown;  // unseen
    }
  }
  return L;
}

planning::TraversabilityGrid Grid(const mapping::ElevationLayers& L) {
  planning::TraversabilityGrid T;
  T.geometry = L.geometry;
  const std::size_t n = L.geometry.cell_count();
  T.blocked.assign(n, planning::Blocked::kFree);
  T.z_m = L.mean_z;
  T.enter_cost.assign(n, 1.0f);
  for (int j = 0; j < L.geometry.size_y; ++j) {
    for (int i = 0; i < L.geometry.size_x; ++i) {
      const Eigen::Vector2d c = L.geometry.CenterOf({i, j});
      const std::size_t k = L.geometry.Linear({i, j});
      if (L.state[k] == mapping::CellState::kUnknown) T.blocked[k] = planning::Blocked::kUnknown;
      if (InBlock(c.x(), c.y()) != InBlock(c.x() + kCell_m, c.y()) ||
          InBlock(c.x(), c.y()) != InBlock(c.x(), c.y() + kCell_m)) {
        T.blocked[k] = planning::Blocked::kStep;
      }
    }
  }
  return T;
}

void WritePicture(const mapping::ElevationLayers& L, const std::filesystem::path& file,
                  int width_px = 500) {
  const MapWindow window = ExploredWindow(L, {});
  mapping::ImageOptions options;
  options.pixels_per_cell = FigurePixelsPerCell(L.geometry, window, width_px);
  const auto [lo, hi] = mapping::ElevationRampRange(L);
  FigureMarks marks{Eigen::Vector2d(0, 0), Eigen::Vector2d(6, 4),
                    ColourBar{lo, hi, mapping::ElevationRamp}};
  const mapping::RgbImage figure =
      ComposeMapFigure(mapping::RenderElevationImage(L, options), L.geometry, window, marks);
  if (!mapping::WritePng(figure, file.string()))
    throw std::runtime_error("cannot write " + file.string());
}

}  // namespace

RunReportInput SyntheticReport(const std::filesystem::path& folder, std::size_t cloud_points,
                               int side) {
  std::filesystem::create_directories(folder / "stops/000");
  const mapping::ElevationLayers L = Layers(side);
  WritePicture(L, folder / "elevation.png");
  WritePicture(L, folder / "stops/000/map.png");
  WritePicture(L, folder / "stops/000/map_small.png", 240);
  RunReportInput in;
  in.metrics = {{"success", false},
                {"reason", kSyntheticReason},
                {"world", "synthetic"},
                {"robot", "p3at"},
                {"seed", 7},
                {"stops", 1},
                {"distance_m", 3.14159},
                {"sim_time_s", 42.0},
                {"hazard_cells_crossed", 0},
                {"forbidden_cells_crossed", 0},
                {"closest_approach_to_forbidden_m", 1.25}};
  in.config_yaml = "seed: 7\n";
  in.folder = folder;
  in.pictures = {{"elevation.png", "estimated elevation map", "A tilted plane with a block."}};
  std::vector<Eigen::Vector2d> arc;
  Scene3D scene;
  for (int k = 0; k <= 100; ++k) {
    const double a = M_PI / 2 * k / 100;
    arc.emplace_back(3 * std::sin(a), 3 - 3 * std::cos(a));
    scene.true_m.emplace_back(arc.back().x(), arc.back().y(), Height(arc.back().x(), 0) + 0.1);
    scene.estimated_m.push_back(scene.true_m.back() + Eigen::Vector3d(0.05, 0.02, 0));
  }
  in.trajectories = {{"true", "#1e50ff", arc, true}};
  in.markers = {{"start", "#111111", {0, 0}}, {"goal", "#d01010", {6, 4}}};
  in.stop_header = {"stop", "t [s]"};
  in.stop_rows = {{"0", "0.0"}};
  in.stop_pictures = {{"stops/000/map_small.png", "stop 0", "", "stops/000/map.png"}};
  // The cloud: points on the plane and on the block's faces, a deterministic spiral of samples.
  for (std::size_t k = 0; k < cloud_points; ++k) {
    const double u = std::fmod(k * 0.618033988749895, 1.0), v = double(k) / cloud_points;
    const double x = -1 + u * side * kCell_m * 0.99, y = -1 + v * side * kCell_m * 0.7;
    scene.cloud_m.emplace_back(x, y, Height(x, y) + 0.01 * std::sin(k));
  }
  scene.stops_m = {scene.estimated_m.front()};
  scene.start_m = scene.true_m.front();
  scene.goal_m = {6, 4, Height(6, 4)};
  scene.surface = BuildSurface(L, Grid(L), ExploredWindow(L, {}));
  in.scene_json = SceneJson(scene);
  in.files = {"elevation.png", "metrics.json", "report.html", "stops/000/map.png"};
  return in;
}

}  // namespace pitchlab::mission::testing
