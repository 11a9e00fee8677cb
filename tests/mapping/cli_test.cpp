// `pitchlab register` and `pitchlab merge` (apps/register_command.cpp, apps/merge_command.cpp)
// called directly on simulated scans written as PCD.

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pitchlab/sensors/scan_pcd.hpp"
#include "sim_scans.hpp"

namespace pitchlab::apps {
int RunRegister(int argc, char** argv);  // declared in apps/commands.hpp once wired
int RunMerge(int argc, char** argv);
}  // namespace pitchlab::apps

namespace pitchlab::mapping {
namespace {

namespace fs = std::filesystem;
using testing::SimulatedScan;

// Runs a subcommand on `args`, returns its exit code and stdout.
template <typename F>
std::pair<int, std::string> RunCommand(F command, std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  ::testing::internal::CaptureStdout();
  const int code = command(static_cast<int>(argv.size()), argv.data());
  return {code, ::testing::internal::GetCapturedStdout()};
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("pitchlab_cli_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const sensors::Scan3D& scan, const std::string& name) {
    const std::string path = (dir_ / name).string();
    EXPECT_TRUE(sensors::WriteScanPcd(scan, path));
    return path;
  }
  fs::path dir_;
};

TEST_F(Cli, RegisterPrintsTheMatrixResultFieldsAndTheGroundTruthErrorAsJson) {
  const std::string target = Write(SimulatedScan("office", -8, 0, 0, 1), "a.pcd");
  const std::string source = Write(SimulatedScan("office", -7.2, 0.3, 12, 2), "b.pcd");
  auto [code, out] =
      RunCommand(apps::RunRegister, {source, target, "--json", "--prior", "0.8,0.3,0,0,0,12"});
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["T_target_source"].size(), 16u);
  EXPECT_TRUE(j["success"].get<bool>());
  EXPECT_EQ(j["path"], "features");
  EXPECT_TRUE(j["timings_s"].contains("initial_alignment"));
  EXPECT_LT(j["ground_truth_error"]["rotation_deg"].get<double>(), 0.5);
  EXPECT_LT(j["ground_truth_error"]["translation_m"].get<double>(), 0.03);
}

TEST_F(Cli, RegisterOfScansWithoutOverlapExitsNonZeroWithTheReason) {
  const std::string target = Write(SimulatedScan("office", -8, 0, 0, 1), "a.pcd");
  const std::string source = Write(SimulatedScan("terrain", 0, 0, 0), "b.pcd");
  auto [code, out] = RunCommand(apps::RunRegister, {source, target, "--json"});
  EXPECT_EQ(code, 1);
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_FALSE(j["success"].get<bool>());
  EXPECT_FALSE(j["reason"].get<std::string>().empty());
}

TEST_F(Cli, RegisterOfAMissingFileThrowsNamingIt) {
  try {
    RunCommand(apps::RunRegister, {(dir_ / "nope.pcd").string(), (dir_ / "nope2.pcd").string()});
    FAIL() << "no error";
  } catch (const std::exception& e) {
    ::testing::internal::GetCapturedStdout();
    EXPECT_NE(std::string(e.what()).find("nope"), std::string::npos) << e.what();
  }
}

TEST_F(Cli, RegisterWithAConfigHavingAnUnknownKeyThrowsNamingTheKey) {
  const std::string scan = Write(SimulatedScan("office", -8, 0, 0, 1), "a.pcd");
  const std::string config = (dir_ / "c.yaml").string();
  std::ofstream(config) << "registration:\n  icp_voxel_m: 0.1\n  voxel: 2\n";
  try {
    RunCommand(apps::RunRegister, {scan, scan, "--config", config});
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    ::testing::internal::GetCapturedStdout();
    EXPECT_EQ(std::string(e.what()), config + ": registration.voxel is not a known setting");
  }
}

TEST_F(Cli, MergeWritesTheMapAndTheTrajectory) {
  std::vector<std::string> args;
  const double xs[] = {-8, -7.4, -6.8};
  for (int i = 0; i < 3; ++i) {
    args.push_back(Write(SimulatedScan("office", xs[i], 0.1 * i, 5.0 * i, 20 + i),
                         "s" + std::to_string(i) + ".pcd"));
  }
  const std::string map = (dir_ / "map.pcd").string();
  args.insert(args.end(), {"--out", map, "--json"});
  auto [code, out] = RunCommand(apps::RunMerge, args);
  ASSERT_EQ(code, 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["merged"], 3);
  Result<sensors::Scan3D> read = sensors::ReadScanPcd(map);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->points.size(), j["map_points"].get<std::size_t>());
  std::ifstream csv(dir_ / "map_trajectory.csv");
  std::string line;
  int lines = 0;
  while (std::getline(csv, line)) ++lines;
  EXPECT_EQ(lines, 4);  // header + 3 poses
  for (const auto& step : j["steps"]) {
    if (!step.contains("ground_truth_error")) continue;
    EXPECT_LT(step["ground_truth_error"]["translation_m"].get<double>(), 0.03);
  }
}

}  // namespace
}  // namespace pitchlab::mapping
