// metrics.json's "loop_closures": the accepted loop edges scored against the truth.

#include "pitchlab/mission/loop_closure_metrics.hpp"

#include <stdexcept>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

Eigen::Isometry3d Pose(double x, double y, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * 3.14159265358979323846 / 180, Eigen::Vector3d::UnitZ())
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

// Stops 0..3 on a 2 m square, all merged as scans 0..3; stop 3 comes back next to stop 0.
MissionResult SquareRun() {
  MissionResult r;
  const Eigen::Isometry3d truth[] = {Pose(0, 0, 0), Pose(2, 0, 90), Pose(2, 2, 180),
                                     Pose(0, 1, 270)};
  for (int k = 0; k < 4; ++k) {
    StopRecord s;
    s.index = k;
    s.merge.merged = true;
    s.merge.scan_index = static_cast<std::size_t>(k);
    s.T_world_base_true = truth[k];
    r.stops.push_back(s);
  }
  r.loop_counts = {3, 1, 2, 0};
  return r;
}

mapping::LoopClosure Loop(const MissionResult& r, std::size_t from, std::size_t to,
                          const Eigen::Isometry3d& error) {
  mapping::LoopClosure loop;
  loop.from_scan_index = from;
  loop.to_scan_index = to;
  loop.T_from_to =
      r.stops[from].T_world_base_true->inverse() * *r.stops[to].T_world_base_true * error;
  return loop;
}

TEST(LoopClosureJson, AnEdgeMoreThanACellOffTheTruthIsWrong) {
  MissionResult r = SquareRun();
  // One 5 mm / 0.2 deg off (right), one 0.2 m off (wrong: over kWrongLoopTranslationM).
  r.loop_closures = {Loop(r, 0, 3, Pose(0.005, 0, 0.2)), Loop(r, 1, 3, Pose(0, 0.2, 0))};
  const nlohmann::json j = LoopClosureJson(r);
  EXPECT_EQ(j["registered"].get<int>(), 3);
  EXPECT_EQ(j["registration_failed"].get<int>(), 1);
  EXPECT_EQ(j["accepted"].get<int>(), 2);
  EXPECT_EQ(j["rejected"].get<int>(), 0);
  EXPECT_EQ(j["wrong"].get<int>(), 1);
  ASSERT_EQ(j["edges"].size(), 2u);
  EXPECT_EQ(j["edges"][0]["from_stop"].get<int>(), 0);
  EXPECT_EQ(j["edges"][0]["to_stop"].get<int>(), 3);
  EXPECT_NEAR(j["edges"][0]["translation_error_m"].get<double>(), 0.005, 1e-12);
  EXPECT_NEAR(j["edges"][0]["rotation_error_deg"].get<double>(), 0.2, 1e-9);
  EXPECT_FALSE(j["edges"][0]["wrong"].get<bool>());
  EXPECT_NEAR(j["edges"][1]["translation_error_m"].get<double>(), 0.2, 1e-12);
  EXPECT_TRUE(j["edges"][1]["wrong"].get<bool>());
}

TEST(LoopClosureJson, ATurnOverADegreeIsWrongToo) {
  MissionResult r = SquareRun();
  r.loop_closures = {Loop(r, 0, 3, Pose(0, 0, 1.5))};
  EXPECT_EQ(LoopClosureJson(r)["wrong"].get<int>(), 1);
}

TEST(LoopClosureJson, WithoutTruthNothingIsCalledWrong) {
  MissionResult r = SquareRun();
  r.loop_closures = {Loop(r, 0, 3, Pose(0, 0.2, 0))};
  r.stops[3].T_world_base_true.reset();
  const nlohmann::json j = LoopClosureJson(r);
  EXPECT_TRUE(j["wrong"].is_null());
  EXPECT_TRUE(j["edges"][0]["wrong"].is_null());
  EXPECT_EQ(j["accepted"].get<int>(), 2);
}

TEST(LoopClosureJson, AnEdgeToAScanNoStopMergedIsABug) {
  MissionResult r = SquareRun();
  r.loop_closures = {Loop(r, 0, 3, Eigen::Isometry3d::Identity())};
  r.stops[3].merge.merged = false;
  EXPECT_THROW(LoopClosureJson(r), std::logic_error);
}

}  // namespace
}  // namespace pitchlab::mission
