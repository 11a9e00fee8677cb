#include "pitchlab/mission/sim_mission.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mission/stage_times.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

// A floor with pitchlab's metadata: placement bounds 10 x 6 m around the origin, no default goal.
constexpr const char* kFloorWorld = R"(<mujoco model="floor">
  <custom>
    <numeric name="pitchlab:bounds" data="-5 -3 5 3"/>
    <numeric name="pitchlab:default_start" data="-4 0 0"/>
  </custom>
  <worldbody><geom name="floor" type="plane" size="6 4 0.1"/></worldbody>
</mujoco>)";

using test_support::ScopedTempDir;

fs::path WriteFloorWorld(const fs::path& dir) {
  const fs::path file = dir / "floor.xml";
  std::ofstream(file) << kFloorWorld;
  return file;
}

TEST(LoadSimMissionSpec, OneSeedReachesEveryRandomSource) {
  const SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 7);
  EXPECT_EQ(spec.config.seed, 7u);
  EXPECT_EQ(spec.config.sensors.lms200.seed, 7u);
  EXPECT_EQ(spec.config.rig.lms200.seed, 7u);
  EXPECT_EQ(spec.config.rig.odometry.seed, 7u);
  EXPECT_EQ(spec.config.rig.imu.seed, 7u);
}

TEST(LoadSimMissionSpec, TheRobotModelPicksItsPlannerPreset) {
  const SimMissionSpec dx = LoadSimMissionSpec(std::nullopt, std::nullopt, sim::P3Model::kP3DX);
  EXPECT_EQ(dx.config.rig.robot.model, sim::P3Model::kP3DX);
  EXPECT_EQ(dx.settings.mission.planner.robot.name, "p3dx");
  EXPECT_DOUBLE_EQ(dx.settings.mission.planner.robot.width_m,
                   planning::RobotLimits::P3DX().width_m);
}

TEST(LoadWorldMetadata, ReadsTheWorldsBoundsAndStart) {
  const ScopedTempDir dir("simmission");
  const worlds::WorldMetadata meta = LoadWorldMetadata(WriteFloorWorld(dir.path()));
  EXPECT_DOUBLE_EQ(meta.bounds.x_min_m, -5.0);
  EXPECT_DOUBLE_EQ(meta.bounds.y_max_m, 3.0);
  EXPECT_DOUBLE_EQ(meta.default_start.x_m, -4.0);
  EXPECT_FALSE(meta.default_goal.has_value());
}

TEST(LoadWorldMetadata, AMissingFileIsAnErrorNamingIt) {
  try {
    LoadWorldMetadata("/nonexistent/world.xml");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/world.xml"), std::string::npos) << e.what();
  }
}

TEST(RunSimMission, AGoalOffTheMapIsRefusedBeforeAnyFolderIsMade) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt);
  spec.world_file = WriteFloorWorld(dir.path());
  spec.goal_m = Eigen::Vector2d(20.0, 0.0);  // the bounds end at x = 5
  try {
    RunSimMission(spec, dir / "run");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("off the map"), std::string::npos) << e.what();
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator{}), 1)
      << "only the world file: no run folder, no staging folder";
}

TEST(RunSimMission, NoGoalGivenAndNoneInTheWorldIsABadSpec) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt);
  spec.world_file = WriteFloorWorld(dir.path());
  EXPECT_THROW(RunSimMission(spec, dir / "run"), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "run"));
}

// The default mission on the flat floor world written into `dir`, to `goal`.
SimMissionSpec FloorSpec(const fs::path& dir, const Eigen::Vector2d& goal) {
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt);
  spec.world_file = WriteFloorWorld(dir);
  spec.goal_m = goal;
  return spec;
}

