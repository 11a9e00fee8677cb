// `pitchlab plan`: least-cost path (Eq. 4-5, Algorithm 2) on an elevation map, a DEM or an
// occupancy grid, written as CSV, GeoJSON (WGS84) and drawn on the map picture.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "output_paths.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mission/map_figure.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"
#include "pitchlab/planning/path_io.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sensors/yaml_keys.hpp"
#include "plan_input.hpp"
#include "run_folder.hpp"
#include "traversability_image.hpp"

namespace pitchlab::apps {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// --config: as every pitchlab config, a key given twice is refused (yaml-cpp would keep the first).
planning::PlannerConfig ReadPlannerConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the planner config");
  std::stringstream text;
  text << in.rdbuf();
  sensors::CheckUniqueYamlKeys(text.str(), path);
  return planning::ParsePlannerConfig(text.str(), path);
}

// The planner's defaults as --help states them, from the library's own values.
std::string PlannerDefaults() {
  const planning::PlannerConfig c;
  char text[1200];
  std::snprintf(
      text, sizeof(text),
      "Defaults (a --config file may set any of them; --robot and --unknown override it):\n"
      "  robot %s: step %g m, inclination %.1f deg, %g m wide, %g m long, wheel radius %g m\n"
      "  weights: roughness %g, length %g, inclination_x %g, inclination_y %g\n"
      "  unknown: forbid (unknown_penalty %g when penalise); `pitchlab run` plans with\n"
      "    penalise: a map from scans has unknown cells under and around the robot (the laser\n"
      "    does not see its own footprint), so give --unknown penalise on such maps;\n"
      "    unknown cells in a gap between scan lines (at most %.2f m across for this robot's\n"
      "    wheels, rays crossed them within a step of the ground on both sides) are ground\n"
      "  clearance_m %g, clearance_cost %g (off); algorithm astar (exact, as dijkstra)\n",
      c.robot.name.c_str(), c.robot.step_max_m, c.robot.max_inclination_rad * kRadToDeg,
      c.robot.width_m, c.robot.length_m, c.robot.wheel_radius_m, c.weights.roughness,
      c.weights.length, c.weights.inclination_x, c.weights.inclination_y, c.unknown_penalty,
      planning::MaxBridgedGap(c.robot), c.clearance_m, c.clearance_cost);
  return text;
}

CliArgs PlanArgs() {
  CliArgs args(
      "plan",
      "Plans the least-cost path (Eq. 5: W_T*T + W_P*P + W_phix*phi_x + W_phiy*phi_y per\n"
      "edge, 8-connected cells) on a map and writes DIR/path.csv (z_m empty in cells of\n"
      "unknown height), DIR/path.geojson (WGS84, when the map is georeferenced; heights only\n"
      "when every waypoint has one), DIR/path.png and DIR/plan.json, and always\n"
      "DIR/traversability.png (what the robot may enter and why not) and, for maps with\n"
      "heights, DIR/elevation.png. No path: the reason is printed and the exit code is 1;\n"
      "when start and goal lie on the map, DIR still gets the pictures and plan.json\n"
      "(found: false), to show why; otherwise no DIR is made.\n"
      "\n"
      "MAP is one of:\n"
      "  MAP.plem   an elevation map written by `pitchlab map`\n"
      "  MAP.asc    a DEM, ESRI ASCII grid, with its MAP.prj when georeferenced (longitude/\n"
      "             latitude, UTM or another Transverse Mercator; none: local metres); a\n"
      "             georeferenced grid is resampled onto square metres at its centre\n"
      "  MAP.tif    a DEM as a GeoTIFF (also .tiff, SRTM .hgt, ERDAS .img, GDAL .vrt;\n"
      "             read by GDAL), one band of heights in metres or feet, north-up cells,\n"
      "             georeferenced by the coordinate system it carries as an .asc is by its\n"
      "             .prj (oblong cells only when georeferenced: they are resampled)\n"
      "  MAP.yaml   a ROS map_server occupancy grid (PGM image; trinary, scale or raw):\n"
      "             occupied cells are obstacles, grey levels costs, unknown cells unknown\n"
      "--start and --goal are in the map's own coordinates: the map frame of a .plem, the\n"
      "grid's x, y of a DEM (easting, northing, or longitude, latitude in degrees), the\n"
      "YAML's frame of an occupancy grid.\n"
      "\n"
      "A grid coarser than the robot (a DEM's 3 m or 30 m cells) holds one height under the\n"
      "whole robot: a rise between neighbouring cells is read as a slope (blocked beyond the\n"
      "robot's inclination), not as a step, and a warning says what the map cannot show.\n"
      "\n" +
          PlannerDefaults());
  args.Positionals("MAP", "map file: .plem, .asc, .tif (or another raster) or .yaml (see above)", 1, 1)
      .Option("start", "x,y", "start in the map's own coordinates (see above)")
      .Option("goal", "x,y", "goal in the map's own coordinates")
      .Option("robot", "p3at|p3dx",
              "robot preset (step, inclination, size); default p3at, or --config's")
      .Option("algo", "astar|dijkstra", "graph search", "astar")
      .Option("config", "FILE.yaml", "planner config: weights, robot limits, unknown policy")
      .Option("unknown", "forbid|penalise", "unknown cells; default forbid, or --config's")
      .Option("out", "DIR", "output folder to create (refused when it exists, as run refuses)")
      .Flag("json", "print the result as JSON on stdout");
  return args;
}

