#pragma once
// The run's trajectory in the field's standard form (issue 20): the stops' estimated and true
// poses as TUM files (trajectory_estimated.tum, trajectory_true.tum; stamps = the simulated time
// of each stop's scan) and metrics.json's "trajectory_error": absolute trajectory error without
// and after SE(3) alignment, relative pose error per stop and per metre (mapping's
// trajectory_metrics.hpp). Kept apart from the rest of metrics.json so it merges on its own.
// The estimate scored and written is the final one (StopRecord::T_world_base_final: the pose
// graph's last optimum with loop closure); with loop closure the live one (each stop as it was
// registered, what the robot acted on) is kept beside it: trajectory_estimated_live.tum and
// "trajectory_error_live".

#include <vector>

#include <nlohmann/json.hpp>

#include "pitchlab/mapping/tum_trajectory.hpp"
#include "pitchlab/mission/mission.hpp"
#include "pitchlab/mission/run_folder.hpp"

namespace pitchlab::mission {

/// RPE per metre spans at least this much true path [m]: "per metre" as the issue asks. Stops are
/// drive_per_stop_m (4 m) apart on a plain drive, so a segment is mostly one stop to the next;
/// shorter steps (turning in place to look, backing off a tilt) join the next ones, so an error
/// is never divided by a near-zero length.
inline constexpr double kRpeSegmentM = 1.0;

/// Which of a stop's poses.
enum class StopPoses {
  kFinal,  ///< StopRecord::T_world_base_final: after the run's last optimisation
  kLive,   ///< StopRecord::T_world_base: as the stop was registered (what the robot acted on)
  kTrue,   ///< StopRecord::T_world_base_true
};

/// The stops' poses stamped with their scans' time; with kTrue empty when some stop has no truth
/// (hardware runs).
std::vector<mapping::StampedPose> StopTrajectory(const MissionResult& result, StopPoses which);

/// metrics.json's "trajectory_error" over StopTrajectory's `estimate` vs truth: {poses,
/// ate: {unaligned, aligned}: {rmse_m, max_m, rotation_rmse_deg}, rpe: {per_stop: {pairs,
/// translation_rmse_m, translation_max_m, rotation_rmse_deg, rotation_max_deg}, per_metre: {the
/// same per metre, segment_m}}}. A metric that cannot be computed (one stop, a path shorter than
/// kRpeSegmentM) is null with "<name>_note" saying why. Null when the run has no truth.
nlohmann::json TrajectoryErrorJson(const MissionResult& result,
                                   StopPoses estimate = StopPoses::kFinal);

/// Writes trajectory_estimated.tum (final poses), with `live` also trajectory_estimated_live.tum
/// (live poses), and with truth trajectory_true.tum. Throws
/// std::runtime_error naming the file on a bad trajectory (stamps not increasing) or a write
/// failure.
void WriteStopTrajectories(RunFolder& folder, const MissionResult& result, bool live);

}  // namespace pitchlab::mission
