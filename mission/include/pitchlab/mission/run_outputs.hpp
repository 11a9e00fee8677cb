#pragma once
// What a closed-loop run leaves in its folder: per stop the scan, registration and plan; at the
// end the merged cloud, the elevation map (lossless, ESRI grid, PNG), both trajectories (CSV,
// GeoJSON), metrics.json and a self-contained report.html.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mission/mission.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/run_scoring.hpp"
#include "pitchlab/mission/stage_times.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mission {

/// Facts about the run that the mission itself does not hold.
struct RunContext {
  std::string world, world_file, robot;
  std::uint64_t seed = 0;
  Eigen::Vector3d start{0, 0, 0};  ///< x [m], y [m], yaw [rad]
  Eigen::Vector2d goal{0, 0};      ///< [m]
  std::vector<Eigen::Vector2d> via;  ///< waypoints before the goal, in order [m]
  bool loop_closure = false;  ///< the mission closed loops (run: {loop_closure: true})
  std::optional<mapping::GeodeticOrigin> geodetic_origin;
  /// Simulated runs: the scanner's mount error the simulator drew, roll, pitch, yaw [rad]
  /// (truth the mission never saw; metrics.json scores the mount calibration against it).
  std::optional<Eigen::Vector3d> mount_error_rpy_rad;
  std::string config_yaml;  ///< the configuration as used
  /// The planner as the mission used it (robot width including the safety margin).
  planning::PlannerConfig planner;
  mapping::LayerConfig layers;  ///< how the mission derived the map's layers
  double wall_time_s = 0;       ///< whole run including set-up [s]
  /// Where the run's time went (simulated runs); its `run` is the same span as wall_time_s.
  std::optional<StageBreakdown> stages;
};

/// Writes stops/NN/{scan.pcd, registration.json, path.csv, path.geojson, map.png, map_small.png}.
/// `world`: the world's name (its file's stem; empty when unknown), written into scan.pcd so that
/// `map --world` can tell a scan of another world. Throws std::runtime_error naming the file on a
/// write failure.
void WriteStopOutputs(RunFolder& folder, const StopRecord& stop, const MissionResult& so_far,
                      const std::optional<mapping::GeodeticOrigin>& origin,
                      const std::string& world);

/// metrics.json's content.
nlohmann::json RunMetrics(const RunContext& context, const MissionResult& result,
                          const std::optional<RunScore>& score);

/// The final map as every file at the end reads it, each part made once: its layers and the
/// traversability the mission planned on (RunContext::planner: traversability.png, the report's 3D
/// surface). A run's end had made the layers twice, the grid three times and the truth's again.
struct FinalMap {
  mapping::ElevationLayers layers;
  planning::TraversabilityGrid grid;
};

/// The final map's layers (RunContext::layers) and its traversability (RunContext::planner).
FinalMap MakeFinalMap(const RunContext& context, const MissionResult& result);

/// What a simulated run knows besides the map: the true map's layers, the grids ScoreRun compared
/// (the true map's and the final map's, both with the mission's own planner: the robot's width
/// without RunContext's safety margin), the true optimal path (null: not known) and where the run
/// crossed truly forbidden cells (RunScore::forbidden_crossed_at; empty: nowhere).
struct TruthMaps {
  const mapping::ElevationLayers& layers;
  const planning::TraversabilityGrid& grid;
  const planning::TraversabilityGrid& scored_estimate;
  const planning::Path* optimum;
  std::vector<Eigen::Vector2d> forbidden_crossed_at;
};

/// Everything written at the end (see the file comment), report.html last. `truth` is null on
/// hardware; with it also hazard_errors.png (run_pictures.hpp). WriteFinalData then WriteSummary.
void WriteFinalOutputs(RunFolder& folder, const RunContext& context, const MissionResult& result,
                       const std::optional<RunScore>& score, const TruthMaps* truth);

/// The end's files but metrics.json and report.html: config, clouds, maps, trajectories,
/// pictures.
void WriteFinalData(RunFolder& folder, const RunContext& context, const MissionResult& result,
                    const FinalMap& final_map, const TruthMaps* truth);

/// metrics.json and report.html, last: they hold the run's time up to them (context).
void WriteSummary(RunFolder& folder, const RunContext& context, const MissionResult& result,
                  const std::optional<RunScore>& score, const FinalMap& final_map);

}  // namespace pitchlab::mission
