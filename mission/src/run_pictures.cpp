#include "run_pictures.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <stdexcept>

#include "pitchlab/mission/map_figure.hpp"
#include "pitchlab/mission/traversability_image.hpp"
#include "pitchlab/planning/path_io.hpp"
#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::mission {
namespace {

void Write(const mapping::RgbImage& image, const std::filesystem::path& file) {
  if (Result<void> r = mapping::WritePng(image, file.string()); !r) {
    throw std::runtime_error(r.error().message);
  }
}

// A 3 px line through the map points, on a picture rendered from `g`.
void DrawPolyline(mapping::RgbImage& image, const mapping::GridGeometry& g,
                  const std::vector<Eigen::Vector2d>& points_m, std::uint8_t r, std::uint8_t gr,
                  std::uint8_t b) {
  for (std::size_t k = 1; k < points_m.size(); ++k) {
    const Eigen::Vector2d a =
        mapping::MapToPixel(g, image, points_m[k - 1].x(), points_m[k - 1].y());
    const Eigen::Vector2d c = mapping::MapToPixel(g, image, points_m[k].x(), points_m[k].y());
    const int steps = std::max(1, static_cast<int>(std::ceil((c - a).norm())));
    for (int s = 0; s <= steps; ++s) {
      const Eigen::Vector2d p = a + (c - a) * (double(s) / steps);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          image.Set(static_cast<int>(p.x()) + dx, static_cast<int>(p.y()) + dy, r, gr, b);
    }
  }
}

// A 3 px ring of `radius_m` about each of `places_m` [m], one for each group of places within
// twice the radius of the first: an unsafe stretch is found on a whole map's picture at a glance.
void RingPlaces(mapping::RgbImage& image, const mapping::GridGeometry& g,
                const std::vector<Eigen::Vector2d>& places_m, double radius_m, std::uint8_t r,
                std::uint8_t gr, std::uint8_t b) {
  std::vector<Eigen::Vector2d> centres;
  for (const Eigen::Vector2d& p : places_m) {
    if (std::any_of(centres.begin(), centres.end(),
                    [&](const Eigen::Vector2d& c) { return (c - p).norm() < 2 * radius_m; })) {
      continue;
    }
    centres.push_back(p);
  }
  const double radius_px = radius_m / g.cell_m * image.pixels_per_cell;
  const int reach = static_cast<int>(std::ceil(radius_px)) + 2;
  for (const Eigen::Vector2d& c : centres) {
    const Eigen::Vector2d at = mapping::MapToPixel(g, image, c.x(), c.y());
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx)
        if (std::abs(std::hypot(dx, dy) - radius_px) <= 1.5) {
          image.Set(static_cast<int>(at.x()) + dx, static_cast<int>(at.y()) + dy, r, gr, b);
        }
  }
}

// A forbidden crossing's ring: 1 m across, twice the P3-AT's length, found at a glance on a whole
// map's picture and still pointing at the 0.1 m cells crossed.
constexpr double kCrossingRing_m = 0.5;

// The part of `map` a stop's picture shows, with what its layers there depend on. Made from the
// whole map every stop, the layers and the image were 45 % of a terrain run's page faults (641 x
// 641 cells, a few percent of them seen), on the thread beside the robot. The picture's window
// holds the known cells and `points_m` (ExploredWindow); a known cell has a point or a ray over
// it, and its layers read cells up to a drop's flood (LayerConfig::drop_flood_m) away, all
// unknown beyond the region: its layers and pixels are the whole map's. The region's corner
// lies on a multiple of 8 cells, a pair of the unknown cells' 4-cell checkerboard squares.
mapping::ElevationMap PictureRegion(const mapping::ElevationMap& map,
                                    const std::vector<Eigen::Vector2d>& points_m) {
  const mapping::GridGeometry& g = map.geometry();
  int lo_i = g.size_x, lo_j = g.size_y, hi_i = -1, hi_j = -1;
  for (int j = 0; j < g.size_y; ++j) {
    for (int i = 0; i < g.size_x; ++i) {
      const mapping::CellStats& c = map.at({i, j});
      if (!c.known() && !std::isfinite(c.clearance_z)) continue;
      lo_i = std::min(lo_i, i), hi_i = std::max(hi_i, i);
      lo_j = std::min(lo_j, j), hi_j = std::max(hi_j, j);
    }
  }
  if (hi_i < 0 && points_m.empty()) return map;  // the window is then the whole map
  for (const Eigen::Vector2d& p : points_m) {
    const mapping::CellIndex c = g.IndexOf(p.x(), p.y());
    lo_i = std::min(lo_i, c.i), hi_i = std::max(hi_i, c.i);
    lo_j = std::min(lo_j, c.j), hi_j = std::max(hi_j, c.j);
  }
  constexpr int kCheckerboard = 8;
  const int reach = static_cast<int>(
      std::ceil((kPictureWindowMargin_m + mapping::LayerConfig{}.drop_flood_m) / g.cell_m)) + 2;
  lo_i = std::max(0, (lo_i - reach) / kCheckerboard * kCheckerboard);
  lo_j = std::max(0, (lo_j - reach) / kCheckerboard * kCheckerboard);
  hi_i = std::min(g.size_x - 1, hi_i + reach);
  hi_j = std::min(g.size_y - 1, hi_j + reach);
  if (lo_i == 0 && lo_j == 0 && hi_i == g.size_x - 1 && hi_j == g.size_y - 1) return map;
  mapping::GridGeometry region = g;
  region.x_min_m = g.x_min_m + lo_i * g.cell_m;
  region.y_min_m = g.y_min_m + lo_j * g.cell_m;
  region.size_x = hi_i - lo_i + 1;
  region.size_y = hi_j - lo_j + 1;
  std::vector<mapping::CellStats> cells;
  cells.reserve(region.cell_count());
  for (int j = lo_j; j <= hi_j; ++j) {
    const auto row = map.cells().begin() + static_cast<std::ptrdiff_t>(g.Linear({lo_i, j}));
    cells.insert(cells.end(), row, row + region.size_x);
  }
  return mapping::ElevationMap(region, std::move(cells), map.geodetic_origin());
}

