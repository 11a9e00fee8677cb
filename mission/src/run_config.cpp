#include "pitchlab/mission/run_config.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// Scan-to-map registration as the mission runs it, where it differs from the pairwise defaults
// (registration_eval's); a key the config's registration section gives wins.
struct MissionRegistrationDefault {
  const char* key;
  double mapping::RegistrationConfig::*field;
  double value;
};
constexpr MissionRegistrationDefault kMissionRegistration[] = {
    // A drive into a room sees mostly new ground: the first scan through the office's goal-room
    // door shares 8.8-14.5 % of its points with the map (seeds 1..20), and each was right to
    // 1-7 cm / 0.2 deg. Refused at 15 %, the map never grew into the room: every later stop there
    // fitted 0 % and took odometry (10 of 20 runs). What fits at a low share is judged as any fit
    // is: the odometry bound, the degeneracy checks (odometry keeps what the overlap leaves free),
    // free space and the measured tilt. The share only says whether there is overlap at all.
    {"min_inlier_ratio", &mapping::RegistrationConfig::min_inlier_ratio, 0.05},
    // A pose 2 m or more from odometry is the scan matched to a neighbouring copy of repeated
    // structure (the office's doors and desk rows, 2 m apart), not the robot's motion; within it
    // the odometry's own bound (run.odometry_error_*) decides. Gyro-aided odometry drifts a few
    // per cent indoors (office: 0.2 m at most between stops), but slips 1-2.5 m on rugged ground;
    // at 1 m the correct poses were rejected (1.05-2.5 m off odometry) and the failures cascaded,
    // the error growing with every stop (terrain seeds 1..40: 36 -> 37 runs succeeded, seeds 9 and
    // 20 no longer lose their way; office, urban 40/40 either way).
    {"constraint_translation_m", &mapping::RegistrationConfig::constraint_translation_m, 2.0},
    // A stop entering a new room fits 20-30 % of its points to the map at 18-29 mm RMS (the
    // inliers crowd the map's edges) with a step error no worse than odometry's. Rejected (the
    // pairwise 17 mm then), the scan stays out of the map, the next stop overlaps the map less,
    // and failures cascade: office 16/20 runs succeeded vs 19/20 at 0.06 m.
    {"max_rmse_m", &mapping::RegistrationConfig::max_rmse_m, 0.06},
    // Along a direction the scene leaves free (an office corridor's axis) the pose comes from
    // odometry within its bound (run.odometry_error_*): still the best estimate there is, and
    // merged the map keeps growing. The pairwise default (5 cm / 0.5 deg) reports it undetermined.
    {"carry_max_m", &mapping::RegistrationConfig::carry_max_m, 2.0},
    {"carry_max_deg", &mapping::RegistrationConfig::carry_max_deg, 10.0},
};

void ApplyMissionRegistrationDefaults(const YAML::Node& section, mapping::RegistrationConfig& r) {
  for (const MissionRegistrationDefault& d : kMissionRegistration) {
    if (!section || !section[d.key]) r.*d.field = d.value;
  }
}
constexpr double kMissionUnknownPenalty = 5.0;
// Paths keep off hazards where the ground leaves room: wheel odometry slips 0.2-0.5 m over a few
// metres of rugged ground, and a path that hugs the footprint's margin around a crack's end took
// the robot into it (terrain seeds 9 and 11: crossed 9 and 1 true hazard cells, tilted to 31 deg).
// Half a metre of clearance at up to 1 (a cell's entry costs 0.3-0.6 on rough ground).
constexpr double kMissionClearance_m = 0.5;
constexpr double kMissionClearanceCost = 1.0;
// The P3-AT's 35 % grade (19.3 deg) is the bare robot's. With the LMS200 on its pitching mount
// (4.5 kg, 0.45 m up) the loaded robot tips forward at 31 deg standing (sim/README.md), less
// braking downhill, sweeping the laser down or over a rock on rough ground; planning to 19.3 deg
// took the terrain runs onto rims they tipped on (3 of 6 seeds). Runs plan to 16 deg unless the
// config says otherwise.
constexpr double kLoadedP3AtInclination_deg = 16.0;

double MissionInclinationLimit(const planning::RobotLimits& robot) {
  const double preset = robot.max_inclination_rad;
  return robot.name == "p3at" ? std::min(preset, kLoadedP3AtInclination_deg * kDegToRad) : preset;
}

