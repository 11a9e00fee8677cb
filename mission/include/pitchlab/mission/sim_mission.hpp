#pragma once
// A whole closed-loop run in a simulated world, as `pitchlab run` makes it: the world's ground
// truth on the map grid, the simulated rig with its attitude sensor, the mission (mission.hpp),
// its score against the truth (run_scoring.hpp) and the run folder (run_outputs.hpp).
//
//   mission::SimMissionSpec spec = mission::LoadSimMissionSpec(std::nullopt);  // the defaults
//   spec.world_file = worlds::ResolveWorld("office", worlds_dir);
//   spec.goal_m = Eigen::Vector2d(4.0, 1.0);
//   const mission::SimMissionOutcome run = mission::RunSimMission(spec, "runs/mine");
//   run.result.success, run.score.final_translation_error_m, run.folder / "metrics.json"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pitchlab/mission/app_config.hpp"
#include "pitchlab/mission/mission.hpp"
#include "pitchlab/mission/run_config.hpp"
#include "pitchlab/mission/run_outputs.hpp"
#include "pitchlab/mission/run_scoring.hpp"
#include "pitchlab/worlds/world_metadata.hpp"

namespace pitchlab::mission {

/// What a simulated run is made of.
struct SimMissionSpec {
  std::filesystem::path world_file;  ///< any MJCF world (worlds::ResolveWorld for built-in names)
  std::string world_name;            ///< how the outputs name the world; empty: the file's stem
  std::optional<Eigen::Vector3d> start;   ///< x [m], y [m], yaw [rad]; empty: the world's default
  std::optional<Eigen::Vector2d> goal_m;  ///< [m]; empty: the world's default goal
  /// Waypoints driven through, in order, before the goal [m] (MissionConfig::via_m).
  std::vector<Eigen::Vector2d> via_m;
  /// Through via_m to the goal (given or the world's), then back to the start: the mission's goal
  /// becomes the start, and the goal the last waypoint.
  bool round_trip = false;
  /// Where the ground truth's elevation map is kept for later runs of the same world, placement,
  /// map grid and executable (a sweep's runs share it: pitchlab bench); empty: none.
  std::filesystem::path truth_cache_dir;
  AppConfig config;                       ///< sensors, simulated rig, seed
  /// Mission, planner, registration; the run sets the goal, map area and mount.
  RunSettings settings;
};

/// The spec `pitchlab run --config` builds, world_file still to set: `config_path`'s sections
/// (nullopt: the built-in defaults), then `seed` for every random source and the `robot` model
/// (its planner preset) when given. Throws std::invalid_argument naming the file, field and value.
SimMissionSpec LoadSimMissionSpec(const std::optional<std::string>& config_path,
                                  std::optional<std::uint64_t> seed = std::nullopt,
                                  std::optional<sim::P3Model> robot = std::nullopt);

/// What a world file says about itself (bounds, default start and goal, geodetic origin). Throws
/// std::runtime_error naming the file when MuJoCo cannot load it.
worlds::WorldMetadata LoadWorldMetadata(const std::filesystem::path& world_file);

/// Progress of a simulated run, for a person watching; every callback may be empty.
struct SimMissionObserver {
  std::function<void(const std::string& text)> on_setup;   ///< set-up steps (the ground truth)
  /// The mission's progress (mission.hpp) with the simulated clock then [s].
  std::function<void(const std::string& text, double sim_time_s)> on_progress;
};

/// A finished run.
struct SimMissionOutcome {
  MissionResult result;
  RunScore score;
  RunContext context;            ///< as written into metrics.json and config.yaml
  nlohmann::json metrics;        ///< metrics.json's content
  std::filesystem::path folder;  ///< the run folder, committed
  /// report.html's safety findings, one sentence each (the true trajectory over true hazard or
  /// forbidden cells): empty when the run was safe. A mission can reach its goal unsafely.
  std::vector<std::string> safety;
};

/// Runs `spec` and writes the run folder `out` (run_outputs.hpp), committed only at the end: a
/// failed run leaves no folder. A mission that ends without reaching the goal is a result
/// (`result.success` false), not an error. Throws std::invalid_argument on a bad spec (no goal
/// given and none in the world, bad configuration) and std::runtime_error when `out` exists, the
/// goal or a waypoint is off the world's map or unreachable on its true map, or a file cannot be
/// written.
SimMissionOutcome RunSimMission(const SimMissionSpec& spec, const std::filesystem::path& out,
                                const SimMissionObserver& observer = {});

}  // namespace pitchlab::mission