// A real run, 2 m across the floor: its breakdown in metrics.json covers every stage, each a
// part of the run, and "other" is what they leave of it.
TEST(RunSimMission, ItsStageBreakdownAddsUpToTheRunWithOtherAsTheRest) {
  // Sums of up to a dozen clock readings in seconds: rounding far below the clocks' nanosecond.
  constexpr double kSumTolerance_s = 1e-9;
  const ScopedTempDir dir("simmission");
  const SimMissionSpec spec = FloorSpec(dir.path(), {-2.0, 0.0});  // 2 m ahead of the start (-4, 0)
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  std::ifstream file(run.folder / "metrics.json");
  const nlohmann::json metrics = nlohmann::json::parse(file);
  ASSERT_TRUE(metrics.contains("stages"));
  const nlohmann::json& stages = metrics["stages"];
  const double run_wall = stages["run"]["wall_s"].get<double>();
  const double run_cpu = stages["run"]["cpu_s"].get<double>();
  EXPECT_DOUBLE_EQ(run_wall, metrics["wall_time_s"].get<double>()) << "one span, two names";
  double wall = 0, cpu = 0;
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const char* key = StageKey(static_cast<Stage>(i));
    ASSERT_TRUE(stages.contains(key)) << key;
    EXPECT_GE(stages[key]["wall_s"].get<double>(), 0.0) << key;
    EXPECT_GE(stages[key]["cpu_s"].get<double>(), 0.0) << key;
    wall += stages[key]["wall_s"].get<double>();
    cpu += stages[key]["cpu_s"].get<double>();
  }
  EXPECT_LE(wall, run_wall);
  EXPECT_LE(cpu, run_cpu);
  ASSERT_TRUE(stages.contains("other"));
  EXPECT_NEAR(stages["other"]["wall_s"].get<double>(), run_wall - wall, kSumTolerance_s);
  EXPECT_NEAR(stages["other"]["cpu_s"].get<double>(), run_cpu - cpu, kSumTolerance_s);
  // The run drove, scanned, registered and wrote files: those stages took time.
  for (const char* key : {"physics_driving", "physics_standing", "ray_casting", "registration",
                          "map_update", "outputs", "ground_truth"}) {
    EXPECT_GT(stages[key]["cpu_s"].get<double>(), 0.0) << key;
  }
}

std::vector<fs::path> TruthFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().extension() == ".plem") files.push_back(e.path());
  }
  return files;
}

// Runs of one world share its ground truth through truth_cache_dir: the first run ray casts it
// and leaves it there, a run with another seed (another mount error drawn for the robot) reads it
// back and scores against the same truth; a corrupt file is said and replaced; another world
// (a box on the floor) is a file of its own.
TEST(RunSimMission, RunsOfOneWorldShareTheGroundTruthThroughItsCache) {
  const ScopedTempDir dir("simmission");
  const fs::path cache = dir / "truth";
  int runs = 0;
  auto run = [&](std::uint64_t seed, const fs::path& world, std::string& setup) {
    SimMissionSpec spec = FloorSpec(dir.path(), {-2.0, 0.0});
    spec.world_file = world;
    spec.config = LoadSimMissionSpec(std::nullopt, seed).config;
    spec.truth_cache_dir = cache;
    SimMissionObserver observer;
    observer.on_setup = [&setup](const std::string& text) { setup += text + "\n"; };
    const fs::path out = dir / ("run" + std::to_string(++runs));
    return RunSimMission(spec, out, observer);
  };
  const fs::path floor = WriteFloorWorld(dir.path());
  std::string first, second, corrupt, boxed;
  const SimMissionOutcome a = run(1, floor, first);
  ASSERT_TRUE(a.result.success) << a.result.reason;
  const std::vector<fs::path> files = TruthFiles(cache);
  ASSERT_EQ(files.size(), 1u) << first;
  EXPECT_EQ(first.find("true surface from"), std::string::npos) << first;

  const SimMissionOutcome b = run(2, floor, second);
  ASSERT_TRUE(b.result.success) << b.result.reason;
  EXPECT_NE(second.find("true surface from " + files[0].string()), std::string::npos) << second;
  EXPECT_EQ(TruthFiles(cache).size(), 1u);
  EXPECT_EQ(a.metrics["true_optimal_cost"], b.metrics["true_optimal_cost"]);

  std::ofstream(files[0], std::ios::trunc) << "not a map";
  const SimMissionOutcome c = run(2, floor, corrupt);
  ASSERT_TRUE(c.result.success) << c.result.reason;
  EXPECT_NE(corrupt.find("the cached one is unusable"), std::string::npos) << corrupt;
  EXPECT_EQ(c.metrics["true_optimal_cost"], b.metrics["true_optimal_cost"]);
  EXPECT_GT(fs::file_size(files[0]), 1000u) << "replaced by the truth";

  const fs::path box_world = dir / "boxed.xml";
  std::string xml = kFloorWorld;
  xml.replace(xml.find("</worldbody>"), 0,
              R"(<geom name="box" type="box" size="0.3 0.3 0.3" pos="3 2 0.3"/>)");
  std::ofstream(box_world) << xml;
  const SimMissionOutcome d = run(1, box_world, boxed);
  ASSERT_TRUE(d.result.success) << d.result.reason;
  EXPECT_EQ(boxed.find("true surface from"), std::string::npos) << boxed;
  EXPECT_EQ(TruthFiles(cache).size(), 2u);
}

