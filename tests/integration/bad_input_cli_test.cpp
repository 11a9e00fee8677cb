// Bad input to the `pitchlab` binary, as a new user gives it (issue 18): each case exits with the
// README's code (2 for a command-line mistake, 1 for a bad file or an impossible request), says
// what is wrong naming the option or file, does so before any long work, and leaves nothing.

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;

// The first line each command prints once its work starts: a check "before the work" must fail
// without it (wall time would depend on the machine and on sanitizers).
constexpr const char* kRunStarted = "run: ground truth";
constexpr const char* kScanStarted = "scan: line";
constexpr const char* kMapStarted = "map: reading";
constexpr const char* kBenchStarted = "bench: start";

class BadInputCli : public ::testing::Test {
 protected:
  void SetUp() override { fs::create_directories(dir_ / "scratch"); }

  CliResult Exec(const std::string& args) { return cli_test::RunPitchlab(args, dir_ / "scratch"); }
  // Everything in dir_ but the scratch folder and the inputs a test wrote: what a command left.
  std::vector<std::string> Left(const std::vector<std::string>& inputs = {}) const {
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(dir_.path())) {
      const std::string name = e.path().filename().string();
      if (name != "scratch" && std::find(inputs.begin(), inputs.end(), name) == inputs.end())
        left.push_back(name);
    }
    return left;
  }
  // An ascii PCD of `points` lines ("x y z") with pitchlab's header comments `comments`.
  fs::path Pcd(const std::string& name, const std::vector<std::string>& points,
               const std::string& comments = "# sensor_origin 0 0 0.5\n# pose truth\n") const {
    std::ostringstream os;
    os << "# .PCD v0.7\n"
       << comments << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH "
       << points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size()
       << "\nDATA ascii\n";
    for (const std::string& p : points) os << p << "\n";
    std::ofstream(dir_ / name) << os.str();
    return dir_ / name;
  }
  // A floor 1..5 m ahead of the sensor, 0.5 m below it, every 5 cm.
  static std::vector<std::string> Floor() {
    std::vector<std::string> points;
    for (int i = 0; i <= 80; ++i) {
      for (int j = -40; j <= 40; ++j) {
        points.push_back(std::to_string(1.0 + 0.05 * i) + " " + std::to_string(0.05 * j) + " 0");
      }
    }
    return points;
  }
  std::string Out(const std::string& name) const { return (dir_ / name).string(); }

  const test_support::ScopedTempDir dir_{"bad_input"};
};

TEST_F(BadInputCli, VersionPrintsTheProjectVersion) {
  const CliResult r = Exec("--version");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("pitchlab 0.", 0), 0u) << r.out;
}

