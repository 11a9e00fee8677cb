// The run's standard trajectory metrics and TUM files: known answers on a made-up run, and a real
// simulated run whose metrics.json matches a recomputation from its own TUM files.

#include "pitchlab/mission/trajectory_outputs.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <utility>

#include <gtest/gtest.h>

#include "pitchlab/mapping/trajectory_metrics.hpp"
#include "pitchlab/mission/sim_mission.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

// Poses go through the TUM text as a quaternion and shortest round-trip decimals: what they read
// back as differs from the original by rounding only (a few ulps of 1).
constexpr double kRoundTrip = 1e-9;

using test_support::ScopedTempDir;

Eigen::Isometry3d Pose(double x, double y, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 0);
  return T;
}

// Four stops 2 m apart along x, every estimate 0.1 m to the left of the truth.
MissionResult ShiftedRun() {
  MissionResult r;
  for (int k = 0; k < 4; ++k) {
    StopRecord s;
    s.index = k;
    s.stamp_s = 10.0 * k + 0.5;
    s.T_world_base_true = Pose(2.0 * k, 0.0, 0.0);
    s.T_world_base = s.T_world_base_final = Pose(2.0 * k, 0.1, 0.0);
    r.stops.push_back(s);
  }
  return r;
}

TEST(TrajectoryErrorJson, AConstantOffsetIsAllAbsoluteAndNoneRelativeOrAligned) {
  const nlohmann::json j = TrajectoryErrorJson(ShiftedRun());
  EXPECT_EQ(j["poses"].get<int>(), 4);
  EXPECT_NEAR(j["ate"]["unaligned"]["rmse_m"].get<double>(), 0.1, 1e-12);
  EXPECT_NEAR(j["ate"]["unaligned"]["max_m"].get<double>(), 0.1, 1e-12);
  EXPECT_NEAR(j["ate"]["aligned"]["rmse_m"].get<double>(), 0.0, 1e-9);  // a pure shift aligns
  EXPECT_EQ(j["rpe"]["per_stop"]["pairs"].get<int>(), 3);
  EXPECT_NEAR(j["rpe"]["per_stop"]["translation_max_m"].get<double>(), 0.0, 1e-12);
  // 2 m steps >= kRpeSegmentM: one segment per stop but the last.
  EXPECT_EQ(j["rpe"]["per_metre"]["pairs"].get<int>(), 3);
  EXPECT_DOUBLE_EQ(j["rpe"]["per_metre"]["segment_m"].get<double>(), kRpeSegmentM);
}

TEST(TrajectoryErrorJson, ARelativeErrorIsDividedByTheTruePathLength) {
  MissionResult r = ShiftedRun();
  r.stops[3].T_world_base_final = Pose(6.0 + 0.2, 0.1, 0.0);  // the last step 0.2 m too long
  const nlohmann::json j = TrajectoryErrorJson(r);
  EXPECT_NEAR(j["rpe"]["per_stop"]["translation_max_m"].get<double>(), 0.2, 1e-12);
  EXPECT_NEAR(j["rpe"]["per_metre"]["translation_max_m_per_m"].get<double>(), 0.2 / 2.0, 1e-12);
}

