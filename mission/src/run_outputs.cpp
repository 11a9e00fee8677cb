#include "pitchlab/mission/run_outputs.hpp"
#include "pitchlab/mission/loop_closure_metrics.hpp"
#include "pitchlab/mission/odometry_drift.hpp"
#include "pitchlab/mission/registration_json.hpp"
#include "pitchlab/mission/trajectory_outputs.hpp"
#include "run_pictures.hpp"
#include "run_report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <sstream>
#include <stdexcept>

#include <GeographicLib/LocalCartesian.hpp>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/planning/path_io.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"
#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

template <typename T>
void Check(const Result<T>& r) {
  if (!r) throw std::runtime_error(r.error().message);
}

nlohmann::json PoseJson(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d t = T.translation();
  const Eigen::Matrix3d R = T.linear();
  return {{"x_m", t.x()},
          {"y_m", t.y()},
          {"z_m", t.z()},
          {"roll_deg", std::atan2(R(2, 1), R(2, 2)) * kRadToDeg},
          {"pitch_deg", std::asin(std::clamp(-R(2, 0), -1.0, 1.0)) * kRadToDeg},
          {"yaw_deg", std::atan2(R(1, 0), R(0, 0)) * kRadToDeg}};
}

void WriteTrajectoryCsv(const std::filesystem::path& file, const MissionResult& r, bool truth) {
  std::ostringstream os;
  os.precision(10);
  os << "stamp_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n";
  for (const TrajectorySample& s : r.trajectory) {
    if (truth && !s.T_world_base_true) continue;
    const nlohmann::json p = PoseJson(truth ? *s.T_world_base_true : s.T_world_base_est);
    os << s.stamp_s << "," << p["x_m"].get<double>() << "," << p["y_m"].get<double>() << ","
       << p["z_m"].get<double>() << "," << p["roll_deg"].get<double>() << ","
       << p["pitch_deg"].get<double>() << "," << p["yaw_deg"].get<double>() << "\n";
  }
  WriteTextFile(file, os.str());
}

void WriteTrajectoryGeoJson(const std::filesystem::path& file, const MissionResult& r,
                            const mapping::GeodeticOrigin& origin) {
  const GeographicLib::LocalCartesian enu(origin.latitude_deg, origin.longitude_deg,
                                          origin.height_m);
  nlohmann::json features = nlohmann::json::array();
  for (bool truth : {false, true}) {
    nlohmann::json coords = nlohmann::json::array();
    for (const TrajectorySample& s : r.trajectory) {
      if (truth && !s.T_world_base_true) continue;
      const Eigen::Vector3d p = (truth ? *s.T_world_base_true : s.T_world_base_est).translation();
      double lat, lon, h;
      enu.Reverse(p.x(), p.y(), p.z(), lat, lon, h);
      coords.push_back({lon, lat, h});
    }
    if (coords.size() < 2) continue;
    features.push_back(
        {{"type", "Feature"},
         {"properties", {{"name", truth ? "true trajectory" : "estimated trajectory"}}},
         {"geometry", {{"type", "LineString"}, {"coordinates", coords}}}});
  }
  WriteTextFile(file,
                nlohmann::json{{"type", "FeatureCollection"}, {"features", features}}.dump(1));
}

// The waypoints a mission drove through before its goal, and how many it reached.
nlohmann::json RouteJson(const RunContext& c, const MissionResult& r) {
  nlohmann::json via = nlohmann::json::array();
  for (const Eigen::Vector2d& p : c.via) via.push_back({{"x_m", p.x()}, {"y_m", p.y()}});
  return {{"via", via}, {"waypoints_reached", r.waypoints_reached}};
}

