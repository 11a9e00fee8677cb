#include "report_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pitchlab/mission/stage_times.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mission {
namespace {

// The report prints distances to 0.1 m, the elevation map's usual cell: closer than half of
// that reads as 0.0 m, i.e. on the hazard cell's edge.
constexpr double kTouch_m = 0.05;

const nlohmann::json* At(const nlohmann::json& j, const std::string& path) {
  const nlohmann::json* p = &j;
  std::size_t from = 0;
  while (true) {
    const std::size_t dot = path.find('.', from);
    const std::string key = path.substr(from, dot - from);
    if (!p->is_object() || !p->contains(key)) return nullptr;
    p = &(*p)[key];
    if (dot == std::string::npos) break;
    from = dot + 1;
  }
  return p->is_null() ? nullptr : p;
}

std::string Count(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// metrics.json's hazards_touched in words ("4 too-steep cells (the steepest 16.4 deg; the
// limit 16 deg), 1 step cell"), or empty when it records none.
std::string TouchedText(const nlohmann::json& m) {
  const nlohmann::json* t = At(m, "hazards_touched");
  if (!t || !t->is_object()) return {};
  std::string text;
  const auto add = [&](const std::string& part) { text += (text.empty() ? "" : ", ") + part; };
  if (const std::size_t n = t->value("too_steep", std::size_t{0}); n > 0) {
    add(Count(n, "too-steep cell", "too-steep cells") + " (the steepest " +
        Significant(t->value("steepest_deg", 0.0)) + " deg; the limit " +
        Significant(t->value("too_steep_limit_deg", 0.0)) + " deg)");
  }
  if (const std::size_t n = t->value("step", std::size_t{0}); n > 0)
    add(Count(n, "step cell", "step cells"));
  if (const std::size_t n = t->value("drop", std::size_t{0}); n > 0)
    add(Count(n, "drop cell", "drop cells"));
  return text;
}

// A stage's words in the report.
const char* StageLabel(Stage stage) {
  switch (stage) {
    case Stage::kPhysicsDriving:
      return "physics while driving";
    case Stage::kPhysicsStanding:
      return "physics while standing to scan";
    case Stage::kRayCasting:
      return "ray casting (the scan's lines; wall: what the physics beside it did not hide)";
    case Stage::kRegistration:
      return "registration";
    case Stage::kMapUpdate:
      return "map update (elevation, layers)";
    case Stage::kTraversability:
      return "traversability";
    case Stage::kPlanning:
      return "planning";
    case Stage::kOutputs:
      return "outputs (the run folder's files; each stop's beside the mission)";
    case Stage::kGroundTruth:
      return "ground truth (beside the mission)";
    case Stage::kScoring:
      return "scoring against the truth";
  }
  return "?";
}

// A stage's number as the table shows it: below `floor` (a stopwatch reading of work that was
// not there, e.g. 4 us of the ground truth's wall when the mission had nothing left to wait for),
// "< floor", not digits of timer noise.
std::string Shown(const nlohmann::json& stage, const char* key, double scale, int digits,
                  double floor, const char* floor_text) {
  const auto v = stage.find(key);
  if (v == stage.end() || !v->is_number()) return "-";
  const double x = scale * v->get<double>();
  if (x > 0 && x < floor) return floor_text;
  return Significant(x, digits);
}

std::string Percent(const nlohmann::json& stage, const char* key) {
  return Shown(stage, key, 100.0, 2, 0.01, "< 0.01");
}

std::string Seconds(const nlohmann::json& stage, const char* key) {
  return Shown(stage, key, 1.0, 3, 0.001, "< 0.001");
}

}  // namespace

std::vector<std::string> StageHeader() {
  return {"stage", "wall [s]", "CPU [s]", "wall [%]", "CPU [%]"};
}

std::vector<std::vector<std::string>> StageRows(const nlohmann::json& m) {
  const nlohmann::json* stages = At(m, "stages");
  if (!stages || !stages->is_object()) return {};
  std::vector<std::vector<std::string>> rows;
  const auto row = [&](const std::string& key, const std::string& label) {
    const auto s = stages->find(key);
    if (s == stages->end() || !s->is_object()) return;
    rows.push_back({label, Seconds(*s, "wall_s"), Seconds(*s, "cpu_s"), Percent(*s, "wall_share"),
                    Percent(*s, "cpu_share")});
  };
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const Stage stage = static_cast<Stage>(i);
    row(StageKey(stage), StageLabel(stage));
  }
  row("other", "other (set-up: world, ray caster scene, placement; the loop's bookkeeping)");
  if (const nlohmann::json* run = At(*stages, "run"); run && run->is_object()) {
    rows.push_back({"whole run", Seconds(*run, "wall_s"), Seconds(*run, "cpu_s"), "100", "100"});
  }
  return rows;
}

