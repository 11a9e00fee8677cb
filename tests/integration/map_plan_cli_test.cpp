// End to end through the `pitchlab` binary: scan -> map --world -> plan --json, every file read
// back, and bad input to `plan` refused with a clear error, exit code 1 and no output folder.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/planning/occupancy_grid.hpp"

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;

// One office scan and its map, made once for the suite (a scan takes seconds).
class MapPlanCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // Per process: CTest runs each test of the suite in its own process, in parallel.
    scratch_.emplace("cli_map_plan");
    dir_ = scratch_->path();
    const CliResult scan =
        Run("scan --world office --json --quiet --out " + (dir_ / "office.pcd").string());
    ASSERT_EQ(scan.exit_code, 0) << scan.err;
    const auto pose = nlohmann::json::parse(scan.out)["pose"];
    start_x_ = pose["x_m"].get<double>();
    start_y_ = pose["y_m"].get<double>();
    map_run_ = Run("map " + (dir_ / "office.pcd").string() +
                   " --world office --cell 0.1 --json --out " + (dir_ / "map").string());
  }
  static void TearDownTestSuite() { scratch_.reset(); }

  static CliResult Run(const std::string& args) {
    return cli_test::RunPitchlab(args, dir_);
  }
  static std::string Point(double x, double y) {
    return std::to_string(x) + "," + std::to_string(y);
  }

  // The suite's folder, from its set-up to its tear-down (or the end of the process).
  static inline std::optional<test_support::ScopedTempDir> scratch_;
  static inline fs::path dir_;
  static inline double start_x_ = 0, start_y_ = 0;
  static inline CliResult map_run_;
};

TEST_F(MapPlanCli, ScanMapPlanWritesFilesThatParse) {
  ASSERT_EQ(map_run_.exit_code, 0) << map_run_.err;
  ASSERT_FALSE(map_run_.out.empty()) << map_run_.err;
  const nlohmann::json map = nlohmann::json::parse(map_run_.out);
  EXPECT_GT(map["known_cells"].get<int>(), 100);
  EXPECT_TRUE(map.contains("truth"));
  // --world's frame is the simulator's, z up: nothing to level.
  EXPECT_NE(map["levelling"]["method"].get<std::string>().find("--world"), std::string::npos);
  EXPECT_EQ(map["max_height_m"].get<double>(), 1.0);
  EXPECT_EQ(nlohmann::json::parse(Slurp(dir_ / "map" / "map.json"))["cell_m"], 0.1);
  const auto loaded = mapping::LoadElevationMap((dir_ / "map" / "map.plem").string());
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->geometry().size_x, map["size_x"].get<int>());
  EXPECT_EQ(Slurp(dir_ / "map" / "elevation.asc").rfind("ncols", 0), 0u);
  EXPECT_FALSE(Slurp(dir_ / "map" / "elevation.prj").empty());
  EXPECT_EQ(Slurp(dir_ / "map" / "elevation.png").substr(0, 8), "\x89PNG\r\n\x1a\n");

  // 1.5 m ahead of the robot (facing +x at the office's start). The laser does not see the
  // floor right around the robot, so unknown cells are penalised, not forbidden.
  const fs::path plan_dir = dir_ / "plan";
  const CliResult plan = Run("plan " + (dir_ / "map" / "map.plem").string() + " --start " +
                          Point(start_x_, start_y_) + " --goal " +
                          Point(start_x_ + 1.5, start_y_) +
                          " --unknown penalise --json --out " + plan_dir.string());
  ASSERT_EQ(plan.exit_code, 0) << plan.err;
  ASSERT_TRUE(fs::exists(plan_dir / "plan.json")) << plan.out;
  const nlohmann::json result = nlohmann::json::parse(plan.out);
  EXPECT_TRUE(result["found"].get<bool>());
  EXPECT_GT(result["cost"].get<double>(), 0);
  EXPECT_GE(result["length_m"].get<double>(), 1.4);
  EXPECT_EQ(nlohmann::json::parse(Slurp(plan_dir / "plan.json"))["cost"], result["cost"]);
  std::ifstream csv(plan_dir / "path.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header, "index,x_m,y_m,z_m,cum_length_m");
  std::size_t rows = 0;
  while (std::getline(csv, line)) rows += !line.empty();
  EXPECT_EQ(rows, result["waypoints"].get<std::size_t>());
  if (map.contains("geodetic_origin")) {  // GeoJSON needs the world's geodetic origin
    const nlohmann::json geo = nlohmann::json::parse(Slurp(plan_dir / "path.geojson"));
    EXPECT_EQ(geo["features"][0]["geometry"]["coordinates"].size(), rows);
  } else {
    EXPECT_FALSE(fs::exists(plan_dir / "path.geojson"));
    EXPECT_NE(result["geojson"].get<std::string>().find("no geodetic origin"), std::string::npos);
  }
  EXPECT_EQ(Slurp(plan_dir / "path.png").substr(0, 8), "\x89PNG\r\n\x1a\n");
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos) << e.path();
}