nlohmann::json RegistrationJson(const StopRecord& stop) {
  const mapping::RegistrationResult& reg = stop.merge.registration;
  nlohmann::json matrix = nlohmann::json::array();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) matrix.push_back(stop.merge.T_map_base.matrix()(i, j));
  nlohmann::json j = {
      {"stop", stop.index},
      {"stamp_s", stop.stamp_s},
      {"merged", stop.merge.merged},
      {"elevation_from_odometry", stop.elevation_from_odometry},
      {"height_fit", stop.height_fit ? nlohmann::json{{"dz_m", stop.height_fit->dz_m},
                                                      {"cells", stop.height_fit->cells}}
                                     : nlohmann::json()},
      {"elevation_cells_filled", stop.elevation_cells_filled},
      {"line_pitch", stop.line_pitch ? LinePitchJson(*stop.line_pitch) : nlohmann::json()},
      {"deskewed", stop.scan.deskewed},
      {"deskew_deg", stop.scan.deskew_max_rad * kRadToDeg},
      {"prior_bound", stop.index == 0
                          ? nlohmann::json()
                          : nlohmann::json{{"translation_m", stop.prior_bound.translation_m},
                                           {"rotation_deg", stop.prior_bound.rotation_deg}}},
      {"driven_m", stop.driven_m},
      {"turned_off_level_deg", stop.turned_rad * kRadToDeg},
      {"success", reg.success},
      {"reason", reg.reason},
      {"path", mapping::ToString(reg.path)},
      {"fitness_m2", reg.fitness_m2},
      {"rmse_m", reg.rmse_m},
      {"inlier_ratio", reg.inlier_ratio},
      {"iterations", reg.iterations},
      {"timings_s", StageTimingsJson(reg.timings)},
      {"T_map_base", matrix},
      {"estimate", PoseJson(stop.T_world_base)},
      {"odometry", PoseJson(stop.T_world_base_odom)},
      {"observability", ObservabilityJson(reg)}};
  if (stop.T_world_base_true) {
    const Eigen::Isometry3d d = stop.T_world_base_true->inverse() * stop.T_world_base;
    j["truth"] = PoseJson(*stop.T_world_base_true);
    j["error"] = {{"translation_m", d.translation().norm()},
                  {"rotation_deg", Eigen::AngleAxisd(d.linear()).angle() * kRadToDeg}};
    // The truth is the pose after the scan. On rough ground the robot rocks while the laser nods
    // (terrain: 0.2 deg median, 2.2 deg p95, 12 deg at most), its lines come from different poses
    // and no single pose is the scan's: this says how far from one this stop's truth is (a
    // deskewed scan's truth is already the pose after it; deskew_deg says how much it turned).
    if (stop.scan.has_truth && !stop.scan.deskewed) {
      const Eigen::Isometry3d m = stop.scan.T_world_base.inverse() * *stop.T_world_base_true;
      j["truth_moved_during_scan"] = {
          {"translation_m", m.translation().norm()},
          {"rotation_deg", Eigen::AngleAxisd(m.linear()).angle() * kRadToDeg}};
    }
  }
  // Loop closure on: each earlier scan registered against this one, and the pose graph's verdict.
  if (!stop.merge.loop_attempts.empty()) {
    nlohmann::json loops = nlohmann::json::array();
    for (const mapping::LoopAttempt& a : stop.merge.loop_attempts) {
      loops.push_back({{"target_scan_index", a.target_scan_index},
                       {"graph_distance_m", a.candidate.distance_m},
                       {"graph_uncertainty_m", a.candidate.uncertainty_m},
                       {"success", a.registration.success},
                       {"path", mapping::ToString(a.registration.path)},
                       {"inlier_ratio", a.registration.inlier_ratio},
                       {"reason", a.registration.reason},
                       {"tested", a.tested},
                       {"accepted", a.tested && a.decision.accepted},
                       {"chi2_increase", a.tested ? nlohmann::json(a.decision.chi2_increase)
                                                  : nlohmann::json()}});
    }
    j["loops"] = loops;
  }
  // The plan of this stop: how it was found, or why there was none.
  j["plan"] = {{"found", stop.plan.has_value()},
               {"known_m", stop.plan_known_m},
               {"clear_m", stop.plan_clear_m},
               {"felt_hazards", stop.felt_hazards},
               {"look_closer", stop.look_closer}};
  if (!stop.plan_note.empty()) j["plan"]["note"] = stop.plan_note;
  if (!stop.plan_error.empty()) j["plan"]["error"] = stop.plan_error;
  return j;
}

}  // namespace

