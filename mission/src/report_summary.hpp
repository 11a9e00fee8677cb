#pragma once
// What a reader of a run report needs first: did it reach the goal, why it stopped, was it safe,
// and the few numbers that matter, each with its unit and no more digits than it means.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pitchlab::mission {

/// The verdict of a run, read from metrics.json.
struct Outcome {
  bool success = false;             ///< reached the goal
  bool safe = true;                 ///< touched no true hazard (only known with ground truth)
  std::string headline;             ///< "Goal reached", "Goal reached, but unsafe", "Failed"
  std::string reason;               ///< the mission's reason, verbatim
  std::vector<std::string> safety;  ///< one sentence per safety finding; empty when safe
};

/// The outcome of `metrics` (RunMetrics' JSON). A run is unsafe when its true trajectory crossed
/// true hazard cells or forbidden cells (within half the robot's width of a hazard), or came
/// 0.0 m (at the report's 0.1 m precision) from a true hazard.
Outcome ReadOutcome(const nlohmann::json& metrics);

/// One row of the key metrics table.
struct MetricRow {
  std::string label;  ///< what it is, in words
  std::string value;  ///< formatted: 3 significant digits, integers as they are
  std::string unit;   ///< "m", "deg", "s", "" (a count or a ratio)
  std::string note;   ///< how to read it, one short phrase
};

/// The metrics that matter, in the order a reader asks for them; rows whose keys are absent
/// (hardware runs have no truth) or null are left out.
std::vector<MetricRow> KeyMetrics(const nlohmann::json& metrics);

/// The header of the stage table (StageRows).
std::vector<std::string> StageHeader();

/// Where the run's time went, from metrics.json's `stages` (stage_times.hpp): one row per stage in
/// the loop's order, then "other" and the whole run; each row its label, wall and CPU seconds and
/// their shares of the run in percent. Empty when the metrics have no stages (hardware runs).
std::vector<std::vector<std::string>> StageRows(const nlohmann::json& metrics);

/// `v` with `digits` significant digits in fixed notation ("25.7", "0.221", "234", "0");
/// "-" for NaN or infinity.
std::string Significant(double v, int digits = 3);

}  // namespace pitchlab::mission
