#pragma once
// The closed-loop run's settings from the YAML config: sections `run` (the mission), `planner`
// (Eq. 5 weights, robot limits, unknown cells) and `registration` (Algorithm 1).

#include <optional>
#include <string>

#include "pitchlab/mission/mission.hpp"
#include "pitchlab/sim/robot_model.hpp"

namespace pitchlab::mission {

struct RunSettings {
  MissionConfig mission;  ///< goal, map_area and mount are filled in by the caller
  double cell_m = 0.1;    ///< elevation map and planning grid [m]
  /// Half the side of the inclination's fit region, from the centre cell's centre to the outer
  /// edge (mission.layers gets it in cells, at least 1) [m]. 0.15 is 3 x 3 cells of 0.1 m. Half
  /// the robot's length (0.25, 5 x 5) reads robot-scale tilt but mixes wall cells into the fits
  /// beside walls and closes the office's 1 m doors.
  double inclination_radius_m = 0.15;
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

}  // namespace pitchlab::mission
