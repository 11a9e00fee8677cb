// `pitchlab map`: clouds (PCD) -> elevation map (Eq. 2, 3, inclination), written losslessly, as
// ESRI ASCII rasters (elevation, inclination, roughness) with their projection, as a map_server
// occupancy grid (traversability) and as a PNG; with --world, scored against ground truth.


#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "cloud_input.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "output_paths.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/elevation_truth.hpp"
#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/mapping/physical_memory.hpp"
#include "pitchlab/mission/map_figure.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sensors/ray_caster.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"
#include "pitchlab/sim/simulation.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "progress.hpp"
#include "run_folder.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

// The library's default, as --help shows it.
std::string DefaultClearance() {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", mapping::InsertConfig{}.clearance_length_m);
  return text;
}

CliArgs MapArgs() {
  CliArgs args(
      "map",
      "Builds an elevation map from point clouds (any format sensors read: PCD, 3DTK\n"
      ".3d, PLY, XYZ; points moved into the world by each file's pose) and writes\n"
      "DIR/map.plem (lossless), DIR/elevation.png, DIR/map.json, ESRI ASCII rasters\n"
      "with their .prj (georeferenced with --world): DIR/elevation.asc [m],\n"
      "DIR/inclination.asc (the cell plane's tilt [deg]), DIR/roughness.asc (Eq. 3 [m]),\n"
      "and the traversability for --robot as a ROS map_server occupancy grid,\n"
      "DIR/traversability.yaml + .pgm (raw mode: 0 free, 1..99 the cost of entering,\n"
      "100 lethal: step, drop, too steep; 255 unknown; Nav2's static layer reads the\n"
      "costs with trinary_costmap: false, and inflates by its own footprint). With\n"
      "--world, the map is georeferenced and scored against the world's true surface.\n"
      "\n"
      "Levelling: without --world (whose frame is the simulator's, z up) nothing tells\n"
      "where gravity points, and a scanner mounted a few degrees off tilts the whole map\n"
      "(a flat floor reads as a slope). The map frame is then turned about its origin so\n"
      "that the floor under the first cloud's sensor is level: a robust plane fit of the\n"
      "points below the sensor within 0.5-4 m of it. It assumes the first scan stood on\n"
      "level ground; map.json reports the plane (normal, tilt removed, residual, points).\n"
      "--no-level keeps the clouds' frame (their poses came levelled by an IMU).\n"
      "\n"
      "Height band: points higher than --max-height above the ground under the sensor\n"
      "that saw them are not ground (a ceiling, a canopy), unless the laser saw their\n"
      "surface from above: terrain rising ahead may climb 35 % (the P3-AT's grade) of\n"
      "its distance higher. Points on a surface the laser saw from below (a ceiling, a\n"
      "desk's underside) are never ground. Cells whose only points were those stay\n"
      "unknown.");
  args.Positionals("CLOUD", "one or more clouds, any format below", 1, 1000)
      .Option("sensor-origin", "x,y,z", kSensorOriginHelp)
      .Flag("as-recorded", kAsRecordedHelp)
      .Option("cell", "METRES", "cell size [m]", "0.1")
      .Option("out", "DIR", "output folder to create (refused when it exists, as run refuses)")
      .Option("area", "xmin,ymin,xmax,ymax", "map area [m] (default: the clouds' extent)")
      .Option("margin", "METRES", "added around the clouds' extent [m]", "0.5")
      .Option("world", "NAME|FILE.xml",
              "world the clouds came from: geodetic origin and ground truth (" +
                  BuiltinWorldNames() + ")")
      .Option("clearance", "METRES",
              "ray length behind each hit that marks free space (drops, overhangs); 0 disables",
              DefaultClearance())
      .Option("max-height", "METRES",
              "height band above the ground under the sensor: the robot with its laser is "
              "0.6 m tall, plus 0.4 m for the ground's unevenness and the pose's tilt error; "
              "'inf' disables",
              "1.0")
      .Option("robot", "p3at|p3dx",
              "robot whose limits (step, inclination) make traversability.pgm's lethal cells",
              "p3at")
      .Flag("no-level", "keep the clouds' frame; do not level it by the first cloud's floor")
      .Flag("json", "print the summary as JSON on stdout")
      .Flag("quiet", "no progress on stderr");
  return args;
}

struct LoadedCloud {
  std::vector<Eigen::Vector3f> points;  // world frame
  Eigen::Vector3f sensor_origin;        // approximate laser position in the world
  std::size_t no_position = 0;          // points the file held without one (NaN), dropped
  std::string world;                    // the world it was scanned in, when the file says
  nlohmann::json line_pitch;            // what setting its lines right did
};

