#include "pitchlab/mission/trajectory_outputs.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "pitchlab/mapping/trajectory_metrics.hpp"

namespace pitchlab::mission {
namespace {

std::vector<Eigen::Isometry3d> Poses(const std::vector<mapping::StampedPose>& stamped) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(stamped.size());
  for (const mapping::StampedPose& p : stamped) poses.push_back(p.T_map_base);
  return poses;
}

nlohmann::json AteJson(const mapping::AbsoluteTrajectoryError& e) {
  return {{"rmse_m", e.rmse_m}, {"max_m", e.max_m}, {"rotation_rmse_deg", e.rotation_rmse_deg}};
}

// Per stop the values are [m] and [deg]; per metre [m/m] and [deg/m] (`unit` says which).
nlohmann::json RpeJson(const mapping::RelativePoseError& e, const std::string& unit) {
  return {{"pairs", e.pairs},
          {"translation_rmse_" + unit, e.translation_rmse},
          {"translation_max_" + unit, e.translation_max},
          {"rotation_rmse_deg" + unit.substr(1), e.rotation_rmse_deg},
          {"rotation_max_deg" + unit.substr(1), e.rotation_max_deg}};
}

// Puts `value`'s JSON under `key`, or null and `key`_note with the error's message.
template <typename T, typename ToJson>
void Put(nlohmann::json& j, const std::string& key, const Result<T>& value, ToJson to_json) {
  if (value) {
    j[key] = to_json(*value);
  } else {
    j[key] = nullptr;
    j[key + "_note"] = value.error().message;
  }
}

}  // namespace

std::vector<mapping::StampedPose> StopTrajectory(const MissionResult& result, StopPoses which) {
  std::vector<mapping::StampedPose> poses;
  for (const StopRecord& s : result.stops) {
    switch (which) {
      case StopPoses::kFinal:
        poses.push_back({s.stamp_s, s.T_world_base_final});
        break;
      case StopPoses::kLive:
        poses.push_back({s.stamp_s, s.T_world_base});
        break;
      case StopPoses::kTrue:
        if (!s.T_world_base_true) return {};
        poses.push_back({s.stamp_s, *s.T_world_base_true});
        break;
    }
  }
  return poses;
}

nlohmann::json TrajectoryErrorJson(const MissionResult& result, StopPoses estimate) {
  const std::vector<mapping::StampedPose> truth = StopTrajectory(result, StopPoses::kTrue);
  if (truth.empty()) return nullptr;
  const std::vector<Eigen::Isometry3d> est = Poses(StopTrajectory(result, estimate));
  const std::vector<Eigen::Isometry3d> tru = Poses(truth);
  nlohmann::json ate, rpe;
  Put(ate, "unaligned", mapping::AbsoluteTrajectoryErrorUnaligned(est, tru), AteJson);
  Put(ate, "aligned", mapping::AbsoluteTrajectoryErrorAligned(est, tru), AteJson);
  Put(rpe, "per_stop", mapping::RelativePoseErrorPerStop(est, tru),
      [](const mapping::RelativePoseError& e) { return RpeJson(e, "m"); });
  Put(rpe, "per_metre", mapping::RelativePoseErrorPerMetre(est, tru, kRpeSegmentM),
      [](const mapping::RelativePoseError& e) {
        nlohmann::json j = RpeJson(e, "m_per_m");
        j["segment_m"] = kRpeSegmentM;
        return j;
      });
  return {{"poses", tru.size()}, {"ate", ate}, {"rpe", rpe}};
}

void WriteStopTrajectories(RunFolder& folder, const MissionResult& result, bool live) {
  const std::pair<StopPoses, const char*> files[] = {
      {StopPoses::kFinal, "trajectory_estimated.tum"},
      {StopPoses::kLive, "trajectory_estimated_live.tum"},
      {StopPoses::kTrue, "trajectory_true.tum"}};
  for (const auto& [which, name] : files) {
    if (which == StopPoses::kLive && !live) continue;
    const std::vector<mapping::StampedPose> poses = StopTrajectory(result, which);
    if (which == StopPoses::kTrue && poses.empty()) continue;  // no truth (hardware)
    const Result<std::string> text = mapping::FormatTumTrajectory(poses);
    if (!text) throw std::runtime_error(std::string(name) + ": " + text.error().message);
    WriteTextFile(folder.File(name), *text);
  }
}

}  // namespace pitchlab::mission