void ReadRunSection(const YAML::Node& node, const std::string& source, RunSettings& s) {
  if (!node) return;
  if (!node.IsMap()) throw std::invalid_argument(source + ": 'run' must be a map");
  MissionConfig& m = s.mission;
  const std::map<std::string, double*> numbers = {
      {"goal_tolerance_m", &m.goal_tolerance_m},
      {"drive_per_stop_m", &m.drive_per_stop_m},
      {"time_budget_s", &m.time_budget_s},
      {"max_tilt_deg", &m.max_tilt_deg},
      {"caution_tilt_deg", &m.caution_tilt_deg},
      {"slope_tilt_deg", &m.slope_tilt_deg},
      {"scan_tilt_deg", &m.scan_tilt_deg},
      {"slope_speed_mps", &m.slope_speed_mps},
      {"stuck_timeout_s", &m.stuck_timeout_s},
      {"control_period_s", &m.control_period_s},
      {"cell_m", &s.cell_m},
      {"inclination_radius_m", &s.inclination_radius_m},
      {"safety_margin_m", &m.safety_margin_m},
      {"unknown_margin_m", &m.unknown_margin_m},
      {"drift_per_m", &m.drift_per_m},
      {"map_range_m", &m.map_range_m},
      {"odometry_error_m", &m.odometry_error_m},
      {"odometry_error_per_m", &m.odometry_error_per_m},
      {"odometry_error_level_per_m", &m.odometry_error_level_per_m},
      {"odometry_error_per_rad", &m.odometry_error_per_rad},
      {"odometry_error_deg", &m.odometry_error_deg},
      {"odometry_error_dps", &m.odometry_error_dps},
      {"tilt_tolerance_deg", &m.tilt_tolerance_deg},
      {"lookahead_m", &m.follower.lookahead_m},
      {"max_speed_mps", &m.follower.max_speed_mps},
      {"max_yaw_rate_rps", &m.follower.max_yaw_rate_rps}};
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    try {
      if (key == "map_size_m") {
        s.map_size_m = kv.second.as<double>();
        if (!(*s.map_size_m >= 2.0 && *s.map_size_m <= 2000.0)) {
          throw std::invalid_argument("= " + NumberText(*s.map_size_m) +
                                      " is outside 2 .. 2000 m");
        }
      } else if (key == "max_stops") {
        m.max_stops = kv.second.as<int>();
      } else if (key == "loop_closure") {
        // MapBuilder's loop closure (mapping/README.md); off by default, so every figure measured
        // without it stays.
        m.registration.loop_closure.enabled = kv.second.as<bool>();
      } else if (key == "calibrate_mount") {
        // MissionConfig::calibrate_mount; on by default.
        m.calibrate_mount = kv.second.as<bool>();
      } else if (key == "set_lines_right") {
        // MissionConfig::set_lines_right; off by default, as every figure was measured.
        m.set_lines_right = kv.second.as<bool>();
      } else if (key == "reverse") {
        // PurePursuitConfig::reverse: a path that starts behind is driven backwards; on by default.
        m.follower.reverse = kv.second.as<bool>();
      } else if (key == "algorithm") {
        m.algorithm = planning::ParseAlgorithm(kv.second.as<std::string>());
      } else if (auto it = numbers.find(key); it != numbers.end()) {
        *it->second = kv.second.as<double>();
      } else {
        throw std::invalid_argument("is not a known setting");
      }
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(source + ": run." + key + " has the wrong type");
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(source + ": run." + key + " " + e.what());
    }
  }
  if (!(s.cell_m >= 0.02 && s.cell_m <= 2.0)) {
    throw std::invalid_argument(source + ": run.cell_m = " + NumberText(s.cell_m) +
                                " is outside 0.02 .. 2 m");
  }
  for (const auto& [name, value] : {std::pair{"odometry_error_m", m.odometry_error_m},
                                    {"odometry_error_per_m", m.odometry_error_per_m},
                                    {"odometry_error_level_per_m", m.odometry_error_level_per_m},
                                    {"odometry_error_per_rad", m.odometry_error_per_rad},
                                    {"odometry_error_deg", m.odometry_error_deg},
                                    {"odometry_error_dps", m.odometry_error_dps},
                                    {"drift_per_m", m.drift_per_m}}) {
    if (!(value >= 0 && std::isfinite(value))) {
      throw std::invalid_argument(source + ": run." + name + " = " + NumberText(value) +
                                  " must be finite and >= 0");
    }
  }
  if (!(m.tilt_tolerance_deg > 0 && m.tilt_tolerance_deg <= 90)) {
    throw std::invalid_argument(source + ": run.tilt_tolerance_deg = " +
                                NumberText(m.tilt_tolerance_deg) + " is outside (0, 90] deg");
  }
  if (m.max_stops < 1 || !(m.drive_per_stop_m > 0) || !(m.goal_tolerance_m > 0) ||
      !(m.time_budget_s > 0) || !(m.control_period_s > 0)) {
    throw std::invalid_argument(source +
                                ": run: max_stops, drive_per_stop_m, goal_tolerance_m, "
                                "time_budget_s and control_period_s must be positive");
  }
}

}  // namespace

