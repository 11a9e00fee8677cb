#pragma once
// Where a run's time goes (issue 21): wall-clock and CPU time per stage of the closed loop, so a
// change meant to speed a run up is measured against the stage it targets. metrics.json carries
// it as `stages` and report.html as a table.

#include <array>
#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "pitchlab/sensors/stopwatch.hpp"

namespace pitchlab::mission {

/// The stages of a simulated run. Each is timed over disjoint spans of the run, so they add up to
/// at most the run's own time; what no stage covers (loading the world, building the ray caster's
/// scene, placing the robot, the loop's own bookkeeping) is the breakdown's "other". The ground
/// truth and each stop's files are made on a thread beside the mission: their CPU time is that
/// thread's (the other stages' CPU time is the mission thread's and its loops' helpers'), their
/// wall time what the run waited for them.
enum class Stage : std::size_t {
  kPhysicsDriving,   ///< the base's drive commands: physics stepped while moving (and braking)
  kPhysicsStanding,  ///< a scan minus its lines: the pitch servo's physics while standing still
  kRayCasting,       ///< making the scan's lines: rays cast and turned into LMS200 readings
  kRegistration,     ///< Algorithm 1 against the map (mapping::MapBuilder::Add)
  kMapUpdate,        ///< the scan into the elevation map, and the map's layers for planning
  kTraversability,   ///< planning::BuildTraversability (recoveries' relaxed grids included)
  kPlanning,         ///< graph search (Algorithm 2) and the mission's path checks
  kOutputs,          ///< the run folder's files: per stop (beside the mission) and at the end
  kGroundTruth,      ///< the true elevation map, its traversability and optimum (beside it)
  kScoring,          ///< the final map's traversability and the score against the truth
};
inline constexpr std::size_t kStageCount = 10;

/// The stage's key in metrics.json ("physics_driving", ...).
const char* StageKey(Stage stage);

/// Time per stage, accumulated over a run.
struct StageTimes {
  std::array<sensors::Elapsed, kStageCount> stage{};
  sensors::Elapsed& operator[](Stage s) { return stage[static_cast<std::size_t>(s)]; }
  const sensors::Elapsed& operator[](Stage s) const { return stage[static_cast<std::size_t>(s)]; }
  StageTimes& operator+=(const StageTimes& o);
};

/// A run's breakdown: its stages and the run's own time (set-up included) they are part of.
struct StageBreakdown {
  StageTimes stages;
  sensors::Elapsed run;
  /// The run's time no stage covers: run - the stages' sum (wall and CPU alike).
  sensors::Elapsed Other() const;
};

/// metrics.json's `stages`: {"run": {wall_s, cpu_s}, "<stage>": {wall_s, cpu_s, wall_share,
/// cpu_share}, ..., "other": {...}}; a share is the stage's fraction of the run's wall or CPU time
/// (0 when the run took none), and the stages with other sum to the run.
nlohmann::json StagesJson(const StageBreakdown& breakdown);

}  // namespace pitchlab::mission
