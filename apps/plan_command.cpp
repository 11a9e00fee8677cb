// `pitchlab plan`: least-cost path (Eq. 4-5, Algorithm 2) on an elevation map, written as CSV,
// GeoJSON (WGS84) and drawn on the map picture.

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
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/planning/path_io.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sensors/yaml_keys.hpp"
#include "output_paths.hpp"
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

CliArgs PlanArgs() {
  CliArgs args(
      "plan",
      "Plans the least-cost path (Eq. 5: W_T*T + W_P*P + W_phix*phi_x + W_phiy*phi_y per\n"
      "edge, 8-connected cells) on an elevation map written by `pitchlab map`, and writes\n"
      "DIR/path.csv, DIR/path.geojson (when the map is georeferenced), DIR/path.png and\n"
      "DIR/plan.json, and always DIR/traversability.png (what the robot may enter and why\n"
      "not) and DIR/elevation.png. No path: the reason is printed and the exit code is 1;\n"
      "when start and goal lie on the map, DIR still gets the two pictures and plan.json\n"
      "(found: false), to show why; otherwise no DIR is made.");
  args.Positionals("MAP.plem", "elevation map", 1, 1)
      .Option("start", "x,y", "start in the map frame [m]")
      .Option("goal", "x,y", "goal in the map frame [m]")
      .Option("robot", "p3at|p3dx", "robot preset (step, inclination, width); overrides --config's")
      .Option("algo", "astar|dijkstra", "graph search", "astar")
      .Option("config", "FILE.yaml", "planner config: weights, robot limits, unknown policy")
      .Option("unknown", "forbid|penalise", "unknown cells, overrides --config's")
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
            {"unknown", p.parts.unknown}}},
          {"length_m", p.length_m},
          {"waypoints", p.waypoints.size()},
          {"max_step_m", p.max_step_m},
          {"max_inclination_deg", p.max_inclination_rad * kRadToDeg},
          {"expanded", p.expanded}};
}

}  // namespace

int RunPlan(int argc, char** argv) {
  CliArgs args = PlanArgs();
  if (!args.Parse(argc, argv)) return 0;
  InstallInterruptCleanup("pitchlab plan");  // Ctrl-C removes the unfinished folder
  const std::vector<double> start = args.GetNumbers("start", 2), goal = args.GetNumbers("goal", 2);
  const std::filesystem::path out = args.Get("out");
  CheckNewFolder("out", out);  // as run and map: never into an existing folder
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
  planning::Algorithm algorithm;
  try {
    algorithm = planning::ParseAlgorithm(args.Get("algo"));
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("--algo: ") + e.what());
  }
  Result<mapping::ElevationMap> map = mapping::LoadElevationMap(args.positionals()[0]);
  if (!map) throw std::runtime_error(map.error().message);

  const auto t0 = std::chrono::steady_clock::now();
  const mapping::ElevationLayers layers = mapping::ComputeLayers(*map);
  const planning::TraversabilityGrid grid = planning::BuildTraversability(layers, config);
  const auto t1 = std::chrono::steady_clock::now();
  const auto result = planning::PlanPath(grid, {start[0], start[1]}, {goal[0], goal[1]}, algorithm);
  const auto t2 = std::chrono::steady_clock::now();

  nlohmann::json summary;
  summary["robot"] = config.robot.name;
  summary["start"] = start;
  summary["goal"] = goal;
  summary["traversability_time_s"] = std::chrono::duration<double>(t1 - t0).count();
  summary["search_time_s"] = std::chrono::duration<double>(t2 - t1).count();
  const auto check = [](Result<void> r) {
    if (!r) throw std::runtime_error(r.error().message);
  };
  // The pictures of the map and of what the planner may enter, with or without a path: they
  // show why the path went where it did, or why there is none.
  const auto write_pictures = [&](const RunFolder& folder, const planning::Path* path) {
    mapping::RgbImage elevation = mapping::RenderElevationImage(layers);
    check(mapping::WritePng(elevation, folder.File("elevation.png").string()));
    mapping::RgbImage traversability = RenderTraversability(grid);
    if (path) planning::DrawPath(*path, map->geometry(), traversability);
    check(mapping::WritePng(traversability, folder.File("traversability.png").string()));
    summary["traversability_legend"] = TraversabilityLegend();
  };
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
    if (on_map) {
      RunFolder folder(out);
      write_pictures(folder, nullptr);
      summary["files"] = {"traversability.png", "elevation.png", "plan.json"};
      WriteTextFile(folder.File("plan.json"), summary.dump(2) + "\n");
      folder.Commit();
    }
    if (args.Flagged("json")) std::cout << summary.dump(2) << "\n";
    std::cerr << "pitchlab plan: no path (" << planning::ToString(reason)
              << "): " << result.error().message << "\n";
    if (on_map) {
      std::cerr << "wrote " << out.string()
                << "/{traversability.png, elevation.png, plan.json}: traversability.png shows what "
                   "blocks the way (red step, orange too steep, magenta drop, checkered unknown)\n";
    }
    return 1;
  }
  summary.update(PathJson(*result));
  RunFolder folder(out);
  check(planning::WritePathCsv(*result, folder.File("path.csv").string()));
  if (map->geodetic_origin()) {
    check(planning::WritePathGeoJson(*result, map->geodetic_origin(),
                                     folder.File("path.geojson").string()));
  } else {
    summary["geojson"] = "skipped: the map has no geodetic origin (map it with --world)";
  }
  mapping::RgbImage image = mapping::RenderElevationImage(layers);
  planning::DrawPath(*result, map->geometry(), image);
  check(mapping::WritePng(image, folder.File("path.png").string()));
  write_pictures(folder, &*result);
  WriteTextFile(folder.File("plan.json"), summary.dump(2) + "\n");
  folder.Commit();
  if (args.Flagged("json")) {
    std::cout << summary.dump(2) << "\n";
  } else {
    std::printf(
        "path (%s): cost %.4f (roughness %.4f, length %.4f, incl. x %.4f, incl. y %.4f, "
        "unknown %.4f), %.2f m, %zu waypoints, max step %.3f m, max inclination %.1f deg\n"
        "wrote %s/{path.csv, path.geojson, path.png, traversability.png, elevation.png, "
        "plan.json}\n",
        planning::ToString(algorithm), result->cost, result->parts.roughness, result->parts.length,
        result->parts.inclination_x, result->parts.inclination_y, result->parts.unknown,
        result->length_m, result->waypoints.size(), result->max_step_m,
        result->max_inclination_rad * kRadToDeg, out.string().c_str());
  }
  return 0;
}

}  // namespace pitchlab::apps