std::string Significant(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  if (v == 0) return "0";
  if (v == std::round(v) && std::abs(v) >= std::pow(10.0, digits - 1)) {
    char buf[32];
    std::snprintf(buf, sizeof(buf), "%.0f", v);
    return buf;
  }
  const int magnitude = static_cast<int>(std::floor(std::log10(std::abs(v))));
  const int decimals = std::clamp(digits - 1 - magnitude, 0, 9);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

Outcome ReadOutcome(const nlohmann::json& m) {
  Outcome o;
  o.success = m.value("success", false);
  o.reason = m.value("reason", std::string("(no reason recorded)"));
  if (const auto* n = At(m, "hazard_cells_crossed"); n && n->get<std::size_t>() > 0) {
    o.safety.push_back("the true trajectory crossed " +
                       Count(n->get<std::size_t>(), "true hazard cell", "true hazard cells") +
                       " (step, drop or too steep)");
  }
  const auto* hazard = At(m, "hazard_cells_crossed");
  if (const auto* n = At(m, "forbidden_cells_crossed");
      n && n->get<std::size_t>() > (hazard ? hazard->get<std::size_t>() : 0)) {
    o.safety.push_back("it drove over " +
                       Count(n->get<std::size_t>(), "forbidden cell", "forbidden cells") +
                       " (closer to a true hazard than half the robot's width; ringed on the true "
                       "traversability picture)");
  }
  if (const auto* d = At(m, "closest_approach_to_forbidden_m"); d && d->get<double>() < kTouch_m) {
    o.safety.push_back("its centre came " + Significant(d->get<double>(), 2) +
                       " m from a true hazard cell");
  }
  // What those hazards were: a cell a fraction of a degree over the planner's slope limit (set
  // with a margin below where the robot tips) reads otherwise than a cliff's edge.
  if (!o.safety.empty()) {
    if (std::string what = TouchedText(m); !what.empty())
      o.safety.push_back("the true hazards under its footprint: " + what);
  }
  o.safe = o.safety.empty();
  o.headline = !o.success ? "Failed" : o.safe ? "Goal reached" : "Goal reached, but unsafe";
  return o;
}

std::vector<MetricRow> KeyMetrics(const nlohmann::json& m) {
  struct Spec {
    const char* key;
    const char* label;
    const char* unit;
    const char* note;
  };
  static const Spec kSpecs[] = {
      {"final_true_distance_to_goal_m", "distance to the goal at the end", "m", "true position"},
      {"distance_m", "distance driven", "m", "along the true trajectory"},
      {"sim_time_s", "mission time", "s", "simulated clock"},
      {"stops", "stops", "", "scan, register, plan, drive"},
      {"closest_approach_to_forbidden_m", "closest approach to a true hazard", "m",
       "robot centre to a step, drop or too-steep cell"},
      {"hazard_cells_crossed", "true hazard cells crossed", "", "0 is safe"},
      {"forbidden_cells_crossed", "forbidden cells crossed", "",
       "within half the robot's width of a hazard; 0 is safe"},
      {"cost_ratio", "path cost / optimal cost", "", "on the true map; 1 is optimal"},
      {"final_pose_error.translation_m", "final pose error", "m", "estimate against truth"},
      {"final_pose_error.rotation_deg", "final heading error", "deg", "estimate against truth"},
      {"max_registration_error.translation_m", "worst pose error at a stop", "m", ""},
      {"trajectory_error.ate.unaligned.rmse_m", "absolute trajectory error (RMSE)", "m",
       "the stops' estimates against truth, no alignment (the start is known)"},
      {"trajectory_error.ate.aligned.rmse_m", "absolute trajectory error, aligned", "m",
       "after the best rigid alignment (as trajectory-evaluation tools report)"},
      {"registration_step_error.p95_m", "registration step error, 95th percentile", "m",
       "motion between stops against truth"},
      {"registration_step_error.p95_deg", "registration step error, 95th percentile", "deg", ""},
      {"registration_failures", "registration failures", "", "stops that fell back to odometry"},
      {"mount_calibration.max_error_deg", "mount calibration error", "deg",
       "largest of roll, pitch, yaw found on the first stop's floor against the drawn error"},
      {"map_hazards.false_hazard_cells", "false hazard cells in the final map", "",
       "hazards where the truth is free, in the robot's reach"},
      {"map_hazards.missed_hazard_cells", "missed hazard cells in the final map", "",
       "true hazards the map calls free"},
      {"max_tilt_deg", "largest tilt", "deg", "roll/pitch of the base"},
      {"odometry_drift.p90_per_m", "odometry drift, 9 drives in 10", "m/m",
       "odometry's pose against the registered one, per metre driven (run.drift_per_m)"},
      {"wall_time_s", "wall time", "s", "including set-up"},
  };
  std::vector<MetricRow> rows;
  for (const Spec& s : kSpecs) {
    const nlohmann::json* v = At(m, s.key);
    if (!v || !v->is_number()) continue;
    const std::string value = v->is_number_integer() ? v->dump() : Significant(v->get<double>());
    std::string note = s.note;
    // A count of map cells means little without how many were compared.
    const nlohmann::json* compared = At(m, "map_hazards.cells_compared");
    if (std::string(s.key).rfind("map_hazards.", 0) == 0 && compared) {
      note += ", of " + compared->dump() + " cells compared";
    }
    // The truly free cells it cannot reach (pink in hazard_errors.png) are not in the count.
    const nlohmann::json* out_of_reach = At(m, "map_hazards.false_hazard_cells_out_of_reach");
    if (std::string(s.key) == "map_hazards.false_hazard_cells" && out_of_reach &&
        out_of_reach->is_number_integer() && out_of_reach->get<long long>() > 0) {
      note += "; " + out_of_reach->dump() + " more out of its reach";
    }
    rows.push_back({s.label, value, s.unit, note});
  }
  // What the map's slopes are worth where the planner decides on them: map minus truth over the
  // cells truly between half the slope limit and beyond it (metrics.json map_tilt_against_truth),
  // where some had a supported slope; beside the map's hazard counts.
  std::vector<MetricRow> slopes;
  if (const nlohmann::json* bins = At(m, "map_tilt_against_truth"); bins && bins->is_array()) {
    for (const nlohmann::json& b : *bins) {
      const double lo = b.value("true_from_deg", 0.0), hi = b.value("true_to_deg", 0.0);
      const long long cells = b.value("cells", 0LL), unsupported = b.value("map_unsupported", 0LL);
      if (lo <= 0.0 || cells <= unsupported) continue;  // level ground: the false hazards say it
      const std::string range = hi >= 90.0 ? "beyond " + NumberText(lo) + " deg"
                                           : NumberText(lo) + "-" + NumberText(hi) + " deg";
      slopes.push_back(
          {"map slope error, true slope " + range, Significant(b.value("median_error_deg", 0.0)),
           "deg",
           "map minus truth, median; 10-90 %: " + Significant(b.value("p10_error_deg", 0.0)) +
               " .. " + Significant(b.value("p90_error_deg", 0.0)) + " deg, over " +
               std::to_string(cells - unsupported) + " cells with a supported slope"});
    }
  }
  auto at = std::find_if(rows.begin(), rows.end(), [](const MetricRow& r) {
    return r.label == "missed hazard cells in the final map";
  });
  rows.insert(at == rows.end() ? at : at + 1, slopes.begin(), slopes.end());
  return rows;
}

}  // namespace pitchlab::mission