LoadedCloud LoadCloud(const std::string& path, const std::optional<Eigen::Vector3d>& origin,
                      bool set_lines_right) {
  LoadedCloud c;
  // Any format; origin always set; lines set right in the scan's own frame, before its pose.
  const sensors::Scan3D scan = LoadInputCloud(path, origin, set_lines_right, &c.line_pitch);
  const Eigen::Isometry3f T = scan.T_world_base.cast<float>();
  c.points.reserve(scan.points.size());
  for (const sensors::ScanPoint& p : scan.points)
    c.points.push_back(T * Eigen::Vector3f(p.x, p.y, p.z));
  // The sensor where the file (or --sensor-origin) puts it: for pitchlab's own scans the mirror
  // at zero pitch, which moves by a few centimetres while pitching and shifts the clearance rays'
  // ends (the last few metres) by well under a centimetre.
  c.sensor_origin = T * scan.sensor_origin->cast<float>();
  c.no_position = scan.no_returns;
  c.world = scan.world;
  return c;
}

constexpr double kInf = std::numeric_limits<double>::infinity();

// A cloud that says which world it was scanned in (pitchlab's PCDs do) must be of --world: else
// the score compares it with another world's truth.
void CheckSameWorld(const std::string& path, const std::string& cloud_world,
                    const std::filesystem::path& world_path) {
  const std::string world = world_path.stem().string();
  if (cloud_world.empty() || cloud_world == world) return;
  throw std::runtime_error("'" + path + "' was scanned in world '" + cloud_world + "', not '" +
                           world + "' (--world): its score would be against another world's " +
                           "truth; give --world " + cloud_world + " or leave --world out");
}

// Why no point went into the map, from the counts of what became of them.
std::string NothingInserted(const mapping::InsertStats& s, std::size_t points) {
  return "no point of the clouds went into the map: of " + std::to_string(points) + ", " +
         std::to_string(s.outside) + " lie outside the map area (--area), " +
         std::to_string(s.above_band) + " above the height band (--max-height), " +
         std::to_string(s.underside + s.overhang) + " on undersides or overhangs, " +
         std::to_string(s.non_finite) + " without a finite position";
}

// The LMS200's longest range, cm mode's 8191 counts of 1 cm (DESIGN.md): a point farther from the
// sensor that saw it is not a return, and it is what stretches a map past its size [m].
constexpr double kLms200MaxRange_m = 81.91;

// The point farthest from the sensor that saw it when that is beyond any LMS200 return (named, so a
// user can find the stray point or the cloud in other units); empty when every point is in range.
std::string StrayPoint(const std::vector<LoadedCloud>& clouds,
                       const std::vector<std::string>& paths) {
  double farthest = -1;
  std::size_t cloud = 0, index = 0;
  for (std::size_t c = 0; c < clouds.size(); ++c) {
    for (std::size_t i = 0; i < clouds[c].points.size(); ++i) {
      const double d = (clouds[c].points[i] - clouds[c].sensor_origin).head<2>().norm();
      if (d > farthest) farthest = d, cloud = c, index = i;
    }
  }
  if (farthest <= kLms200MaxRange_m) return "";
  const Eigen::Vector3f& p = clouds[cloud].points[index];
  char text[320];
  std::snprintf(text, sizeof(text),
                "the farthest point, %zu of '%s' at (%.6g, %.6g, %.6g) m, lies %.6g m from its "
                "sensor (an LMS200 reaches %.2f m): crop the clouds or give --area",
                index, paths[cloud].c_str(), p.x(), p.y(), p.z(), farthest, kLms200MaxRange_m);
  return text;
}

// The map's cells must fit the machine's memory, checked before they are allocated (a bad_alloc
// names nothing a user can act on): empty when they fit, else what they would take.
std::string MemoryShortfall(const mapping::GridGeometry& g) {
  const double bytes = double(g.cell_count()) * mapping::ElevationMap::kBytesPerCell;
  const double memory = mapping::PhysicalMemoryBytes();
  if (bytes <= memory) return "";
  char text[200];
  std::snprintf(text, sizeof(text),
                "the map would be %d x %d cells of %g m, %.3g GB, more than this machine's "
                "%.3g GB; ",
                g.size_x, g.size_y, g.cell_m, bytes / 1e9, memory / 1e9);
  return text;
}