void WriteStopOutputs(RunFolder& folder, const StopRecord& stop, const MissionResult& so_far,
                      const std::optional<mapping::GeodeticOrigin>& origin,
                      const std::string& world) {
  WriteStopOutputs(folder, stop, ViewOfStop(so_far, stop.plan), origin, world);
}

void WriteStopOutputs(RunFolder& folder, const StopRecord& stop, const StopView& view,
                      const std::optional<mapping::GeodeticOrigin>& origin,
                      const std::string& world) {
  char dir[32];
  std::snprintf(dir, sizeof(dir), "stops/%03d/", stop.index);
  const std::string d = dir;
  sensors::Scan3D scan = stop.scan;
  scan.world = world;
  Check(sensors::WriteScanPcd(scan, folder.File(d + "scan.pcd").string()));
  WriteTextFile(folder.File(d + "registration.json"), RegistrationJson(stop).dump(2));
  if (stop.plan) {
    Check(planning::WritePathCsv(*stop.plan, folder.File(d + "path.csv").string()));
    if (origin) {
      Check(
          planning::WritePathGeoJson(*stop.plan, origin, folder.File(d + "path.geojson").string()));
    }
  }
  WriteStopPictures(folder, d, view);
}

namespace {

nlohmann::json KindsJson(const HazardKinds& k) {
  return {{"step", k.step}, {"drop", k.drop}, {"too_steep", k.too_steep}};
}

nlohmann::json Degrees(const Eigen::Vector3d& rad) {
  return {rad.x() * kRadToDeg, rad.y() * kRadToDeg, rad.z() * kRadToDeg};
}

// The mount calibration at the first stop: what it found (roll, pitch, yaw added to the nominal
// mount, their sigmas, the floor's fit), or why it found nothing; in simulation also the drawn
// error and the largest difference from it.
nlohmann::json MountCalibrationJson(const RunContext& c, const MissionResult& r) {
  if (!r.mount_calibration) return {{"calibrated", false}, {"note", r.mount_calibration_note}};
  const mapping::MountFromFloor& f = *r.mount_calibration;
  nlohmann::json j = {{"calibrated", true},
                      {"correction_rpy_deg", Degrees(f.correction_rpy_rad)},
                      {"sigma_rpy_deg", Degrees(f.sigma_rpy_rad)},
                      {"floor_tilt_before_deg", f.tilt_before_rad * kRadToDeg},
                      {"floor_residual_m", f.residual_m},
                      {"floor_points", f.points}};
  if (c.mount_error_rpy_rad) {
    j["truth_rpy_deg"] = Degrees(*c.mount_error_rpy_rad);
    j["max_error_deg"] =
        (f.correction_rpy_rad - *c.mount_error_rpy_rad).cwiseAbs().maxCoeff() * kRadToDeg;
  }
  return j;
}

}  // namespace

