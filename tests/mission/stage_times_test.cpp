#include "pitchlab/mission/stage_times.hpp"

#include <set>
#include <string>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

// Sums of a few doubles in seconds: exact to far below a nanosecond of the clocks' resolution.
constexpr double kSumTolerance_s = 1e-12;

TEST(StageBreakdown, OtherIsTheRunLessEveryStage) {
  StageBreakdown b;
  b.run = {10.0, 12.0};
  b.stages[Stage::kPhysicsDriving] = {4.0, 4.5};
  b.stages[Stage::kRayCasting] = {1.0, 3.0};  // worker threads: CPU beyond wall
  b.stages[Stage::kOutputs] = {0.5, 0.5};
  const sensors::Elapsed other = b.Other();
  EXPECT_NEAR(other.wall_s, 4.5, kSumTolerance_s);
  EXPECT_NEAR(other.cpu_s, 4.0, kSumTolerance_s);
}

TEST(StagesJson, HasEveryStageAndOtherWithSharesOfTheRun) {
  StageBreakdown b;
  b.run = {20.0, 16.0};
  for (std::size_t i = 0; i < kStageCount; ++i) b.stages.stage[i] = {1.0, 0.5};
  const nlohmann::json j = StagesJson(b);
  ASSERT_TRUE(j.contains("run"));
  EXPECT_DOUBLE_EQ(j["run"]["wall_s"].get<double>(), 20.0);
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const char* key = StageKey(static_cast<Stage>(i));
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_DOUBLE_EQ(j[key]["wall_s"].get<double>(), 1.0) << key;
    EXPECT_DOUBLE_EQ(j[key]["cpu_s"].get<double>(), 0.5) << key;
    EXPECT_DOUBLE_EQ(j[key]["wall_share"].get<double>(), 1.0 / 20.0) << key;
    EXPECT_DOUBLE_EQ(j[key]["cpu_share"].get<double>(), 0.5 / 16.0) << key;
  }
  EXPECT_NEAR(j["other"]["wall_s"].get<double>(), 20.0 - kStageCount * 1.0, kSumTolerance_s);
  EXPECT_NEAR(j["other"]["cpu_s"].get<double>(), 16.0 - kStageCount * 0.5, kSumTolerance_s);
  // Every stage and other make the run: the shares sum to one.
  double wall_share = 0;
  for (const auto& [key, value] : j.items()) {
    if (key != "run") wall_share += value["wall_share"].get<double>();
  }
  EXPECT_NEAR(wall_share, 1.0, kSumTolerance_s);
  EXPECT_EQ(j.size(), kStageCount + 2) << "the stages, other and run, nothing else";
}

TEST(StagesJson, ARunThatTookNoTimeHasZeroShares) {
  const nlohmann::json j = StagesJson(StageBreakdown{});
  EXPECT_EQ(j["other"]["wall_share"].get<double>(), 0.0);
  EXPECT_EQ(j["physics_driving"]["cpu_share"].get<double>(), 0.0);
}

TEST(StageKey, EveryStageHasItsOwnKey) {
  std::set<std::string> keys;
  for (std::size_t i = 0; i < kStageCount; ++i) keys.insert(StageKey(static_cast<Stage>(i)));
  EXPECT_EQ(keys.size(), kStageCount);
  EXPECT_EQ(keys.count("other"), 0u);
  EXPECT_EQ(keys.count("run"), 0u);
}

}  // namespace
}  // namespace pitchlab::mission