// last_plan.png of a failed run: the grid its last plan was made on, that plan, and the run's
// tracks (estimated orange, true blue): where the robot meant to go and where it went.
void WriteLastPlanPicture(RunFolder& folder, const MissionResult& r, const MapWindow& window,
                          const FigureMarks& marks, const std::vector<Eigen::Vector2d>& est,
                          const std::vector<Eigen::Vector2d>& tru) {
  const planning::TraversabilityGrid& grid = r.last_plan_grid;
  const mapping::GridGeometry& g = grid.geometry;
  const auto stop = std::find_if(r.stops.begin(), r.stops.end(),
                                 [&](const StopRecord& s) { return s.index == r.last_plan_stop; });
  if (stop == r.stops.end() || grid.blocked.size() != g.cell_count()) return;
  mapping::ImageOptions options;
  options.pixels_per_cell = FigurePixelsPerCell(g, window);
  mapping::RgbImage image = RenderTraversability(grid, options);
  if (stop->plan) planning::DrawPath(*stop->plan, g, image);
  DrawPolyline(image, g, est, 255, 140, 0);
  DrawPolyline(image, g, tru, 30, 80, 255);
  Write(ComposeMapFigure(image, g, window, marks), folder.File("last_plan.png"));
}

}  // namespace

std::vector<Eigen::Vector2d> TrajectoryXy(const MissionResult& r, bool truth) {
  std::vector<Eigen::Vector2d> xy;
  for (const TrajectorySample& s : r.trajectory) {
    if (!truth) {
      xy.push_back(s.T_world_base_est.translation().head<2>());
    } else if (s.T_world_base_true) {
      xy.push_back(s.T_world_base_true->translation().head<2>());
    }
  }
  return xy;
}