// Wheels on a level floor barely slip, so the registration prior's bound grows with the distance
// at the level rate there (the office's corridors let a scan slide 0.84 m along the axis within
// the terrain's rate, and called it success). The floor world reads level throughout.
TEST(RunSimMission, OnALevelFloorTheOdometryBoundGrowsAtTheLevelRate) {
  const ScopedTempDir dir("simmission");
  const SimMissionSpec spec = FloorSpec(dir.path(), {-2.0, 0.0});  // 2 m ahead of the start (-4, 0)
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  const std::vector<StopRecord>& stops = run.result.stops;
  ASSERT_GE(stops.size(), 2u);
  // Every stop merged, and the run ended at its last: each metre driven is in one stop's bound.
  const MissionConfig& m = spec.settings.mission;
  double grown_m = 0;
  for (std::size_t k = 1; k < stops.size(); ++k) {
    ASSERT_TRUE(stops[k].merge.merged) << k;
    grown_m += stops[k].prior_bound.translation_m - m.odometry_error_m;
  }
  const double driven_m = run.result.odometry_distance_m;
  EXPECT_GT(driven_m, 1.5);
  EXPECT_NEAR(grown_m, m.odometry_error_level_per_m * driven_m, 1e-9);
  std::ifstream file(run.folder / "stops" / "001" / "registration.json");
  const nlohmann::json reg = nlohmann::json::parse(file);
  EXPECT_DOUBLE_EQ(reg["prior_bound"]["translation_m"].get<double>(),
                   stops[1].prior_bound.translation_m);
}

// Off level ground a skid-steer base slides as it turns, so the prior's bound grows with the yaw
// odometry turned there as well as with the distance: on a floor rolled 5 deg (past the 3 deg
// that counts as level), with a box to drive round, each stop's bound is the constant, the
// distance at the rough rate and the turn at odometry_error_per_rad, and the turn each stop
// records is the one the robot made.
TEST(RunSimMission, OffLevelTheOdometryBoundGrowsWithTheTurnAsWellAsTheDistance) {
  const ScopedTempDir dir("simmission");
  std::string xml = kFloorWorld;
  xml.replace(xml.find(R"(size="6 4 0.1")"), 0, R"(euler="5 0 0" )");
  xml.replace(xml.find("</worldbody>"), 0,
              R"(<geom name="box" type="box" size="0.4 0.4 0.4" pos="0 0 0.4"/>)");
  const fs::path world = dir / "rolled.xml";
  std::ofstream(world) << xml;
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt);
  spec.world_file = world;
  spec.goal_m = {3.0, 0.0};  // beyond the box, from the start (-4, 0)
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  const std::vector<StopRecord>& stops = run.result.stops;
  ASSERT_GE(stops.size(), 3u);
  const MissionConfig& m = spec.settings.mission;
  double turned_rad = 0;
  for (std::size_t k = 1; k < stops.size(); ++k) {
    ASSERT_TRUE(stops[k].merge.merged) << k;
    EXPECT_NEAR(stops[k].prior_bound.translation_m,
                m.odometry_error_m + m.odometry_error_per_m * stops[k].driven_m +
                    m.odometry_error_per_rad * stops[k].turned_rad,
                1e-9)
        << "stop " << k;
    turned_rad += stops[k].turned_rad;
  }
  // The truth's yaw turned from the first scan to the last.
  const auto yaw = [](const Eigen::Isometry3d& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
  };
  double true_rad = 0;
  std::optional<double> last;
  for (const TrajectorySample& t : run.result.trajectory) {
    if (t.stamp_s < stops.front().stamp_s || t.stamp_s > stops.back().stamp_s) continue;
    const double y = yaw(*t.T_world_base_true);
    if (last) true_rad += std::abs(std::remainder(y - *last, 2 * M_PI));
    last = y;
  }
  EXPECT_GT(true_rad, 0.5) << "the box was driven round";
  EXPECT_NEAR(turned_rad, true_rad, 0.15 * true_rad);
}

