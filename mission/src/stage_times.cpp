#include "pitchlab/mission/stage_times.hpp"

namespace pitchlab::mission {
namespace {

nlohmann::json TimeJson(const sensors::Elapsed& t, const sensors::Elapsed& run) {
  return {{"wall_s", t.wall_s},
          {"cpu_s", t.cpu_s},
          {"wall_share", run.wall_s > 0 ? t.wall_s / run.wall_s : 0.0},
          {"cpu_share", run.cpu_s > 0 ? t.cpu_s / run.cpu_s : 0.0}};
}

}  // namespace

const char* StageKey(Stage stage) {
  switch (stage) {
    case Stage::kPhysicsDriving:
      return "physics_driving";
    case Stage::kPhysicsStanding:
      return "physics_standing";
    case Stage::kRayCasting:
      return "ray_casting";
    case Stage::kRegistration:
      return "registration";
    case Stage::kMapUpdate:
      return "map_update";
    case Stage::kTraversability:
      return "traversability";
    case Stage::kPlanning:
      return "planning";
    case Stage::kOutputs:
      return "outputs";
    case Stage::kGroundTruth:
      return "ground_truth";
    case Stage::kScoring:
      return "scoring";
  }
  return "?";
}

StageTimes& StageTimes::operator+=(const StageTimes& o) {
  for (std::size_t i = 0; i < kStageCount; ++i) stage[i] += o.stage[i];
  return *this;
}

sensors::Elapsed StageBreakdown::Other() const {
  sensors::Elapsed other = run;
  for (const sensors::Elapsed& s : stages.stage) other -= s;
  return other;
}

nlohmann::json StagesJson(const StageBreakdown& b) {
  nlohmann::json j = {{"run", {{"wall_s", b.run.wall_s}, {"cpu_s", b.run.cpu_s}}}};
  for (std::size_t i = 0; i < kStageCount; ++i) {
    j[StageKey(static_cast<Stage>(i))] = TimeJson(b.stages.stage[i], b.run);
  }
  j["other"] = TimeJson(b.Other(), b.run);
  return j;
}

}  // namespace pitchlab::mission
