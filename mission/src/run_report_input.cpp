// Gathering report.html's input from a finished run (run_report.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "pitchlab/mission/map_figure.hpp"
#include "report_scene.hpp"
#include "run_pictures.hpp"
#include "run_report.hpp"
#include "pitchlab/mission/traversability_image.hpp"

namespace pitchlab::mission {
namespace {

std::string Fixed(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

std::string StopFile(int index, const char* name) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "stops/%03d/%s", index, name);
  return buf;
}

std::vector<Eigen::Vector3d> Trajectory3d(const MissionResult& r, bool truth) {
  std::vector<Eigen::Vector3d> out;
  for (const TrajectorySample& s : r.trajectory) {
    if (!truth) {
      out.push_back(s.T_world_base_est.translation());
    } else if (s.T_world_base_true) {
      out.push_back(s.T_world_base_true->translation());
    }
  }
  return out;
}

void AddStops(RunReportInput& in, const MissionResult& r) {
  in.stop_header = {"stop",         "t [s]",    "x [m]",       "y [m]",    "pose error [m]",
                    "registration", "rmse [m]", "to goal [m]", "plan cost"};
  for (const StopRecord& s : r.stops) {
    const Eigen::Vector3d e = s.T_world_base.translation();
    const std::string err =
        s.T_world_base_true ? Fixed((s.T_world_base_true->translation() - e).norm(), 3) : "-";
    in.stop_rows.push_back(
        {std::to_string(s.index), Fixed(s.stamp_s, 1), Fixed(e.x(), 2), Fixed(e.y(), 2), err,
         s.merge.merged ? mapping::ToString(s.merge.registration.path) : "failed",
         Fixed(s.merge.registration.rmse_m, 4), Fixed(s.distance_to_goal_m, 2),
         s.plan ? Fixed(s.plan->cost, 1) : (s.plan_error.empty() ? "-" : "none")});
    in.stop_pictures.push_back({StopFile(s.index, "map_small.png"),
                                "stop " + std::to_string(s.index), "",
                                StopFile(s.index, "map.png")});
  }
}

Scene3D BuildRunScene(const RunContext& c, const MissionResult& r, const FinalMap& final_map) {
  const mapping::ElevationLayers& layers = final_map.layers;
  Scene3D scene;
  scene.cloud_m = DecimateCloud(r.map_cloud_world, kSceneMaxPoints);
  scene.true_m = Trajectory3d(r, true);
  scene.estimated_m = Trajectory3d(r, false);
  for (const StopRecord& s : r.stops) scene.stops_m.push_back(s.T_world_base.translation());
  std::vector<Eigen::Vector2d> keep = TrajectoryXy(r, false);
  keep.push_back(c.start.head<2>());
  keep.push_back(c.goal);
  const MapWindow window = ExploredWindow(layers, keep);
  scene.surface = BuildSurface(layers, final_map.grid, window);
  // Start at the robot's first height; the goal on the map where its cell is known, else at the
  // robot's last height.
  const double z0 = scene.estimated_m.empty() ? 0.0 : scene.estimated_m.front().z();
  scene.start_m = {c.start.x(), c.start.y(), z0};
  double goal_z = scene.estimated_m.empty() ? z0 : scene.estimated_m.back().z();
  const mapping::CellIndex gc = layers.geometry.IndexOf(c.goal.x(), c.goal.y());
  if (layers.geometry.Contains(gc)) {
    const std::size_t k = layers.geometry.Linear(gc);
    if (layers.state[k] == mapping::CellState::kObserved) goal_z = layers.mean_z[k];
  }
  scene.goal_m = {c.goal.x(), c.goal.y(), goal_z};
  return scene;
}

std::vector<std::string> FolderFiles(const std::filesystem::path& root) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) files.push_back(std::filesystem::relative(e.path(), root).string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

RunReportInput GatherRunReport(const RunFolder& folder, const RunContext& c, const MissionResult& r,
                               const nlohmann::json& metrics, const FinalMap& final_map) {
  RunReportInput in;
  in.metrics = metrics;
  in.config_yaml = c.config_yaml;
  in.folder = folder.File("metrics.json").parent_path();
  const bool truth = std::filesystem::exists(in.folder / "truth_elevation.png");
  const std::string marks = " S marks the start, G the goal.";
  in.pictures.push_back({"elevation.png", "estimated elevation map",
                         "Estimated elevation map with every planned path (red), the estimated "
                         "trajectory (orange) and the true one (blue); unknown cells are "
                         "checkered, drops magenta." +
                             marks});
  if (truth) {
    in.pictures.push_back({"truth_elevation.png",
                           "true elevation map, true optimal path (red), true trajectory (blue)",
                           ""});
  }
  in.pictures.push_back({"traversability.png", "traversability, estimated map",
                         "Where the planner may go, on the estimated map at the end (the robot "
                         "widened by the follower's safety margin, as the mission planned) and on "
                         "the true map (as scored and as the optimum was planned). " +
                             TraversabilityLegend()});
  if (truth) {
    in.pictures.push_back({"truth_traversability.png",
                           "traversability, true map, true trajectory (blue; ringed where it "
                           "crossed forbidden cells)",
                           ""});
  }
  if (std::filesystem::exists(in.folder / "hazard_errors.png")) {
    in.pictures.push_back({"hazard_errors.png", "hazard errors of the final map",
                           "Where the final map's hazards are wrong (map_hazards in the "
                           "metrics). " +
                               HazardErrorsLegend()});
  }
  if (std::filesystem::exists(in.folder / "last_plan.png")) {
    in.pictures.push_back(
        {"last_plan.png", "the last plan of the failed run, on the grid it was made on",
         "Stop " + std::to_string(r.last_plan_stop) +
             "'s traversability as the mission planned on it (its refuted gaps and recoveries "
             "included), its plan (red) and the run's tracks: estimated (orange), true (blue)." +
             marks});
  }
  in.trajectories = {{"estimated", "#e08000", TrajectoryXy(r, false), false},
                     {"true", "#1e50ff", TrajectoryXy(r, true), true}};
  in.markers = {{"start", "#111111", c.start.head<2>()}, {"goal", "#d01010", c.goal}};
  AddStops(in, r);
  in.scene_json = SceneJson(BuildRunScene(c, r, final_map));
  in.files = FolderFiles(in.folder);
  in.files.push_back("report.html");
  std::sort(in.files.begin(), in.files.end());
  return in;
}

void WriteRunReport(RunFolder& folder, const RunContext& c, const MissionResult& r,
                    const nlohmann::json& metrics, const FinalMap& final_map) {
  const Result<ThreeJs> three = LoadThreeJs(DefaultThreeJsDir());
  if (!three) {
    std::cerr << "warning: report.html without its 3D view: " << three.error().message << "\n";
  }
  WriteTextFile(folder.File("report.html"),
                RenderRunReport(GatherRunReport(folder, c, r, metrics, final_map), three));
}

}  // namespace pitchlab::mission