void WriteRunPictures(RunFolder& folder, const RunContext& c, const MissionResult& r,
                      const FinalMap& final_map, const TruthMaps* truth) {
  const mapping::ElevationLayers& layers = final_map.layers;
  const std::vector<Eigen::Vector2d> est = TrajectoryXy(r, false), tru = TrajectoryXy(r, true);
  std::vector<Eigen::Vector2d> keep = est;
  keep.insert(keep.end(), tru.begin(), tru.end());
  keep.push_back(c.start.head<2>());
  keep.push_back(c.goal);
  const MapWindow window = ExploredWindow(layers, keep);
  const mapping::GridGeometry& g = layers.geometry;
  mapping::ImageOptions options;
  options.pixels_per_cell = FigurePixelsPerCell(g, window);
  const FigureMarks marks{c.start.head<2>(), c.goal, std::nullopt};
  FigureMarks height_marks = marks;
  height_marks.colour_bar = HeightBar(layers);

  // The truth's pictures on a thread of their own beside the estimate's: the run waits for its
  // final files, and a second core halves that wait.
  std::future<void> truth_pictures;
  if (truth) {
    truth_pictures = std::async(std::launch::async, [&] {
      const sensors::WorkerThread worker;  // the run's outputs, done beside it
      const mapping::GridGeometry& tg = truth->layers.geometry;
      mapping::ImageOptions truth_options;
      truth_options.pixels_per_cell = FigurePixelsPerCell(tg, window);
      mapping::RgbImage truth_grid = RenderTraversability(truth->grid, truth_options);
      DrawPolyline(truth_grid, tg, tru, 30, 80, 255);
      RingPlaces(truth_grid, tg, truth->forbidden_crossed_at, kCrossingRing_m, 30, 80, 255);
      Write(ComposeMapFigure(truth_grid, tg, window, marks),
            folder.File("truth_traversability.png"));
      mapping::RgbImage truth_image = mapping::RenderElevationImage(truth->layers, truth_options);
      if (truth->optimum) planning::DrawPath(*truth->optimum, tg, truth_image);
      DrawPolyline(truth_image, tg, tru, 30, 80, 255);
      FigureMarks truth_marks = marks;
      truth_marks.colour_bar = HeightBar(truth->layers);
      Write(ComposeMapFigure(truth_image, tg, window, truth_marks),
            folder.File("truth_elevation.png"));
    });
  }
  mapping::RgbImage image = mapping::RenderElevationImage(layers, options);
  for (const StopRecord& s : r.stops) {
    if (s.plan) planning::DrawPath(*s.plan, g, image);
  }
  DrawPolyline(image, g, est, 255, 140, 0);
  DrawPolyline(image, g, tru, 30, 80, 255);
  Write(ComposeMapFigure(image, g, window, height_marks), folder.File("elevation.png"));
  Write(ComposeMapFigure(RenderTraversability(final_map.grid, options), g, window, marks),
        folder.File("traversability.png"));
  if (!r.success && r.last_plan_stop >= 0) WriteLastPlanPicture(folder, r, window, marks, est, tru);
  if (!truth) return;
  truth_pictures.get();
  Write(ComposeMapFigure(
            RenderHazardErrors(truth->scored_estimate, truth->grid, c.start.head<2>(), options), g,
            window, marks),
        folder.File("hazard_errors.png"));
}

mapping::RgbImage Downscale(const mapping::RgbImage& image, int max_width_px) {
  const int f = std::max(1, (image.width + max_width_px - 1) / std::max(1, max_width_px));
  mapping::RgbImage out;
  out.pixels_per_cell = image.pixels_per_cell;
  out.width = image.width / f;
  out.height = image.height / f;
  out.rgb.assign(static_cast<std::size_t>(out.width) * out.height * 3, 0);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int dy = 0; dy < f; ++dy)
          for (int dx = 0; dx < f; ++dx)
            sum +=
                image.rgb[((static_cast<std::size_t>(y) * f + dy) * image.width + x * f + dx) * 3 +
                          c];
        out.rgb[(static_cast<std::size_t>(y) * out.width + x) * 3 + c] =
            static_cast<std::uint8_t>((sum + f * f / 2) / (f * f));
      }
    }
  }
  return out;
}

void WriteStopPictures(RunFolder& folder, const std::string& dir, const StopView& view) {
  const mapping::RgbImage picture = StopPicture(view);
  Write(picture, folder.File(dir + "map.png"));
  Write(Downscale(picture, kThumbnailWidth_px), folder.File(dir + "map_small.png"));
}

namespace {

// The points a stop's picture holds: the estimated trajectory, then the plan's waypoints.
std::vector<Eigen::Vector2d> PicturePoints(const StopView& view) {
  std::vector<Eigen::Vector2d> points = view.trajectory_m;
  if (view.plan) {
    for (const planning::Waypoint& w : view.plan->waypoints) points.emplace_back(w.x_m, w.y_m);
  }
  return points;
}

}  // namespace

StopView ViewOfStop(const MissionResult& so_far, const std::optional<planning::Path>& plan) {
  StopView view;
  view.whole = so_far.elevation.geometry();
  view.trajectory_m = TrajectoryXy(so_far, false);
  view.plan = plan;
  view.region = PictureRegion(so_far.elevation, PicturePoints(view));
  return view;
}

mapping::RgbImage StopPicture(const StopView& view) {
  const std::vector<Eigen::Vector2d> keep = PicturePoints(view);
  FigureMarks marks;
  if (!view.trajectory_m.empty()) marks.start_m = view.trajectory_m.front();
  if (view.plan && !view.plan->waypoints.empty()) marks.goal_m = keep.back();
  const mapping::ElevationLayers layers = mapping::ComputeLayers(view.region);
  const mapping::GridGeometry& g = layers.geometry;
  const MapWindow window = ExploredWindow(layers, keep);
  mapping::ImageOptions options;
  options.pixels_per_cell = FigurePixelsPerCell(view.whole, window);
  mapping::RgbImage image = mapping::RenderElevationImage(layers, options);
  if (view.plan) planning::DrawPath(*view.plan, g, image);
  marks.colour_bar = HeightBar(layers);
  return ComposeMapFigure(image, g, window, marks);
}

}  // namespace pitchlab::mission
