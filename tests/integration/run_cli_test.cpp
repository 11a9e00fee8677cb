// The closed loop end to end through the `pitchlab run` binary, in a small yard world.

#include <sys/wait.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"

#include "cli_support.hpp"
#include "png_pixels.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;
using test_support::ReadPng;
using test_support::Rgb8;

const fs::path kYard = fs::path(PITCHLAB_SOURCE_DIR) / "tests/data/worlds/yard.xml";

class RunCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_.emplace("run_cli");
    dir_ = scratch_->path();
  }
  static void TearDownTestSuite() { scratch_.reset(); }

  static CliResult Exec(const std::string& args) { return cli_test::RunPitchlab(args, dir_); }
  // Folders in the scratch folder other than the successful run's: a failed run leaves none,
  // not even its hidden staging folder.
  static int Leftovers() {
    int n = 0;
    for (const auto& e : fs::directory_iterator(dir_)) {
      n += e.is_directory() && e.path().filename().string().rfind("ok", 0) != 0;
    }
    return n;
  }
  // The suite's folder, from its set-up to its tear-down (or the end of the process).
  static inline std::optional<test_support::ScopedTempDir> scratch_;
  static inline fs::path dir_;
};

TEST_F(RunCli, AMissionAroundABlockReachesTheGoalAndWritesEveryOutput) {
  const fs::path run = dir_ / "ok_yard";
  const CliResult r =
      Exec("run --world " + kYard.string() + " --seed 3 --json --quiet --out " + run.string());
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const nlohmann::json metrics = nlohmann::json::parse(Slurp(run / "metrics.json"));
  EXPECT_EQ(metrics, nlohmann::json::parse(r.out));
  EXPECT_TRUE(metrics["success"].get<bool>()) << metrics["reason"];
  constexpr double kGoalTolerance_m = 0.5, kPoseBound_m = 0.15;
  EXPECT_LT(metrics["final_true_distance_to_goal_m"].get<double>(),
            kGoalTolerance_m + kPoseBound_m);
  EXPECT_LT(metrics["final_pose_error"]["translation_m"].get<double>(), kPoseBound_m);
  EXPECT_LT(metrics["max_registration_error"]["translation_m"].get<double>(), kPoseBound_m);
  // Each registration on its own: the motion since the last merged stop, against the truth.
  const nlohmann::json& step = metrics["registration_step_error"];
  EXPECT_GE(step["steps"].get<int>(), 1);
  EXPECT_LE(step["p95_m"].get<double>(), step["max_m"].get<double>());
  EXPECT_LT(step["max_m"].get<double>(), kPoseBound_m);
  EXPECT_LT(step["max_deg"].get<double>(), 1.0);
  // The mount calibrated on the start pad against the error the simulator drew (the measured
  // model's 0.25 deg per axis): found to a tenth of a degree.
  const nlohmann::json& mount = metrics["mount_calibration"];
  ASSERT_TRUE(mount["calibrated"].get<bool>()) << mount;
  EXPECT_EQ(mount["truth_rpy_deg"].size(), 3u);
  EXPECT_LT(mount["max_error_deg"].get<double>(), 0.1) << mount;
  EXPECT_GT(metrics["closest_approach_to_forbidden_m"].get<double>(), 0.0);  // never on a hazard
  EXPECT_EQ(metrics["hazard_cells_crossed"].get<int>(), 0);
  EXPECT_LE(metrics["hazard_cells_crossed"].get<int>(),
            metrics["forbidden_cells_crossed"].get<int>());
  // The final map's hazards against the true ones: the block's walls seen, few false ones.
  const nlohmann::json& hazards = metrics["map_hazards"];
  const double compared = hazards["cells_compared"].get<double>();
  EXPECT_GT(compared, 2000);
  EXPECT_LT(hazards["false_hazard_cells"].get<double>(), 0.01 * compared);
  EXPECT_LT(hazards["missed_hazard_cells"].get<double>(), 0.01 * compared);
  // Every missed (and crossed) hazard is one of the three kinds, by the truth.
  const nlohmann::json& missed = hazards["missed_as"];
  EXPECT_EQ(missed["step"].get<int>() + missed["drop"].get<int>() + missed["too_steep"].get<int>(),
            hazards["missed_hazard_cells"].get<int>());
  const nlohmann::json& crossed = metrics["hazard_cells_crossed_as"];
  EXPECT_EQ(crossed["step"].get<int>() + crossed["drop"].get<int>() + crossed["too_steep"].get<int>(),
            metrics["hazard_cells_crossed"].get<int>());
  EXPECT_GT(metrics["distance_m"].get<double>(), 11.0);  // around the block, not through it
  EXPECT_GE(metrics["cost_ratio"].get<double>(), 0.95);
  EXPECT_LT(metrics["cost_ratio"].get<double>(), 1.5);

  // Every file is present and opens in what reads it.
  const int stops = metrics["stops"].get<int>();
  ASSERT_GE(stops, 2);
  for (int k = 0; k < stops; ++k) {
    char stop[32];
    std::snprintf(stop, sizeof(stop), "stops/%03d/", k);
    const auto scan = sensors::ReadScanPcd((run / stop / "scan.pcd").string());
    ASSERT_TRUE(scan) << stop;
    EXPECT_EQ(scan->world, "yard") << stop;  // so `map --world` can refuse it for another world
    EXPECT_NO_THROW(nlohmann::json::parse(Slurp(run / stop / "registration.json"))) << stop;
    EXPECT_EQ(Slurp(run / stop / "map.png").substr(1, 3), "PNG") << stop;
  }
  EXPECT_TRUE(fs::exists(run / "stops/000/path.csv"));
  EXPECT_NO_THROW(nlohmann::json::parse(Slurp(run / "stops/000/path.geojson")));
  const auto cloud = sensors::ReadScanPcd((run / "map_cloud.pcd").string());
  ASSERT_TRUE(cloud);
  EXPECT_GT(cloud->points.size(), 1000u);
  EXPECT_EQ(cloud->world, "yard");
  EXPECT_TRUE(mapping::LoadElevationMap((run / "elevation.plem").string()));
  EXPECT_NE(Slurp(run / "elevation.asc").find("ncols"), std::string::npos);
  EXPECT_NE(Slurp(run / "elevation.prj").find("PROJCS"), std::string::npos);
  for (const char* png : {"elevation.png", "truth_elevation.png", "traversability.png",
                          "truth_traversability.png", "hazard_errors.png"}) {
    EXPECT_EQ(Slurp(run / png).substr(1, 3), "PNG") << png;
  }
  EXPECT_FALSE(fs::exists(run / "last_plan.png"));  // a failed run's picture
  for (const char* csv : {"trajectory_estimated.csv", "trajectory_true.csv"}) {
    const std::string text = Slurp(run / csv);
    EXPECT_EQ(text.rfind("stamp_s,x_m,y_m,z_m", 0), 0u) << csv;
    EXPECT_GT(std::count(text.begin(), text.end(), '\n'), 20) << csv;
  }
  const nlohmann::json geo = nlohmann::json::parse(Slurp(run / "trajectories.geojson"));
  EXPECT_EQ(geo["features"].size(), 2u);
  const YAML::Node config = YAML::LoadFile((run / "config.yaml").string());
  EXPECT_EQ(config["seed"].as<int>(), 3);
  const std::string html = Slurp(run / "report.html");
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);  // every script inline: works offline
  EXPECT_NE(html.find("<div id=outcome class=\"outcome "), std::string::npos);
  // The console's last word agrees with the report's verdict: "unsafe" lines exactly when the
  // report says the run was (this run kept off every hazard).
  EXPECT_NE(html.find("<div id=outcome class=\"outcome ok\""), std::string::npos);
  EXPECT_EQ(r.err.find("unsafe"), std::string::npos) << r.err;
}