TEST_F(MapPlanCli, MapWritesRastersAndAnOccupancyGridThatPlanReads) {
  ASSERT_EQ(map_run_.exit_code, 0) << map_run_.err;
  const fs::path map_dir = dir_ / "map";
  const auto map = mapping::LoadElevationMap((map_dir / "map.plem").string());
  ASSERT_TRUE(map) << map.error().message;
  for (const char* raster : {"inclination", "roughness"}) {
    const auto grid = mapping::ReadAsciiGrid((map_dir / (std::string(raster) + ".asc")).string());
    ASSERT_TRUE(grid) << grid.error().message;
    EXPECT_EQ(grid->ncols, map->geometry().size_x);
    EXPECT_EQ(Slurp(map_dir / (std::string(raster) + ".prj")), Slurp(map_dir / "elevation.prj"));
  }
  // The map_server grid: the map's geometry, the office floor free, its walls lethal.
  const auto occupancy = planning::LoadOccupancyGrid((map_dir / "traversability.yaml").string());
  ASSERT_TRUE(occupancy) << occupancy.error().message;
  EXPECT_TRUE(occupancy->geometry.SameAs(map->geometry()));
  std::size_t lethal = 0, free = 0;
  for (std::int8_t v : occupancy->value) lethal += v == 100, free += v >= 0 && v < 100;
  EXPECT_EQ(lethal, nlohmann::json::parse(map_run_.out)["lethal_cells"].get<std::size_t>());
  EXPECT_GT(free, 100u);
  // The same plan as on the .plem, through the bridge: 1.5 m ahead of the robot.
  const fs::path plan_dir = dir_ / "plan_occupancy";
  const CliResult plan =
      Run("plan " + (map_dir / "traversability.yaml").string() + " --start " +
          Point(start_x_, start_y_) + " --goal " + Point(start_x_ + 1.5, start_y_) +
          " --unknown penalise --json --out " + plan_dir.string());
  ASSERT_EQ(plan.exit_code, 0) << plan.err;
  EXPECT_TRUE(nlohmann::json::parse(plan.out)["found"].get<bool>());
  EXPECT_GE(nlohmann::json::parse(plan.out)["length_m"].get<double>(), 1.4);
}