RunSettings ParseRunSettings(const std::string& yaml_text, const std::string& source,
                             sim::P3Model model) {
  RunSettings s;
  MissionConfig& m = s.mission;
  // The mission explores: unknown cells are allowed at a price, not forbidden.
  m.planner.unknown = planning::UnknownPolicy::kPenalise;
  m.planner.unknown_penalty = kMissionUnknownPenalty;  // prefer ground that has been seen
  m.planner.robot = planning::RobotLimits::Preset(model == sim::P3Model::kP3AT ? "p3at" : "p3dx");
  m.planner.robot.max_inclination_rad = MissionInclinationLimit(m.planner.robot);
  m.planner.clearance_m = kMissionClearance_m;
  m.planner.clearance_cost = kMissionClearanceCost;
  ApplyMissionRegistrationDefaults(YAML::Node(), m.registration.registration);
  YAML::Node root;
  try {
    root = yaml_text.empty() ? YAML::Node() : YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": not valid YAML: " + e.what());
  }
  if (root.IsMap()) {
    ReadRunSection(root["run"], source, s);
    if (root["planner"]) {
      const planning::UnknownPolicy policy = m.planner.unknown;
      const double penalty = m.planner.unknown_penalty;
      // Keys the section leaves out keep the run's defaults, not the planner tool's: the robot's
      // preset first (its limits may then be overridden one by one), the unknown-cell policy.
      YAML::Node section = YAML::Clone(root["planner"]);
      if (!section["robot"]) section["robot"] = m.planner.robot.name;
      m.planner = planning::ParsePlannerConfig(YAML::Dump(section), source + ": planner");
      if (!section["unknown"]) m.planner.unknown = policy;
      if (!section["max_inclination_deg"]) {
        m.planner.robot.max_inclination_rad = MissionInclinationLimit(m.planner.robot);
      }
      if (!section["unknown_penalty"]) m.planner.unknown_penalty = penalty;
      if (!section["clearance_m"]) m.planner.clearance_m = kMissionClearance_m;
      if (!section["clearance_cost"]) m.planner.clearance_cost = kMissionClearanceCost;
    }
    m.registration.registration = mapping::ParseRegistrationConfig(yaml_text, source);
    ApplyMissionRegistrationDefaults(root["registration"], m.registration.registration);
  }
  if (!(m.slope_tilt_deg > 0 && m.slope_tilt_deg < m.caution_tilt_deg &&
        m.caution_tilt_deg < m.max_tilt_deg) ||
      !(m.scan_tilt_deg > 0 && m.scan_tilt_deg < m.caution_tilt_deg) || !(m.slope_speed_mps > 0)) {
    throw std::invalid_argument(source +
                                ": run: need 0 < slope_tilt_deg < caution_tilt_deg < "
                                "max_tilt_deg, 0 < scan_tilt_deg < caution_tilt_deg and "
                                "slope_speed_mps > 0");
  }
  if (!(m.map_range_m > 1.0)) {
    throw std::invalid_argument(source + ": run.map_range_m = " + NumberText(m.map_range_m) +
                                " must be > 1 m (the robot needs to see past its own footprint)");
  }
  if (!(s.inclination_radius_m >= 0 && s.inclination_radius_m <= 16 * s.cell_m)) {
    throw std::invalid_argument(
        source + ": run.inclination_radius_m = " + NumberText(s.inclination_radius_m) +
        " is outside 0 .. 16 cells");
  }
  // The region reaches inclination_radius_m from the centre cell's centre to its outer edge.
  m.layers.inclination_radius_cells = std::max(
      1, static_cast<int>(std::lround((s.inclination_radius_m - 0.5 * s.cell_m) / s.cell_m)));
  m.follower.Validate();
  return s;
}