nlohmann::json RunMetrics(const RunContext& c, const MissionResult& r,
                          const std::optional<RunScore>& score) {
  const double sim_s = r.end_s - r.start_s;
  nlohmann::json m = {
      {"success", r.success},
      {"reason", r.reason},
      {"world", c.world},
      {"robot", c.robot},
      {"seed", c.seed},
      {"start", {{"x_m", c.start.x()}, {"y_m", c.start.y()}, {"yaw_deg", c.start.z() * kRadToDeg}}},
      {"goal", {{"x_m", c.goal.x()}, {"y_m", c.goal.y()}}},
      {"stops", r.stops.size()},
      {"sim_time_s", sim_s},
      {"wall_time_s", c.wall_time_s},
      {"real_time_factor", c.wall_time_s > 0 ? sim_s / c.wall_time_s : 0.0},
      {"odometry_distance_m", r.odometry_distance_m},
      {"max_tilt_deg", r.max_tilt_rad * kRadToDeg}};
  if (c.stages) m["stages"] = StagesJson(*c.stages);
  std::size_t failed = 0;
  for (const StopRecord& s : r.stops) failed += !s.merge.merged && s.index > 0;
  m["registration_failures"] = failed;
  // What run.drift_per_m plans for, as this run's registered scans measured it.
  const OdometryDrift drift = MeasureOdometryDrift(r.stops);
  m["odometry_drift"] = {{"drives", drift.drives},
                         {"median_per_m", drift.median_per_m},
                         {"p90_per_m", drift.p90_per_m},
                         {"max_per_m", drift.max_per_m}};
  if (!r.stops.empty()) m["final_estimate"] = PoseJson(r.stops.back().T_world_base);
  if (!c.via.empty()) m["route"] = RouteJson(c, r);  // run --via, --round-trip
  if (c.loop_closure) m["loop_closures"] = LoopClosureJson(r);  // run: {loop_closure: true}
  if (r.mount_calibration || !r.mount_calibration_note.empty()) {
    m["mount_calibration"] = MountCalibrationJson(c, r);  // run: {calibrate_mount: true}
  }
  // The stops' ATE and RPE at their final poses (null without truth); with loop closure also as
  // they were registered, before later loops moved them.
  m["trajectory_error"] = TrajectoryErrorJson(r, StopPoses::kFinal);
  if (c.loop_closure) m["trajectory_error_live"] = TrajectoryErrorJson(r, StopPoses::kLive);
  if (score) {
    m["distance_m"] = score->true_distance_m;
    m["final_pose_error"] = {{"translation_m", score->final_translation_error_m},
                             {"rotation_deg", score->final_rotation_error_deg}};
    m["final_true_distance_to_goal_m"] = score->final_distance_to_goal_m;
    m["max_registration_error"] = {{"translation_m", score->max_registration_translation_error_m},
                                   {"rotation_deg", score->max_registration_rotation_error_deg}};
    m["registration_step_error"] = {{"steps", score->registration_steps},
                                    {"p95_m", score->registration_step_p95_m},
                                    {"max_m", score->registration_step_max_m},
                                    {"p95_deg", score->registration_step_p95_deg},
                                    {"max_deg", score->registration_step_max_deg}};
    m["max_tilt_deg"] = score->max_true_tilt_deg;
    m["path_cost_on_true_map"] = score->driven_cost_on_true_map;
    m["true_optimal_cost"] =
        score->true_optimal_cost ? nlohmann::json(*score->true_optimal_cost) : nlohmann::json();
    if (!score->true_optimum_note.empty()) m["true_optimum_note"] = score->true_optimum_note;
    m["cost_ratio"] =
        score->cost_ratio && r.success ? nlohmann::json(*score->cost_ratio) : nlohmann::json();
    m["forbidden_cells_crossed"] = score->forbidden_cells_crossed;
    m["hazard_cells_crossed"] = score->hazard_cells_crossed;
    m["hazard_cells_crossed_as"] = KindsJson(score->crossed_as);
    nlohmann::json touched = KindsJson(score->touched);
    touched["steepest_deg"] = score->touched_steepest_deg;
    touched["too_steep_limit_deg"] = score->too_steep_limit_deg;
    m["hazards_touched"] = touched;
    m["map_hazards"] = {{"cells_compared", score->map_cells_compared},
                        {"false_hazard_cells", score->false_hazard_cells},
                        {"false_hazard_cells_out_of_reach",
                         score->false_hazard_cells_out_of_reach},
                        {"false_as", KindsJson(score->false_as)},
                        {"missed_hazard_cells", score->missed_hazard_cells},
                        {"missed_as", KindsJson(score->missed_as)},
                        {"missed_too_steep_tilt",
                         {{"map_median_deg", score->missed_steep_map_tilt_deg},
                          {"truth_median_deg", score->missed_steep_true_tilt_deg},
                          {"map_unsupported", score->missed_steep_tilt_unknown}}}};
    nlohmann::json tilts = nlohmann::json::array();
    for (const TiltAgainstTruth& t : score->tilt_against_truth) {
      tilts.push_back({{"true_from_deg", t.lo_deg},
                       {"true_to_deg", t.hi_deg},
                       {"cells", t.cells},
                       {"map_unsupported", t.unsupported},
                       {"median_error_deg", t.median_error_deg},
                       {"p10_error_deg", t.p10_error_deg},
                       {"p90_error_deg", t.p90_error_deg}});
    }
    m["map_tilt_against_truth"] = tilts;
    if (std::isfinite(score->closest_hazard_m)) {
      m["closest_approach_to_forbidden_m"] = score->closest_hazard_m;
      m["closest_approach_at"] = {{"x_m", score->closest_hazard_at.x()},
                                  {"y_m", score->closest_hazard_at.y()}};
    } else {
      m["closest_approach_to_forbidden_m"] = nullptr;
    }
  }
  return m;
}

