// `pitchlab worlds`: what worlds there are, with what each says about itself.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include <mujoco/mujoco.h>
#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "commands.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "pitchlab/worlds/world_metadata.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {

int RunWorlds(int argc, char** argv) {
  CliArgs args("worlds",
               "Lists the built-in worlds: description, placement bounds, the default run's\n"
               "start and goal (what `run` and `bench` use without --start / --goal) and\n"
               "geodetic origin. Any MJCF file is a world too (--world path/to/scene.xml), and\n"
               "pitchlab_worldgen (beside this program) makes one of a DEM: `pitchlab_worldgen\n"
               "dem --in DEM.tif --area XMIN,YMIN,XMAX,YMAX --out my/site.xml` (see its --help).");
  args.Flag("json", "print the list as JSON on stdout");
  if (!args.Parse(argc, argv)) return 0;
  nlohmann::json list = nlohmann::json::array();
  for (const worlds::CatalogEntry& entry : worlds::BuiltinWorlds()) {
    const auto path = worlds::ResolveWorld(entry.name, WorldsDir());
    char error[1000] = "";
    mjModel* model = mj_loadXML(path.string().c_str(), nullptr, error, sizeof(error));
    if (model == nullptr) {
      throw std::runtime_error("cannot load world '" + path.string() + "': " + error);
    }
    const worlds::WorldMetadata meta = worlds::ReadWorldMetadata(model);
    mj_deleteModel(model);
    nlohmann::json w = {{"name", entry.name},
                        {"file", path.string()},
                        {"description", meta.description},
                        {"bounds_m", {meta.bounds.x_min_m, meta.bounds.y_min_m,
                                      meta.bounds.x_max_m, meta.bounds.y_max_m}},
                        {"default_start", {{"x_m", meta.default_start.x_m},
                                           {"y_m", meta.default_start.y_m},
                                           {"yaw_deg", meta.default_start.yaw_rad * 180 / M_PI}}}};
    // null when the world names none (then `run` needs --goal): every built-in world names one.
    w["default_goal"] = meta.default_goal ? nlohmann::json{{"x_m", meta.default_goal->x_m},
                                                           {"y_m", meta.default_goal->y_m}}
                                          : nlohmann::json(nullptr);
    if (meta.geodetic_origin) {
      w["geodetic_origin"] = {{"latitude_deg", meta.geodetic_origin->latitude_deg},
                              {"longitude_deg", meta.geodetic_origin->longitude_deg},
                              {"height_m", meta.geodetic_origin->height_m}};
    }
    list.push_back(w);
  }
  if (args.Flagged("json")) {
    std::cout << list.dump(2) << "\n";
    return 0;
  }
  // Positions to the millimetre, without trailing zeros (-0.075, 45.825, 4).
  const auto mm = [](const nlohmann::json& v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.10g", std::round(v.get<double>() * 1000) / 1000);
    return std::string(text);
  };
  std::printf("%-10s %-12s %-26s %-15s %s\n", "world", "size", "start x, y [m], yaw [deg]",
              "goal x, y [m]", "description");
  for (const auto& w : list) {
    const auto& b = w["bounds_m"];
    const auto& s = w["default_start"];
    char size[32];
    std::snprintf(size, sizeof(size), "%.0f x %.0f m", b[2].get<double>() - b[0].get<double>(),
                  b[3].get<double>() - b[1].get<double>());
    const std::string start = mm(s["x_m"]) + ", " + mm(s["y_m"]) + ", " + mm(s["yaw_deg"]);
    const auto& g = w["default_goal"];
    const std::string goal = g.is_null() ? "none" : mm(g["x_m"]) + ", " + mm(g["y_m"]);
    std::printf("%-10s %-12s %-26s %-15s %s\n", w["name"].get<std::string>().c_str(), size,
                start.c_str(), goal.c_str(), w["description"].get<std::string>().c_str());
  }
  std::printf("\nworld files in %s\n", WorldsDir().string().c_str());
  std::printf("a world of your own DEM (GeoTIFF, ESRI grid): pitchlab_worldgen dem --help\n");
  return 0;
}

}  // namespace pitchlab::apps