nlohmann::json PathJson(const planning::Path& p) {
  return {{"found", true},
          {"algorithm", planning::ToString(p.algorithm)},
          {"cost", p.cost},
          {"cost_parts",
           {{"roughness", p.parts.roughness},
            {"length", p.parts.length},
            {"inclination_x", p.parts.inclination_x},
            {"inclination_y", p.parts.inclination_y},
            {"unknown", p.parts.unknown},
            {"occupancy", p.parts.occupancy}}},
          {"length_m", p.length_m},
          {"waypoints", p.waypoints.size()},
          {"max_step_m", p.max_step_m},
          {"max_inclination_deg", p.max_inclination_rad * kRadToDeg},
          {"expanded", p.expanded}};
}

// The planner config from --config, --robot and --unknown (CliError on a bad value).
planning::PlannerConfig PlanConfig(const CliArgs& args) {
  planning::PlannerConfig config;
  if (args.Has("config")) config = ReadPlannerConfig(args.Get("config"));
  try {
    if (args.Has("robot")) config.robot = planning::RobotLimits::Preset(args.Get("robot"));
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("--robot: ") + e.what());
  }
  if (args.Has("unknown")) {
    const std::string u = args.Get("unknown");
    if (u != "forbid" && u != "penalise") throw CliError("--unknown must be forbid or penalise");
    config.unknown =
        u == "forbid" ? planning::UnknownPolicy::kForbid : planning::UnknownPolicy::kPenalise;
  }
  return config;
}

// The pictures of the map and of what the planner may enter, with or without a path: they show
// why the path went where it did, or why there is none. Each is cropped to what the map knows
// (and the start and goal), with axes in metres, a scale bar, the start (S) and goal (G) and, for
// heights, a colour bar. Returns the files written.
std::vector<std::string> WritePictures(const PlanInput& in, const planning::Path* path,
                                       const RunFolder& folder, const Eigen::Vector2d& start_m,
                                       const Eigen::Vector2d& goal_m) {
  const auto write = [&](const mapping::RgbImage& image, const std::string& name) {
    if (const Result<void> r = mapping::WritePng(image, folder.File(name).string()); !r) {
      throw std::runtime_error(r.error().message);
    }
  };
  const mapping::GridGeometry& g = in.grid.geometry;
  const mission::MapWindow window =
      in.layers ? mission::ExploredWindow(*in.layers, {start_m, goal_m})
                : mission::MapWindow{{g.x_min_m, g.y_min_m}, {g.x_max_m(), g.y_max_m()}};
  mapping::ImageOptions options;
  options.pixels_per_cell = mission::FigurePixelsPerCell(g, window);
  const mission::FigureMarks marks{start_m, goal_m, std::nullopt};
  mission::FigureMarks height_marks = marks;
  if (in.layers) height_marks.colour_bar = mission::HeightBar(*in.layers);

  std::vector<std::string> files;
  mapping::RgbImage traversability = RenderTraversability(in.grid, options);
  if (path) planning::DrawPath(*path, g, traversability);
  write(mission::ComposeMapFigure(traversability, g, window, marks), "traversability.png");
  files.push_back("traversability.png");
  if (in.layers) {
    write(mission::ComposeMapFigure(mapping::RenderElevationImage(*in.layers, options), g, window,
                                    height_marks),
          "elevation.png");
    files.push_back("elevation.png");
  }
  if (path) {  // the path on the elevation picture, or on the traversability one without heights
    mapping::RgbImage image = in.layers ? mapping::RenderElevationImage(*in.layers, options)
                                        : RenderTraversability(in.grid, options);
    planning::DrawPath(*path, g, image);
    write(mission::ComposeMapFigure(image, g, window, in.layers ? height_marks : marks),
          "path.png");
    files.push_back("path.png");
  }
  return files;
}

std::string JoinFiles(const std::vector<std::string>& files) {
  std::string text;
  for (const std::string& f : files) text += (text.empty() ? "" : ", ") + f;
  return text;
}

}  // namespace