struct BadRun {
  std::string args, message;
};

// A run that fails shows the grid its last plan was made on, that plan and where the robot went
// (estimated and true tracks): here the stop limit ends the run at its second stop's plan.
TEST_F(RunCli, AFailedRunShowsItsLastPlanOnTheGridItWasMadeOn) {
  std::ofstream(dir_ / "two_stops.yaml") << "run: {max_stops: 2}\n";
  const fs::path run = dir_ / "ok_two_stops";
  const CliResult r = Exec("run --world " + kYard.string() + " --seed 3 --json --quiet --config " +
                           (dir_ / "two_stops.yaml").string() + " --out " + run.string());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const nlohmann::json metrics = nlohmann::json::parse(Slurp(run / "metrics.json"));
  ASSERT_FALSE(metrics["success"].get<bool>());
  EXPECT_NE(metrics["reason"].get<std::string>().find("stop limit"), std::string::npos);
  const Rgb8 last = ReadPng(run / "last_plan.png"), map = ReadPng(run / "traversability.png");
  ASSERT_GT(last.width, 0);
  // The same window and scale as the run's other pictures.
  EXPECT_EQ(last.width, map.width);
  EXPECT_EQ(last.height, map.height);
  // The plan in red (planning::DrawPath), the true track in blue; the final map's picture has
  // neither.
  EXPECT_GT(last.Count({230, 20, 20}), 100);
  EXPECT_GT(last.Count({30, 80, 255}), 10);
  EXPECT_EQ(map.Count({230, 20, 20}), 0);
  EXPECT_EQ(map.Count({30, 80, 255}), 0);
  EXPECT_NE(Slurp(run / "report.html").find("last_plan.png"), std::string::npos);
}