// The map frame is the robot's pose at its first scan, taken from odometry after it turned to
// face the goal. Read while the base still braked out of the turn, it missed the last fraction
// of a degree, and every map started 0.2-0.4 deg off in yaw: 0.1-0.2 m at 30 m.
TEST(RunSimMission, TheFirstScansPoseHasTheTurnToTheGoalToATenthOfADegree) {
  const ScopedTempDir dir("simmission");
  // 90 deg left of the start (-4, 0), yaw 0
  SimMissionSpec spec = FloorSpec(dir.path(), {-4.0, 2.5});
  spec.settings.mission.max_stops = 1;
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_EQ(run.result.stops.size(), 1u) << run.result.reason;
  const StopRecord& stop = run.result.stops.front();
  ASSERT_TRUE(stop.T_world_base_true);
  const auto yaw = [](const Eigen::Isometry3d& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
  };
  EXPECT_NEAR(yaw(*stop.T_world_base_true), 90.0, 3.0);  // TurnTo's tolerance
  EXPECT_NEAR(yaw(stop.T_world_base), yaw(*stop.T_world_base_true), 0.1);
}

// Stuck is no progress for stuck_timeout_s, not a turn that takes longer: at 0.15 rad/s the
// quarter turn to the goal takes over 10 s, more than the 8 s allowed without progress, and is
// made (until session 33 a turn was stuck after 8 s in all).
TEST(RunSimMission, ASlowTurnThatKeepsTurningIsNotStuck) {
  const ScopedTempDir dir("simmission");
  // 90 deg left of the start (-4, 0), yaw 0
  SimMissionSpec spec = FloorSpec(dir.path(), {-4.0, 2.5});
  spec.settings.mission.max_stops = 1;
  spec.settings.mission.follower.max_yaw_rate_rps = 0.15;
  ASSERT_LT(spec.settings.mission.stuck_timeout_s, (M_PI / 2) / 0.15);
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_EQ(run.result.stops.size(), 1u) << run.result.reason;
  EXPECT_GT(run.result.stops.front().stamp_s, (M_PI / 2 - 3 * M_PI / 180) / 0.15);
}

// A round trip ends back at the start facing the way it came; its last stop turns to the first
// scan's heading and scans again (Mission::ClosingLook), so the last registration meets the view
// the map was started from. On the floor: 2 m east and back, the first scans face east.
TEST(RunSimMission, ARoundTripEndsLookingWhereItsFirstScanLooked) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = FloorSpec(dir.path(), {-2.0, 0.0});
  spec.round_trip = true;
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  EXPECT_EQ(run.result.reason, "goal reached");
  const std::vector<StopRecord>& stops = run.result.stops;
  ASSERT_GE(stops.size(), 3u);
  const auto yaw_deg = [](const Eigen::Isometry3d& T) {
    return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
  };
  const auto off_deg = [&](const StopRecord& a, const StopRecord& b) {
    return std::abs(std::remainder(yaw_deg(a.T_world_base) - yaw_deg(b.T_world_base), 360.0));
  };
  const StopRecord &first = stops.front(), &arrival = stops[stops.size() - 2],
                   &closing = stops.back();
  EXPECT_GT(off_deg(arrival, first), 90.0);  // it came back facing west
  EXPECT_LT(off_deg(closing, first), 3.0);   // TurnTo's tolerance
  EXPECT_TRUE(closing.merge.merged) << closing.merge.registration.reason;
  EXPECT_FALSE(closing.plan.has_value());
  EXPECT_LT((closing.T_world_base.translation() - first.T_world_base.translation()).head<2>().norm(),
            spec.settings.mission.goal_tolerance_m);
}

