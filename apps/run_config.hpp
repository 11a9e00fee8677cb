#pragma once
// The closed-loop run's settings from the YAML config: sections `run` (the mission), `planner`
// (Eq. 5 weights, robot limits, unknown cells) and `registration` (Algorithm 1).

#include <optional>
#include <string>

#include "mission.hpp"
#include "pitchlab/sim/robot_model.hpp"

namespace pitchlab::apps {

struct RunSettings {
  MissionConfig mission;  ///< goal, map_area and mount are filled in by the caller
  double cell_m = 0.1;    ///< elevation map and planning grid [m]
  /// Side of the square map around the start when no world gives bounds (hardware) [m].
  std::optional<double> map_size_m;
};

/// Reads `run`, `planner` and `registration` from `yaml_text` (empty: defaults) for a robot of
/// `model` (its planner preset unless `planner.robot` says otherwise). Throws
/// std::invalid_argument naming `source`, the field and the value.
RunSettings ParseRunSettings(const std::string& yaml_text, const std::string& source,
                             sim::P3Model model);

/// The three sections as YAML, readable back by ParseRunSettings.
std::string RunSettingsToYaml(const RunSettings& settings);

}  // namespace pitchlab::apps