// The README's main job runs `pitchlab run` with no --out in a fresh clone: the default
// runs/<world>-s<seed>-<time> is created with its missing runs/ folder (it once was refused).
TEST_F(RunCli, WithoutOutTheRunGoesToANewRunsFolderInTheWorkingFolder) {
  const fs::path cwd = dir_ / "ok_default_out";
  fs::create_directories(cwd);
  const std::string command = "cd " + cwd.string() + " && " + std::string(PITCHLAB_CLI) +
                              " run --world " + kYard.string() + " --seed 3 --quiet >" +
                              (dir_ / "default_out.txt").string() + " 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0) << Slurp(dir_ / "default_out.txt");
  std::vector<fs::path> runs;
  for (const auto& e : fs::directory_iterator(cwd / "runs")) runs.push_back(e.path());
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].filename().string().rfind("yard-s3-", 0), 0u) << runs[0];
  EXPECT_TRUE(fs::exists(runs[0] / "metrics.json"));
  EXPECT_TRUE(fs::exists(runs[0] / "report.html"));
}

TEST_F(RunCli, BadInputGivesAClearErrorAndLeavesNoRunFolder) {
  std::ofstream(dir_ / "bad.yaml") << "run: {drive_per_stop_m: -1}\n";
  const std::string yard = " --world " + kYard.string();
  const BadRun cases[] = {
      {"--world atlantis", "unknown world 'atlantis'"},
      {yard + " --goal 40,0", "off the map"},
      {yard + " --goal 0,1", "unreachable"},  // inside the block
      {yard + " --config " + (dir_ / "bad.yaml").string(), "drive_per_stop_m"},
      {yard + " --start -5.5,0", "needs 3 comma-separated numbers"},
  };
  for (const BadRun& c : cases) {
    const CliResult r = Exec("run --quiet " + c.args + " --out " + (dir_ / "bad_run").string());
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << " said: " << r.err;
    EXPECT_EQ(Leftovers(), 0) << c.args;
  }
}

}  // namespace
}  // namespace pitchlab