// The office's goal room is seen from the corridor only through its door, so the first scan
// inside shares about a tenth of its points with the map (seed 2: 10.6 % with the LMS200 model
// before session 51; seed 5's stop 6: 14.1 % with today's). Refused for that
// share, the map never grew into the room: every later stop there fitted none of the map and the
// room was mapped from odometry alone. What fits at a low share is judged as any fit is.
TEST(RunSimMission, AScanThroughADoorIntoAnUnseenRoomJoinsTheMap) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 5);
  spec.world_file = fs::path(PITCHLAB_WORLDS_DIR) / "office.xml";
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  const double share = spec.settings.mission.registration.registration.min_inlier_ratio;
  int low_share = 0;
  for (const StopRecord& s : run.result.stops) {
    EXPECT_TRUE(s.merge.merged) << "stop " << s.index << ": " << s.merge.registration.reason;
    if (s.index == 0 || !s.merge.merged || !s.T_world_base_true) continue;
    const double inliers = s.merge.registration.inlier_ratio;
    if (inliers >= 0.15) continue;
    ++low_share;
    EXPECT_GE(inliers, share);
    const Eigen::Isometry3d off = s.T_world_base_true->inverse() * s.T_world_base;
    EXPECT_LT(off.translation().norm(), 0.1) << "stop " << s.index;
    EXPECT_LT(Eigen::AngleAxisd(off.linear()).angle() * 180 / M_PI, 0.5) << "stop " << s.index;
  }
  EXPECT_GE(low_share, 1) << "no stop fitted less than 15 % of its points: nothing tested";
}

// The P3-DX may climb 2.5 cm: a far floor's single points differ by that much from noise alone.
// Taken as steps, they walled its runs in on floors it could drive (cluttered seeds 1..4: none
// reached the goal); steps now need support, as slopes do (planning/README.md).
TEST(RunSimMission, TheP3DxCrossesTheClutteredRoomsFloor) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 1, sim::P3Model::kP3DX);
  spec.world_file = fs::path(PITCHLAB_WORLDS_DIR) / "cluttered.xml";
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  EXPECT_TRUE(run.result.success) << run.result.reason;
  EXPECT_EQ(run.metrics["forbidden_cells_crossed"], 0) << run.metrics.dump();
}

// The README's main command. Steering by odometry, the robot slid up to 0.5 m off a plan that kept
// clear of the crack's south-west end and came over 14 forbidden and 2 true hazard cells there.
// Its drives now end where the drift could reach a hazard beside the plan (drift_per_m), and the
// next scan puts it back on its map.
TEST(RunSimMission, TheDefaultRunsDrivesEndBeforeDriftTakesThemOntoAHazard) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 1);
  spec.world_file = fs::path(PITCHLAB_WORLDS_DIR) / "terrain.xml";
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  ASSERT_TRUE(run.result.success) << run.result.reason;
  EXPECT_EQ(run.metrics["forbidden_cells_crossed"], 0) << run.metrics.dump();
  EXPECT_EQ(run.metrics["hazard_cells_crossed"], 0) << run.metrics.dump();
  int cut = 0;
  for (const StopRecord& s : run.result.stops) {
    cut += s.plan && s.plan_clear_m < std::min(s.plan_known_m, spec.settings.mission.drive_per_stop_m);
  }
  EXPECT_GE(cut, 1) << "no drive was cut for drift: nothing tested";
  EXPECT_GT(run.metrics["odometry_drift"]["drives"].get<int>(), 10);
}

// After a stop that only turned, the robot drives a metre onto the blind zone ahead of it; a plan
// that the new scan moved behind it starts in ground no scan saw, and is faced first. Office seed
// 5 with the real rig's servo error (0.9 deg, lines as recorded: poor maps, each scan moves the
// plan) turned south at stop 0, planned north at stop 1, reversed the metre into the corridor's
// wall behind it and climbed it to 48 deg.
TEST(RunSimMission, AfterATurnAPlanThatStartsBehindTheRobotIsFacedNotReversedInto) {
  const ScopedTempDir dir("simmission");
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt, 5);
  spec.world_file = fs::path(PITCHLAB_WORLDS_DIR) / "office.xml";
  spec.config.rig.pitch_unit.line_pitch_error_deg = 0.9;
  spec.config.rig.pitch_unit.sweep_lag_deg = 0.16;
  spec.settings.mission.max_stops = 3;
  const SimMissionOutcome run = RunSimMission(spec, dir / "run");
  EXPECT_EQ(run.result.reason.find("tipping"), std::string::npos) << run.result.reason;
  EXPECT_LT(run.metrics["max_tilt_deg"].get<double>(), 5.0) << run.metrics.dump();
}

TEST(RunSimMission, NoWorldFileIsABadSpec) {
  const ScopedTempDir dir("simmission");
  EXPECT_THROW(RunSimMission(LoadSimMissionSpec(std::nullopt), dir / "run"), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mission