std::string RunSettingsToYaml(const RunSettings& s) {
  const MissionConfig& m = s.mission;
  const planning::PlannerConfig& p = m.planner;
  std::ostringstream os;
  os.precision(17);
  os << "run:\n"
     << "  goal_tolerance_m: " << m.goal_tolerance_m << "\n"
     << "  drive_per_stop_m: " << m.drive_per_stop_m << "\n"
     << "  max_stops: " << m.max_stops << "\n"
     << "  time_budget_s: " << m.time_budget_s << "\n"
     << "  max_tilt_deg: " << m.max_tilt_deg << "\n"
     << "  caution_tilt_deg: " << m.caution_tilt_deg << "\n"
     << "  slope_tilt_deg: " << m.slope_tilt_deg << "\n"
     << "  scan_tilt_deg: " << m.scan_tilt_deg << "\n"
     << "  slope_speed_mps: " << m.slope_speed_mps << "\n"
     << "  stuck_timeout_s: " << m.stuck_timeout_s << "\n"
     << "  control_period_s: " << m.control_period_s << "\n"
     << "  cell_m: " << s.cell_m << "\n"
     << "  inclination_radius_m: " << s.inclination_radius_m << "\n"
     << (s.map_size_m ? "  map_size_m: " + std::to_string(*s.map_size_m) + "\n" : std::string())
     << "  safety_margin_m: " << m.safety_margin_m << "\n"
     << "  unknown_margin_m: " << m.unknown_margin_m << "\n"
     << "  drift_per_m: " << m.drift_per_m << "\n"
     << "  map_range_m: " << m.map_range_m << "\n"
     << "  loop_closure: " << (m.registration.loop_closure.enabled ? "true" : "false") << "\n"
     << "  set_lines_right: " << (m.set_lines_right ? "true" : "false") << "\n"
     << "  calibrate_mount: " << (m.calibrate_mount ? "true" : "false") << "\n"
     << "  odometry_error_m: " << m.odometry_error_m << "\n"
     << "  odometry_error_per_m: " << m.odometry_error_per_m << "\n"
     << "  odometry_error_level_per_m: " << m.odometry_error_level_per_m << "\n"
     << "  odometry_error_per_rad: " << m.odometry_error_per_rad << "\n"
     << "  odometry_error_deg: " << m.odometry_error_deg << "\n"
     << "  odometry_error_dps: " << m.odometry_error_dps << "\n"
     << "  tilt_tolerance_deg: " << m.tilt_tolerance_deg << "\n"
     << "  algorithm: " << planning::ToString(m.algorithm) << "\n"
     << "  lookahead_m: " << m.follower.lookahead_m << "\n"
     << "  max_speed_mps: " << m.follower.max_speed_mps << "\n"
     << "  max_yaw_rate_rps: " << m.follower.max_yaw_rate_rps << "\n"
     << "  reverse: " << (m.follower.reverse ? "true" : "false") << "\n"
     << "planner:\n"
     << "  robot: " << p.robot.name << "\n"
     << "  step_max_m: " << p.robot.step_max_m << "\n"
     << "  max_inclination_deg: " << p.robot.max_inclination_rad / kDegToRad << "\n"
     << "  width_m: " << p.robot.width_m << "\n"
     << "  weights: {roughness: " << p.weights.roughness << ", length: " << p.weights.length
     << ", inclination_x: " << p.weights.inclination_x
     << ", inclination_y: " << p.weights.inclination_y << "}\n"
     << "  unknown: " << (p.unknown == planning::UnknownPolicy::kForbid ? "forbid" : "penalise")
     << "\n"
     << "  unknown_penalty: " << p.unknown_penalty << "\n"
     << "  clearance_m: " << p.clearance_m << "\n"
     << "  clearance_cost: " << p.clearance_cost << "\n"
     << mapping::RegistrationConfigToYaml(m.registration.registration);
  return os.str();
}

}  // namespace pitchlab::mission