nlohmann::json ErrorJson(const mapping::MapErrorReport& r) {
  return {{"compared_cells", r.compared_cells},
          {"truth_cells", r.truth_cells},
          {"coverage", r.coverage},
          {"surface_cells", r.surface_cells},
          {"rmse_m", r.rmse_m},
          {"mean_error_m", r.mean_error_m},
          {"max_abs_error_m", r.max_abs_error_m},
          {"p95_abs_error_m", r.p95_abs_error_m},
          {"wall_cells", r.wall_cells},
          {"wall_rmse_m", r.wall_rmse_m},
          {"all_rmse_m", r.all_rmse_m},
          {"drop_cells", r.drop_cells}};
}

}  // namespace

int RunMap(int argc, char** argv) {
  CliArgs args = MapArgs();
  if (!args.Parse(argc, argv)) return 0;
  InstallInterruptCleanup("pitchlab map");  // Ctrl-C removes the unfinished folder
  const std::filesystem::path out = args.Get("out");
  CheckNewFolder("out", out);  // before the work; never into an existing folder (as run)
  const double cell = args.GetNumbers("cell", 1)[0];
  if (!(cell > 0)) throw CliError("--cell must be positive");
  mapping::InsertConfig insert;
  insert.clearance_length_m = args.GetNumber("clearance", 0.0, kInf);
  insert.max_height_m = args.GetNumbers("max-height", 1)[0];
  if (!(insert.max_height_m > 0)) throw CliError("--max-height must be positive (or inf)");
  const double margin = args.GetNumber("margin", 0.0, kInf);
  planning::RobotLimits robot;
  try {
    robot = planning::RobotLimits::Preset(args.Get("robot"));
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("--robot: ") + e.what());
  }
  const bool quiet = args.Flagged("quiet");
  const auto progress = [quiet](const std::string& text) {
    if (!quiet) std::fprintf(stderr, "map: %s\n", text.c_str());
  };
  const auto wall_start = std::chrono::steady_clock::now();
  const std::optional<std::string> world =
      args.Has("world") ? std::optional(args.Get("world")) : std::nullopt;
  const std::optional<std::filesystem::path> world_path =
      world ? std::optional(worlds::ResolveWorld(*world, WorldsDir())) : std::nullopt;

  const std::optional<Eigen::Vector3d> sensor_origin = SensorOriginOption(args);
  std::vector<LoadedCloud> clouds;
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  std::size_t total_points = 0;
  std::size_t no_position = 0;
  for (const std::string& path : args.positionals()) {
    progress("reading " + path);
    clouds.push_back(LoadCloud(path, sensor_origin, !args.Flagged("as-recorded")));
    if (world_path) CheckSameWorld(path, clouds.back().world, *world_path);
    no_position += clouds.back().no_position;
    for (const Eigen::Vector3f& p : clouds.back().points) {
      lo = lo.cwiseMin(p.head<2>().cast<double>());
      hi = hi.cwiseMax(p.head<2>().cast<double>());
    }
    total_points += clouds.back().points.size();
  }
  nlohmann::json line_pitch = nlohmann::json::array();
  for (std::size_t k = 0; k < clouds.size(); ++k) {
    line_pitch.push_back({{"cloud", args.positionals()[k]}, {"result", clouds[k].line_pitch}});
  }
  // Levelling by the first cloud's floor (see --help), before the grid is laid over the points.
  nlohmann::json levelling;
  if (args.Has("world")) {
    levelling = {{"method", "none: --world's frame is the simulator's, z up"}};
  } else if (args.Flagged("no-level")) {
    levelling = {{"method", "none: --no-level"}};
  } else if (!clouds.empty()) {
    Result<mapping::GroundLevel> level =
        mapping::FitGroundLevel(clouds.front().points, clouds.front().sensor_origin);
    if (!level) {
      throw std::runtime_error(args.positionals().front() + ": " + level.error().message +
                               "; give --no-level to map the clouds' frame as it is");
    }
    const Eigen::Matrix3f R = level->R_level.cast<float>();
    lo = Eigen::Vector2d(1e300, 1e300), hi = Eigen::Vector2d(-1e300, -1e300);
    for (LoadedCloud& c : clouds) {
      for (Eigen::Vector3f& p : c.points) {
        p = R * p;
        lo = lo.cwiseMin(p.head<2>().cast<double>());
        hi = hi.cwiseMax(p.head<2>().cast<double>());
      }
      c.sensor_origin = R * c.sensor_origin;
    }
    insert.sensor_height_m = level->sensor_height_m;
    levelling = {{"method", "ground plane of the first cloud"},
                 {"normal", {level->normal.x(), level->normal.y(), level->normal.z()}},
                 {"tilt_removed_deg", level->tilt_rad * 180 / M_PI},
                 {"residual_m", level->residual_m},
                 {"inlier_threshold_m", level->threshold_m},
                 {"points", level->inliers},
                 {"candidates", level->candidates},
                 {"sensor_height_m", level->sensor_height_m}};
  }
  mapping::GridGeometry geometry;
  if (args.Has("area")) {
    const auto a = args.GetNumbers("area", 4);
    if (!(a[2] > a[0] && a[3] > a[1])) throw CliError("--area needs xmin < xmax and ymin < ymax");
    geometry = mapping::GridGeometry::FromArea(a[0], a[1], a[2] - a[0], a[3] - a[1], cell);
  } else {
    if (total_points == 0) throw std::runtime_error("the clouds hold no points; give --area");
    try {
      geometry = mapping::GridGeometry::Covering(lo, hi, cell, margin);
    } catch (const std::invalid_argument&) {  // more than 2^31 cells
      char extent[160];
      std::snprintf(extent, sizeof(extent),
                    "the clouds span %.6g x %.6g m: at --cell %g that is more cells than a map "
                    "holds (2^31); ",
                    hi.x() - lo.x(), hi.y() - lo.y(), cell);
      const std::string stray = StrayPoint(clouds, args.positionals());
      throw std::runtime_error(extent +
                               (stray.empty() ? "give a coarser --cell or a smaller --area" : stray));
    }
    // A cloud from another scanner, or a merged map, may mean it: a warning, not an error.
    if (const std::string stray = StrayPoint(clouds, args.positionals()); !stray.empty()) {
      std::fprintf(stderr, "warning: %s\n", stray.c_str());
    }
  }
  if (const std::string too_big = MemoryShortfall(geometry); !too_big.empty()) {
    const std::string stray = args.Has("area") ? "" : StrayPoint(clouds, args.positionals());
    throw std::runtime_error(too_big +
                             (stray.empty() ? "give a coarser --cell or a smaller --area" : stray));
  }

  // The world, when given: its geodetic origin and its true surface.
  std::unique_ptr<sim::Simulation> sim;
  std::optional<mapping::GeodeticOrigin> origin;
  if (world_path) {
    sim = std::make_unique<sim::Simulation>(world_path->string(), sim::RobotConfig{});
    if (const auto& g = sim->world().geodetic_origin)
      origin = mapping::GeodeticOrigin{g->x(), g->y(), g->z()};
  }

  progress("inserting " + std::to_string(total_points) + " points into " +
           std::to_string(geometry.size_x) + " x " + std::to_string(geometry.size_y) + " cells");
  mapping::ElevationMap map(geometry, origin);
  const auto insert_start = std::chrono::steady_clock::now();
  mapping::InsertStats stats;
  for (const LoadedCloud& c : clouds) {
    const mapping::InsertStats s =
        map.InsertScan(c.points.data(), c.points.size(), c.sensor_origin, insert);
    stats.inserted += s.inserted;
    stats.outside += s.outside;
    stats.non_finite += s.non_finite;
    stats.overhang += s.overhang;
    stats.above_band += s.above_band;
    stats.underside += s.underside;
  }
  stats.non_finite += no_position;  // dropped by the reader (NaN in the file) or by the map
  if (stats.inserted == 0) throw std::runtime_error(NothingInserted(stats, total_points));
  const double insert_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - insert_start).count();
  const mapping::ElevationLayers layers = mapping::ComputeLayers(map);

  RunFolder folder(out);
  const auto check = [](Result<void> r) {
    if (!r) throw std::runtime_error(r.error().message);
  };
  check(mapping::SaveElevationMap(map, folder.File("map.plem").string()));
  check(mapping::WriteEsriAsciiGrid(layers, origin, folder.File("elevation.asc").string()));
  check(mapping::WriteEsriAsciiGrid(layers, origin, folder.File("inclination.asc").string(),
                                    mapping::RasterLayer::kInclination));
  check(mapping::WriteEsriAsciiGrid(layers, origin, folder.File("roughness.asc").string(),
                                    mapping::RasterLayer::kRoughness));
  // Unknown cells stay unknown in the occupancy grid: a navigation stack decides what they are.
  planning::PlannerConfig planner;
  planner.robot = robot;
  planner.unknown = planning::UnknownPolicy::kForbid;
  const planning::TraversabilityGrid traversability =
      planning::BuildTraversability(layers, planner);
  check(planning::WriteOccupancyGrid(planning::ToOccupancy(traversability),
                                     folder.File("traversability.yaml").string()));
  std::size_t lethal = 0;
  for (planning::Blocked b : traversability.blocked) lethal += planning::IsFootprintHazard(b);
  {  // cropped to the known cells, axes in metres, a scale bar and the heights' colour bar
    const mission::MapWindow window = mission::ExploredWindow(layers, {});
    mapping::ImageOptions options;
    options.pixels_per_cell = mission::FigurePixelsPerCell(layers.geometry, window);
    check(mapping::WritePng(
        mission::ComposeMapFigure(mapping::RenderElevationImage(layers, options), layers.geometry,
                                  window, {std::nullopt, std::nullopt, mission::HeightBar(layers)}),
        folder.File("elevation.png").string()));
  }

  std::size_t known = 0, drops = 0;
  for (mapping::CellState s : layers.state) {
    known += s == mapping::CellState::kObserved;
    drops += s == mapping::CellState::kDrop;
  }
  nlohmann::json summary = {
      {"clouds", args.positionals()},
      {"out", out.string()},
      {"cell_m", cell},
      {"size_x", geometry.size_x},
      {"size_y", geometry.size_y},
      {"x_min_m", geometry.x_min_m},
      {"y_min_m", geometry.y_min_m},
      {"bytes_per_cell", mapping::ElevationMap::kBytesPerCell},
      {"points", total_points},
      {"inserted", stats.inserted},
      {"outside", stats.outside},
      {"non_finite", stats.non_finite},
      {"overhang", stats.overhang},
      {"above_band", stats.above_band},
      {"underside", stats.underside},
      {"max_height_m", insert.max_height_m},
      {"sensor_height_m", insert.sensor_height_m},
      {"levelling", levelling},
      {"line_pitch", line_pitch},
      {"known_cells", known},
      {"drop_cells", drops},
      {"insert_time_s", insert_s},
      {"robot", robot.name},
      {"lethal_cells", lethal},
      {"bridged_gap_cells", traversability.bridged_cells},
      {"files",
       {"map.plem", "elevation.asc", "elevation.prj", "inclination.asc", "inclination.prj",
        "roughness.asc", "roughness.prj", "traversability.yaml", "traversability.pgm",
        "elevation.png", "map.json"}}};
  if (origin) {
    summary["geodetic_origin"] = {origin->latitude_deg, origin->longitude_deg, origin->height_m};
  }
  if (sim) {
    progress("ground truth of " + *world + " on the map's grid");
    const std::unique_ptr<sensors::RayCaster> caster =
        sensors::MakeEmbreeRayCaster(sim->model(), sim->data());
    mapping::TruthConfig truth_config;
    truth_config.progress = QuarterProgress("map: ground truth", "rows", quiet);
    const mapping::ElevationLayers truth = mapping::ComputeTruthLayers(
        mapping::ComputeTrueElevationMap(*caster, geometry, truth_config));
    summary["truth"] = ErrorJson(mapping::CompareToTruth(layers, truth));
    summary["world"] = *world;
  }
  summary["wall_time_s"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  WriteTextFile(folder.File("map.json"), summary.dump(2) + "\n");
  folder.Commit();
  if (args.Flagged("json")) {
    std::cout << summary.dump(2) << "\n";
    return 0;
  }
  std::printf(
      "elevation map %d x %d cells of %.3f m: %zu of %zu points inserted, %zu cells known, "
      "%zu drop cells, %zu lethal for %s\nwrote %s/{map.plem, elevation.asc, inclination.asc, "
      "roughness.asc (each with its .prj), traversability.yaml + .pgm, elevation.png, "
      "map.json}\n",
      geometry.size_x, geometry.size_y, cell, stats.inserted, total_points, known, drops, lethal,
      robot.name.c_str(), out.string().c_str());
  if (levelling.contains("tilt_removed_deg")) {
    std::printf("levelled by the first cloud's floor: %.2f deg of tilt removed (floor plane "
                "residual %.4f m over %zu points, sensor %.3f m above it)\n",
                levelling["tilt_removed_deg"].get<double>(), levelling["residual_m"].get<double>(),
                levelling["points"].get<std::size_t>(),
                levelling["sensor_height_m"].get<double>());
  }
  if (summary.contains("truth")) {
    const auto& t = summary["truth"];
    std::printf(
        "vs ground truth: surface RMSE %.4f m, max %.4f m, bias %.4f m, coverage %.1f %%; "
        "%zu wall cells (no single true height), RMSE %.3f m\n",
        t["rmse_m"].get<double>(), t["max_abs_error_m"].get<double>(),
        t["mean_error_m"].get<double>(), 100 * t["coverage"].get<double>(),
        t["wall_cells"].get<std::size_t>(), t["wall_rmse_m"].get<double>());
  }
  return 0;
}

}  // namespace pitchlab::apps
