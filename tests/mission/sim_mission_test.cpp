#include "pitchlab/mission/sim_mission.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>

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

fs::path Scratch() {
  const fs::path dir =
      fs::temp_directory_path() / ("pitchlab_simmission_" + std::to_string(::getpid()) + "_" +
                                   ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

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
  const worlds::WorldMetadata meta = LoadWorldMetadata(WriteFloorWorld(Scratch()));
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
  const fs::path dir = Scratch();
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt);
  spec.world_file = WriteFloorWorld(dir);
  spec.goal_m = Eigen::Vector2d(20.0, 0.0);  // the bounds end at x = 5
  try {
    RunSimMission(spec, dir / "run");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("off the map"), std::string::npos) << e.what();
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}), 1)
      << "only the world file: no run folder, no staging folder";
}

TEST(RunSimMission, NoGoalGivenAndNoneInTheWorldIsABadSpec) {
  const fs::path dir = Scratch();
  SimMissionSpec spec = LoadSimMissionSpec(std::nullopt);
  spec.world_file = WriteFloorWorld(dir);
  EXPECT_THROW(RunSimMission(spec, dir / "run"), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "run"));
}

TEST(RunSimMission, NoWorldFileIsABadSpec) {
  const fs::path dir = Scratch();
  EXPECT_THROW(RunSimMission(LoadSimMissionSpec(std::nullopt), dir / "run"), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mission