// A loop closed late moved the stops' final poses onto the truth; as registered they were 0.1 m
// off. The default scores the final poses, the live ones on request.
TEST(TrajectoryErrorJson, TheFinalPosesAreScoredAndTheLiveOnesOnRequest) {
  MissionResult r = ShiftedRun();
  for (StopRecord& s : r.stops) s.T_world_base_final = *s.T_world_base_true;
  EXPECT_NEAR(TrajectoryErrorJson(r)["ate"]["unaligned"]["rmse_m"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(
      TrajectoryErrorJson(r, StopPoses::kLive)["ate"]["unaligned"]["rmse_m"].get<double>(), 0.1,
      1e-12);
}

TEST(TrajectoryErrorJson, OneStopHasNoRelativeErrorAndSaysWhy) {
  MissionResult r = ShiftedRun();
  r.stops.resize(1);
  const nlohmann::json j = TrajectoryErrorJson(r);
  EXPECT_NEAR(j["ate"]["unaligned"]["rmse_m"].get<double>(), 0.1, 1e-12);
  EXPECT_TRUE(j["rpe"]["per_stop"].is_null());
  EXPECT_FALSE(j["rpe"]["per_stop_note"].get<std::string>().empty());
}

TEST(TrajectoryErrorJson, NoTruthIsNull) {
  MissionResult r = ShiftedRun();
  r.stops[2].T_world_base_true.reset();
  EXPECT_TRUE(TrajectoryErrorJson(r).is_null());
}

TEST(WriteStopTrajectories, TheTumFilesHoldEachStopAtItsScansTime) {
  const ScopedTempDir dir("trajectory");
  MissionResult r = ShiftedRun();
  for (StopRecord& s : r.stops) s.T_world_base_final = *s.T_world_base_true;  // a loop closed
  RunFolder folder(dir / "run");
  WriteStopTrajectories(folder, r, /*live=*/true);
  folder.Commit();
  const std::pair<const char*, std::function<Eigen::Isometry3d(const StopRecord&)>> files[] = {
      {"trajectory_estimated.tum", [](const StopRecord& s) { return s.T_world_base_final; }},
      {"trajectory_estimated_live.tum", [](const StopRecord& s) { return s.T_world_base; }},
      {"trajectory_true.tum", [](const StopRecord& s) { return *s.T_world_base_true; }}};
  for (const auto& [name, pose] : files) {
    const auto poses = mapping::ReadTumTrajectory((dir / "run" / name).string());
    ASSERT_TRUE(poses) << name << ": " << poses.error().message;
    ASSERT_EQ(poses->size(), r.stops.size());
    for (std::size_t k = 0; k < r.stops.size(); ++k) {
      const StopRecord& s = r.stops[k];
      EXPECT_DOUBLE_EQ((*poses)[k].stamp_s, s.stamp_s);
      EXPECT_TRUE((*poses)[k].T_map_base.isApprox(pose(s), kRoundTrip)) << name << " stop " << k;
    }
  }
}

TEST(WriteStopTrajectories, WithoutTruthOnlyTheEstimateIsWritten) {
  const ScopedTempDir dir("trajectory");
  MissionResult r = ShiftedRun();
  for (StopRecord& s : r.stops) s.T_world_base_true.reset();
  RunFolder folder(dir / "run");
  WriteStopTrajectories(folder, r, /*live=*/false);
  folder.Commit();
  EXPECT_TRUE(fs::exists(dir / "run/trajectory_estimated.tum"));
  EXPECT_FALSE(fs::exists(dir / "run/trajectory_estimated_live.tum"));  // loop closure off
  EXPECT_FALSE(fs::exists(dir / "run/trajectory_true.tum"));
}

// A floor 12 x 6 m: a straight 6 m drive, two stops or three.
constexpr const char* kFloorWorld = R"(<mujoco model="floor">
  <custom>
    <numeric name="pitchlab:bounds" data="-5 -3 5 3"/>
    <numeric name="pitchlab:default_start" data="-4 0 0"/>
    <numeric name="pitchlab:default_goal" data="2 0"/>
  </custom>
  <worldbody>
    <geom name="floor" type="plane" size="6 4 0.1"/>
    <geom name="crate" type="box" pos="0 2 0.3" size="0.4 0.4 0.3"/>
    <geom name="post" type="box" pos="3 -1.5 0.5" size="0.2 0.2 0.5"/>
  </worldbody>
</mujoco>)";

std::vector<Eigen::Isometry3d> ReadPoses(const fs::path& file) {
  const auto stamped = mapping::ReadTumTrajectory(file.string());
  EXPECT_TRUE(stamped) << file;
  std::vector<Eigen::Isometry3d> poses;
  if (stamped) {
    for (const mapping::StampedPose& p : *stamped) poses.push_back(p.T_map_base);
  }
  return poses;
}

void ExpectAte(const nlohmann::json& j, const mapping::AbsoluteTrajectoryError& e) {
  EXPECT_NEAR(j["rmse_m"].get<double>(), e.rmse_m, kRoundTrip);
  EXPECT_NEAR(j["max_m"].get<double>(), e.max_m, kRoundTrip);
  EXPECT_NEAR(j["rotation_rmse_deg"].get<double>(), e.rotation_rmse_deg, 1e-6);
}

TEST(RunSimMission, MetricsHoldTheTrajectoryErrorOfItsOwnTumFiles) {
  const ScopedTempDir dir("trajectory");
  std::ofstream(dir / "floor.xml") << kFloorWorld;
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 5);
  spec.world_file = dir / "floor.xml";
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  const nlohmann::json metrics = nlohmann::json::parse(ReadBinaryFile(run.folder / "metrics.json"));
  const nlohmann::json& t = metrics["trajectory_error"];
  const auto est = ReadPoses(run.folder / "trajectory_estimated.tum");
  const auto tru = ReadPoses(run.folder / "trajectory_true.tum");
  ASSERT_EQ(est.size(), run.result.stops.size());
  ASSERT_EQ(tru.size(), est.size());
  EXPECT_EQ(t["poses"].get<std::size_t>(), est.size());
  ExpectAte(t["ate"]["unaligned"], *mapping::AbsoluteTrajectoryErrorUnaligned(est, tru));
  ExpectAte(t["ate"]["aligned"], *mapping::AbsoluteTrajectoryErrorAligned(est, tru));
  const auto per_stop = mapping::RelativePoseErrorPerStop(est, tru);
  ASSERT_TRUE(per_stop) << per_stop.error().message;
  EXPECT_EQ(t["rpe"]["per_stop"]["pairs"].get<int>(), per_stop->pairs);
  EXPECT_NEAR(t["rpe"]["per_stop"]["translation_rmse_m"].get<double>(), per_stop->translation_rmse,
              kRoundTrip);
  EXPECT_NEAR(t["rpe"]["per_stop"]["rotation_max_deg"].get<double>(), per_stop->rotation_max_deg,
              1e-6);
  const auto per_metre = mapping::RelativePoseErrorPerMetre(est, tru, kRpeSegmentM);
  ASSERT_TRUE(per_metre) << per_metre.error().message;
  EXPECT_EQ(t["rpe"]["per_metre"]["pairs"].get<int>(), per_metre->pairs);
  EXPECT_NEAR(t["rpe"]["per_metre"]["translation_rmse_m_per_m"].get<double>(),
              per_metre->translation_rmse, kRoundTrip);
  // Scan-to-map registration on a floor with two objects: the drift the closed loop reports
  // elsewhere (office 0.17 m median at the goal, issue 20), far below a metre.
  EXPECT_LT(t["ate"]["unaligned"]["rmse_m"].get<double>(), 0.3);
  EXPECT_LE(t["ate"]["aligned"]["rmse_m"].get<double>(),
            t["ate"]["unaligned"]["rmse_m"].get<double>() + kRoundTrip);
}

}  // namespace
}  // namespace pitchlab::mission