TEST_F(BadInputCli, ASeedBeyond64BitsIsACommandLineMistakeNotSeedZero) {
  const CliResult r = Exec("run --world office --seed 99999999999999999999999 --out " + Out("r"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--seed '99999999999999999999999' is not a whole number"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find(kRunStarted), std::string::npos) << r.err;
  EXPECT_TRUE(Left().empty());
}

TEST_F(BadInputCli, OutputPathsAreCheckedBeforeTheWork) {
  CliResult r = Exec("run --world office --out \"\"");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--out is empty"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(kRunStarted), std::string::npos) << r.err;

  r = Exec("scan --world office --out " + Out("no/such/folder/x.pcd"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--out '" + Out("no/such/folder/x.pcd") + "'"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("Success"), std::string::npos) << r.err;  // no stale errno
  EXPECT_EQ(r.err.find(kScanStarted), std::string::npos) << r.err;

  r = Exec("scan --world office --out " + dir_.path().string());  // a folder
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("is a folder"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(kScanStarted), std::string::npos) << r.err;
  EXPECT_TRUE(Left().empty());
}

TEST_F(BadInputCli, MapAndPlanRefuseAnExistingFolderAsRunDoes) {
  Pcd("floor.pcd", Floor());
  fs::create_directories(dir_ / "taken");
  for (const std::string& command :
       {"map " + (dir_ / "floor.pcd").string(), std::string("run --world office"),
        "plan " + (dir_ / "floor.pcd").string() + " --start 0,0 --goal 1,1"}) {
    const CliResult r = Exec(command + " --out " + Out("taken"));
    EXPECT_EQ(r.exit_code, 1) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("'" + Out("taken") + "' already exists; give a new --out"),
              std::string::npos)
        << command << "\n" << r.err;
    for (const char* started : {kRunStarted, kMapStarted}) {
      EXPECT_EQ(r.err.find(started), std::string::npos) << command << "\n" << r.err;
    }
  }
  EXPECT_TRUE(fs::is_empty(dir_ / "taken"));
}

TEST_F(BadInputCli, MapOptionsOutOfRangeAreCommandLineMistakes) {
  Pcd("floor.pcd", Floor());
  const CliResult r = Exec("map " + (dir_ / "floor.pcd").string() + " --clearance -1 --out " +
                           Out("m"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--clearance '-1' is out of range"), std::string::npos) << r.err;
  EXPECT_EQ(Left({"floor.pcd"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, MapAreaWithNoPointsInsideIsAnErrorNotAnEmptyMap) {
  Pcd("floor.pcd", Floor());
  const CliResult r = Exec("map " + (dir_ / "floor.pcd").string() +
                           " --no-level --area 100,100,110,110 --out " + Out("m"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("no point of the clouds went into the map"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("outside the map area (--area)"), std::string::npos) << r.err;
  EXPECT_EQ(Left({"floor.pcd"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, MapCountsThePointsTheReaderDroppedAsNonFinite) {
  std::vector<std::string> points = Floor();
  const std::size_t nan_points = points.size() / 10;
  for (std::size_t i = 0; i < nan_points; ++i) points.push_back("nan nan nan");
  Pcd("floor.pcd", points);
  const CliResult r =
      Exec("map " + (dir_ / "floor.pcd").string() + " --no-level --json --out " + Out("m"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json map = nlohmann::json::parse(Slurp(dir_ / "m" / "map.json"));
  EXPECT_EQ(map["non_finite"].get<std::size_t>(), nan_points);
}

TEST_F(BadInputCli, MapSaysWhatItIsDoingDuringItsLongSteps) {
  Pcd("floor.pcd", Floor());
  const CliResult r =
      Exec("map " + (dir_ / "floor.pcd").string() + " --world office --out " + Out("m"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* step : {"map: reading ", "map: inserting ", "map: ground truth of office",
                           "map: ground truth: 100 %"}) {
    EXPECT_NE(r.err.find(step), std::string::npos) << step << "\n" << r.err;
  }
}

TEST_F(BadInputCli, MapOfAnotherWorldsScanIsRefused) {
  Pcd("urban.pcd", Floor(), "# sensor_origin 0 0 0.5\n# pose truth\n# world urban\n");
  const CliResult r =
      Exec("map " + (dir_ / "urban.pcd").string() + " --world office --out " + Out("m"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("was scanned in world 'urban', not 'office' (--world)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(Left({"urban.pcd"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, AnAbsurdPointIsNamedAndPclSaysNothingFirst) {
  std::vector<std::string> points = Floor();
  points.insert(points.begin() + 7, "1e30 0 0");
  Pcd("far.pcd", points);
  CliResult r = Exec("map " + (dir_ / "far.pcd").string() + " --out " + Out("m"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("point 7 at (1e+30, 0, 0) m"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.rfind("map: reading ", 0), 0u) << r.err;  // pitchlab's own lines only

  // A header PCL's reader itself complains about: its own lines must not come first.
  std::ofstream(dir_ / "bad.pcd") << "VERSION 0.7\nFIELDS x y z\nSIZE 4 4\nTYPE F F F\n"
                                     "COUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n";
  r = Exec("map " + (dir_ / "bad.pcd").string() + " --out " + Out("m"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("map: reading ", 0), 0u) << r.err;
  EXPECT_EQ(r.err.find("[pcl"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pitchlab map: error: PCD '" + (dir_ / "bad.pcd").string() +
                       "': SIZE has 2 entries for 3 FIELDS"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(Left({"far.pcd", "bad.pcd"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, AMapTooBigForAMapSaysWhetherAStrayPointOrTheCellIsTheCause) {
  std::vector<std::string> points = Floor();
  Pcd("floor.pcd", points);
  points.push_back("90000 5 0");  // 90 km out: finite, within the reader's 100 km, no return
  Pcd("stray.pcd", points);
  CliResult r = Exec("map " + (dir_ / "stray.pcd").string() + " --no-level --cell 0.01 --out " +
                     Out("m"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("the farthest point, " + std::to_string(points.size() - 1) + " of '" +
                       (dir_ / "stray.pcd").string() + "' at (90000, 5, 0) m"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("coarser"), std::string::npos) << r.err;  // the cell is not the cause
  r = Exec("map " + (dir_ / "floor.pcd").string() + " --no-level --cell 0.00001 --out " +
           Out("m"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("give a coarser --cell or a smaller --area"), std::string::npos) << r.err;
  EXPECT_EQ(Left({"floor.pcd", "stray.pcd"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, RunningOutOfMemoryIsAnErrorSayingSo) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves more address space than the limit below allows";
#else
  // 10000 x 10000 cells: a few GB, less than the machine has (so map's own check before the
  // allocation passes) but more than the 2.5 GB of address space the process is given here.
  const double memory = double(::sysconf(_SC_PHYS_PAGES)) * double(::sysconf(_SC_PAGE_SIZE));
  if (memory < 16e9) GTEST_SKIP() << "map refuses the area itself on a machine under 16 GB";
  Pcd("floor.pcd", {"1 0 0", "2 0 0", "1 1 0"});
  const fs::path out = dir_ / "scratch" / "stdout.txt", err = dir_ / "scratch" / "stderr.txt";
  const std::string command = "ulimit -v 2500000; exec " + std::string(PITCHLAB_CLI) + " map " +
                              (dir_ / "floor.pcd").string() +
                              " --no-level --area 0,0,100,100 --cell 0.01 --out " + Out("m") +
                              " >" + out.string() + " 2>" + err.string();
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << Slurp(err);
  EXPECT_NE(Slurp(err).find("pitchlab map: error: out of memory"), std::string::npos)
      << Slurp(err);
  EXPECT_EQ(Left({"floor.pcd"}), std::vector<std::string>{});
#endif
}

TEST_F(BadInputCli, ADuplicateConfigKeyIsAnErrorNamingIt) {
  std::ofstream(dir_ / "dup.yaml") << "lms200:\n  noise_sigma_m: 0.01\n  noise_sigma_m: 0.5\n";
  const CliResult r = Exec("scan --world office --config " + (dir_ / "dup.yaml").string() +
                           " --out " + Out("s.pcd"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("lms200.noise_sigma_m is given twice (lines 2 and 3)"), std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find(kScanStarted), std::string::npos) << r.err;
  EXPECT_EQ(Left({"dup.yaml"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, ADuplicatePlannerKeyIsAnErrorNamingIt) {
  std::ofstream(dir_ / "planner.yaml") << "unknown: penalise\nstep_max_m: 0.05\nstep_max_m: 0.2\n";
  // plan's own --config, read before the map.
  CliResult r = Exec("plan " + (dir_ / "absent.plem").string() + " --config " +
                     (dir_ / "planner.yaml").string() + " --start 0,0 --goal 1,1 --out " +
                     Out("p"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("planner.yaml: step_max_m is given twice (lines 2 and 3)"),
            std::string::npos)
      << r.err;
  // The planner section of a run's config.
  std::ofstream(dir_ / "run.yaml") << "planner:\n  step_max_m: 0.05\n  step_max_m: 0.2\n";
  r = Exec("run --world office --config " + (dir_ / "run.yaml").string() + " --out " + Out("r"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("planner.step_max_m is given twice (lines 2 and 3)"), std::string::npos)
      << r.err;
  EXPECT_EQ(Left({"planner.yaml", "run.yaml"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, BenchResumedWithAnotherConfigIsRefusedBeforeAnyRun) {
  const fs::path bench = dir_ / "bench";
  fs::create_directories(bench);
  // A run recorded by a sweep with the built-in defaults.
  std::ofstream(bench / "runs.jsonl")
      << R"({"world":"office","seed":1,"config_hash":"built-in-defaults","success":true})"
      << "\n";
  std::ofstream(dir_ / "other.yaml") << "lms200: {noise_sigma_m: 0.02}\n";
  const CliResult r = Exec("bench --worlds office --seeds 1..2 --out " + bench.string() +
                           " --config " + (dir_ / "other.yaml").string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("holds runs made with another config (built-in-defaults: office-s1)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find(kBenchStarted), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(bench / "runs" / "office-s2"));
}

TEST_F(BadInputCli, APoseInsideABuildingIsAnErrorNotItsRoof) {
  // urban_building_a spans x 8..26, y 8..15 and is 9 m tall (worlds/urban.xml).
  const CliResult r = Exec("scan --world urban --pose 17,11.5,0 --out " + Out("s.pcd"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("start (17.000, 11.500) is on top of an obstacle, not on the ground"),
            std::string::npos)
      << r.err;
  EXPECT_TRUE(Left().empty());
}

TEST_F(BadInputCli, AWorldMuJoCoCannotLoadIsNamedWithoutInternalNames) {
  std::ofstream(dir_ / "bad.xml") << "<mujoco><worldbody><geom type=\"nosuch\"/></worldbody>"
                                     "</mujoco>\n";
  const CliResult r = Exec("scan --world " + (dir_ / "bad.xml").string() + " --out " + Out("s.pcd"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("bad.xml"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("Simulation::"), std::string::npos) << r.err;
  EXPECT_EQ(Left({"bad.xml"}), std::vector<std::string>{});
}

TEST_F(BadInputCli, CommandLineMistakesExitTwo) {
  for (const char* args : {"register --prior-error -1,-5 a.pcd b.pcd",
                           "hw lms200 --device /dev/null --fov 90 --once",
                           "hw lms200 --device /dev/null --fov wide --once"}) {
    const CliResult r = Exec(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find("--"), std::string::npos) << args << ": names no option\n" << r.err;
  }
}

}  // namespace
}  // namespace pitchlab
