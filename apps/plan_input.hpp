#pragma once
// What `pitchlab plan` plans on: a pitchlab elevation map (.plem), a DEM (.asc with its .prj) or a
// map_server occupancy grid (.yaml with its PGM), each turned into the planner's graph.

#include <functional>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::apps {

/// A map file read for planning.
struct PlanInput {
  std::optional<mapping::ElevationLayers> layers;  ///< none for an occupancy grid
  planning::TraversabilityGrid grid;
  std::optional<mapping::GeodeticOrigin> origin;  ///< for GeoJSON; none when not georeferenced
  /// What was read and how the map frame relates to the file's coordinates (plan.json "input").
  nlohmann::json about;
  /// The map-frame point [m] of a point in the file's own coordinates (identity but for a
  /// resampled DEM, whose file is in longitude/latitude or a projection).
  std::function<Eigen::Vector2d(const Eigen::Vector2d&)> to_map = [](const Eigen::Vector2d& p) {
    return p;
  };
};

/// Reads `path` by its extension (.plem, .asc, .yaml / .yml) and builds the planning graph with
/// `config`. Throws CliError on another extension, std::runtime_error naming the file (and line)
/// when it cannot be read.
PlanInput LoadPlanInput(const std::string& path, const planning::PlannerConfig& config);

}  // namespace pitchlab::apps