// The real 3DTK pair (a nodding SICK whose lines' pitch is off by ~1 deg RMS): map sets each
// scan's lines right by the floor, which flattens the floor the levelling fits; --as-recorded
// keeps the lines, and the simulated office scan (laser off the pitch axis, in base_link) is no
// nodding scan in its own frame, so nothing of it moves.
TEST_F(MapPlanCli, MapSetsARealNoddingScansLinesRightByItsFloor) {
  const std::string real = std::string(PITCHLAB_3DTK_CORRIDOR_DIR) + "/scan000.3d " +
                           PITCHLAB_3DTK_CORRIDOR_DIR + "/scan001.3d";
  const CliResult set_right = Run("map " + real + " --out " + (dir_ / "real").string());
  ASSERT_EQ(set_right.exit_code, 0) << set_right.err;
  const auto a = nlohmann::json::parse(Slurp(dir_ / "real" / "map.json"));
  ASSERT_EQ(a["line_pitch"].size(), 2u);
  for (const auto& c : a["line_pitch"]) {
    EXPECT_GT(c["result"]["corrected"].get<int>(), 50) << c.dump();
    EXPECT_LT(c["result"]["floor_rms_after_m"].get<double>(),
              0.5 * c["result"]["floor_rms_before_m"].get<double>());
    // The rig's LMS at 0.5 deg: each line two interlaced sweeps, each set right on its own.
    EXPECT_EQ(c["result"]["sweeps_per_line"].get<int>(), 2) << c.dump();
  }
  EXPECT_NE(set_right.err.find("interlaced in each of 226 lines) set right by the floor"),
            std::string::npos)
      << set_right.err;
  const CliResult kept =
      Run("map " + real + " --as-recorded --out " + (dir_ / "real_kept").string());
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  const auto b = nlohmann::json::parse(Slurp(dir_ / "real_kept" / "map.json"));
  EXPECT_EQ(b["line_pitch"][0]["result"]["corrected"].get<int>(), 0);
  // The levelling's floor fit: 1.0 cm with the lines set right, 2.9 cm as recorded.
  EXPECT_LT(a["levelling"]["residual_m"].get<double>(),
            0.5 * b["levelling"]["residual_m"].get<double>());
  const auto office = nlohmann::json::parse(Slurp(dir_ / "map" / "map.json"));
  EXPECT_EQ(office["line_pitch"][0]["result"]["corrected"].get<int>(), 0) << office.dump();
}

TEST_F(MapPlanCli, BadInputOrNoPathGivesAClearErrorANonZeroExitAndPicturesOnlyForNoPath) {
  ASSERT_EQ(map_run_.exit_code, 0) << map_run_.err;
  const std::string map = (dir_ / "map" / "map.plem").string();
  const std::string start = Point(start_x_, start_y_);
  const struct {
    std::string args, message;
  } cases[] = {
      {(dir_ / "missing.plem").string() + " --start " + start + " --goal " + start, "missing"},
      {map + " --start -500,0 --goal " + start, "start_outside_map"},
      {map + " --start " + start + " --goal " + Point(start_x_, start_y_ + 1e3),
       "goal_outside_map"},
      // 1 m to the robot's left: next to the corridor wall, inside the footprint's margin.
      {map + " --start " + start + " --goal " + Point(start_x_, start_y_ + 1), "goal_blocked"},
      // Ahead, but unknown cells (never seen around the robot) are forbidden by default.
      {map + " --start " + start + " --goal " + Point(start_x_ + 1.5, start_y_), "disconnected"},
  };
  for (const auto& c : cases) {
    const fs::path out = dir_ / "bad_plan";
    fs::remove_all(out);
    const CliResult run = Run("plan " + c.args + " --out " + out.string());
    EXPECT_EQ(run.exit_code, 1) << c.args;
    EXPECT_NE(run.err.find(c.message), std::string::npos) << c.args << "\n" << run.err;
    // Start and goal on the map but no path: the pictures and plan.json show why. A missing map
    // or a point off it is a mistake in the command: no folder.
    const bool on_map = c.message == "goal_blocked" || c.message == "disconnected";
    EXPECT_EQ(fs::exists(out / "traversability.png"), on_map) << c.args;
    EXPECT_EQ(fs::exists(out / "elevation.png"), on_map) << c.args;
    EXPECT_EQ(fs::exists(out / "path.csv"), false) << c.args;
    if (on_map) {
      EXPECT_EQ(Slurp(out / "traversability.png").substr(0, 8), "\x89PNG\r\n\x1a\n");
      EXPECT_NE(Slurp(out / "plan.json").find("\"found\": false"), std::string::npos);
      EXPECT_NE(run.err.find("traversability.png"), std::string::npos) << run.err;
    } else {
      EXPECT_FALSE(fs::exists(out)) << c.args;
    }
  }
}

}  // namespace
}  // namespace pitchlab