FinalMap MakeFinalMap(const RunContext& c, const MissionResult& r) {
  FinalMap final_map{mapping::ComputeLayers(r.elevation, c.layers), {}};
  final_map.grid = planning::BuildTraversability(final_map.layers, c.planner);
  return final_map;
}

void WriteFinalOutputs(RunFolder& folder, const RunContext& c, const MissionResult& r,
                       const std::optional<RunScore>& score, const TruthMaps* truth) {
  const FinalMap final_map = MakeFinalMap(c, r);
  WriteFinalData(folder, c, r, final_map, truth);
  WriteSummary(folder, c, r, score, final_map);
}

void WriteFinalData(RunFolder& folder, const RunContext& c, const MissionResult& r,
                    const FinalMap& final_map, const TruthMaps* truth) {
  WriteTextFile(folder.File("config.yaml"), c.config_yaml);
  // The map's cloud and cells on a thread of their own beside the rest (the run waits for its
  // final files).
  std::future<void> map_files = std::async(std::launch::async, [&] {
    const sensors::WorkerThread worker;  // the run's outputs, done beside it
    sensors::Scan3D cloud;
    for (const Eigen::Vector3f& p : r.map_cloud_world) {
      sensors::ScanPoint q;
      q.x = p.x(), q.y = p.y(), q.z = p.z();
      cloud.points.push_back(q);
    }
    cloud.world = std::filesystem::path(c.world_file).stem().string();  // in the world's frame
    Check(sensors::WriteScanPcd(cloud, folder.File("map_cloud.pcd").string()));
    Check(mapping::SaveElevationMap(r.elevation, folder.File("elevation.plem").string()));
  });
  Check(mapping::WriteEsriAsciiGrid(final_map.layers, c.geodetic_origin,
                                    folder.File("elevation.asc").string()));
  WriteTrajectoryCsv(folder.File("trajectory_estimated.csv"), r, false);
  WriteTrajectoryCsv(folder.File("trajectory_true.csv"), r, true);
  WriteStopTrajectories(folder, r, c.loop_closure);
  if (c.geodetic_origin) {
    WriteTrajectoryGeoJson(folder.File("trajectories.geojson"), r, *c.geodetic_origin);
  }
  WriteRunPictures(folder, c, r, final_map, truth);
  map_files.get();
}

void WriteSummary(RunFolder& folder, const RunContext& c, const MissionResult& r,
                  const std::optional<RunScore>& score, const FinalMap& final_map) {
  const nlohmann::json metrics = RunMetrics(c, r, score);
  WriteTextFile(folder.File("metrics.json"), metrics.dump(2));

  WriteRunReport(folder, c, r, metrics, final_map);
}

}  // namespace pitchlab::mission