int RunPlan(int argc, char** argv) {
  CliArgs args = PlanArgs();
  if (!args.Parse(argc, argv)) return 0;
  InstallInterruptCleanup("pitchlab plan");  // Ctrl-C removes the unfinished folder
  const std::vector<double> start = args.GetNumbers("start", 2), goal = args.GetNumbers("goal", 2);
  const std::filesystem::path out = args.Get("out");
  CheckNewFolder("out", out);  // as run and map: never into an existing folder
  const planning::PlannerConfig config = PlanConfig(args);
  planning::Algorithm algorithm;
  try {
    algorithm = planning::ParseAlgorithm(args.Get("algo"));
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("--algo: ") + e.what());
  }

  const auto t0 = std::chrono::steady_clock::now();
  const PlanInput in = LoadPlanInput(args.positionals()[0], config);
  const auto t1 = std::chrono::steady_clock::now();
  const Eigen::Vector2d start_m = in.to_map({start[0], start[1]});
  const Eigen::Vector2d goal_m = in.to_map({goal[0], goal[1]});
  const auto result = planning::PlanPath(in.grid, start_m, goal_m, algorithm);
  const auto t2 = std::chrono::steady_clock::now();

  nlohmann::json summary;
  summary["robot"] = config.robot.name;
  summary["unknown"] = config.unknown == planning::UnknownPolicy::kForbid ? "forbid" : "penalise";
  summary["input"] = in.about;
  summary["start"] = start;
  summary["goal"] = goal;
  if (start_m != Eigen::Vector2d(start[0], start[1]) ||
      goal_m != Eigen::Vector2d(goal[0], goal[1])) {
    summary["start_map_m"] = {start_m.x(), start_m.y()};
    summary["goal_map_m"] = {goal_m.x(), goal_m.y()};
  }
  // Unknown cells planned as ground: gaps between scan lines the wheels roll over.
  summary["bridged_gap_cells"] = in.grid.bridged_cells;
  summary["traversability_time_s"] = std::chrono::duration<double>(t1 - t0).count();
  summary["search_time_s"] = std::chrono::duration<double>(t2 - t1).count();
  summary["warnings"] = nlohmann::json::array();
  if (const std::string w = planning::CoarseGridWarning(in.grid.geometry, config.robot);
      !w.empty()) {
    summary["warnings"].push_back(w);
    std::cerr << "pitchlab plan: warning: " << w << "\n";
  }
  summary["traversability_legend"] = TraversabilityLegend();
  if (!result) {
    // No path: the reason on stderr (and stdout with --json), exit 1. Start and goal on the map:
    // the pictures and plan.json are written so the user can see what blocks the way; a start
    // or goal off the map is a mistake in the command, and leaves no folder.
    const planning::NoPath::Reason reason = result.error().reason;
    const bool on_map = reason != planning::NoPath::Reason::kStartOutsideMap &&
                        reason != planning::NoPath::Reason::kGoalOutsideMap;
    summary.update({{"found", false},
                    {"reason", planning::ToString(reason)},
                    {"message", result.error().message}});
    std::vector<std::string> files;
    if (on_map) {
      RunFolder folder(out);
      files = WritePictures(in, nullptr, folder, start_m, goal_m);
      files.push_back("plan.json");
      summary["files"] = files;
      WriteTextFile(folder.File("plan.json"), summary.dump(2) + "\n");
      folder.Commit();
    }
    if (args.Flagged("json")) std::cout << summary.dump(2) << "\n";
    std::cerr << "pitchlab plan: no path (" << planning::ToString(reason)
              << "): " << result.error().message << "\n";
    if (on_map && config.unknown == planning::UnknownPolicy::kForbid) {
      std::cerr << "unknown cells are forbidden (the default): --unknown penalise plans through "
                   "them at a cost, as `pitchlab run` does\n";
    }
    if (on_map) {
      std::cerr << "wrote " << out.string() << "/{" << JoinFiles(files)
                << "}: traversability.png shows what blocks the way (red step, orange too "
                   "steep, magenta drop, black occupied, checkered unknown)\n";
    }
    return 1;
  }
  summary.update(PathJson(*result));
  RunFolder folder(out);
  const auto check = [](Result<void> r) {
    if (!r) throw std::runtime_error(r.error().message);
  };
  std::vector<std::string> files = {"path.csv"};
  check(planning::WritePathCsv(*result, folder.File("path.csv").string()));
  if (in.origin) {
    check(planning::WritePathGeoJson(*result, in.origin, folder.File("path.geojson").string()));
    files.push_back("path.geojson");
  } else {
    summary["geojson"] =
        "skipped: the map is not georeferenced (a .plem mapped without --world, "
        "a DEM without a .prj, an occupancy grid)";
  }
  for (const std::string& f : WritePictures(in, &*result, folder, start_m, goal_m)) {
    files.push_back(f);
  }
  files.push_back("plan.json");
  summary["files"] = files;
  WriteTextFile(folder.File("plan.json"), summary.dump(2) + "\n");
  folder.Commit();
  if (args.Flagged("json")) {
    std::cout << summary.dump(2) << "\n";
  } else {
    std::printf(
        "path (%s): cost %.4f (roughness %.4f, length %.4f, incl. x %.4f, incl. y %.4f, "
        "unknown %.4f, occupancy %.4f), %.2f m, %zu waypoints, max step %.3f m, max inclination "
        "%.1f deg\nwrote %s/{%s}\n",
        planning::ToString(algorithm), result->cost, result->parts.roughness, result->parts.length,
        result->parts.inclination_x, result->parts.inclination_y, result->parts.unknown,
        result->parts.occupancy, result->length_m, result->waypoints.size(), result->max_step_m,
        result->max_inclination_rad * kRadToDeg, out.string().c_str(), JoinFiles(files).c_str());
  }
  return 0;
}

}  // namespace pitchlab::apps
