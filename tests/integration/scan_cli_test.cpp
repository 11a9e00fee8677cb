// End to end through the `pitchlab` binary: what a user types, what they get back.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pitchlab/sensors/scan_pcd.hpp"

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;

class ScanCli : public ::testing::Test {
 protected:
  CliResult Run(const std::string& args) const { return cli_test::RunPitchlab(args, dir_.path()); }
  const test_support::ScopedTempDir dir_{"scan_cli"};
};

TEST_F(ScanCli, WritesAFullSeedScanAndAJsonSummaryWithTheTruePose) {
  const fs::path pcd = dir_ / "office.pcd";
  // The LMS200 as it was before issue 16 (5 mm noise, a perfect mount): the surface tolerance
  // below rests on it. The default model's mount error tilts the floor by design.
  const fs::path config = dir_ / "legacy_lms200.yaml";
  std::ofstream(config) << "lms200: {noise_sigma_m: 0.005, noise_per_m: 0, "
                           "incidence_noise_gain: 0, dropout_far_per_m: 0, "
                           "mount_error_sigma_deg: 0}\n";
  const CliResult run = Run("scan --world office --json --quiet --config " + config.string() +
                            " --out " + pcd.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json summary = nlohmann::json::parse(run.out);
  EXPECT_EQ(summary["lines"], 200);
  EXPECT_EQ(summary["readings"], 361 * 200);
  EXPECT_EQ(summary["points"].get<int>() + summary["misses"].get<int>(), 361 * 200);
  EXPECT_GT(summary["scan_duration_s"].get<double>(), 200 * 0.041);  // lines alone take 8.3 s
  constexpr double kStartTolerance_m = 0.01;
  EXPECT_NEAR(summary["pose"]["x_m"].get<double>(), -8.0, kStartTolerance_m);  // default start
  EXPECT_NEAR(summary["pose"]["y_m"].get<double>(), 0.0, kStartTolerance_m);

  Result<sensors::Scan3D> scan = sensors::ReadScanPcd(pcd.string());
  ASSERT_TRUE(scan) << scan.error().message;
  EXPECT_EQ(scan->points.size(), summary["points"].get<std::size_t>());
  EXPECT_NEAR(scan->T_world_base.translation().x(), summary["pose"]["x_m"].get<double>(), 1e-4);
  // Seen from the world, the office's points lie between the floor and the 2.5 m walls' tops, and
  // many lie on the floor.
  std::size_t on_floor = 0;
  constexpr double kSurfaceTolerance_m = 0.03;  // 5 mm noise, 1 cm quantization, pose float
  for (const sensors::ScanPoint& p : scan->points) {
    const Eigen::Vector3d w = scan->T_world_base * Eigen::Vector3d(p.x, p.y, p.z);
    EXPECT_GT(w.z(), -kSurfaceTolerance_m);
    EXPECT_LT(w.z(), 2.5 + kSurfaceTolerance_m);
    if (std::abs(w.z()) < kSurfaceTolerance_m) ++on_floor;
  }
  EXPECT_GT(on_floor, scan->points.size() / 5);
}

TEST_F(ScanCli, SameSeedGivesTheSameBytesAndAnotherSeedDoesNot) {
  int runs = 0;
  auto scan_with_seed = [&](int seed) {
    const fs::path config = dir_ / ("seed" + std::to_string(seed) + ".yaml");
    std::ofstream(config) << "seed: " << seed << "\nscan: {lines: 40}\n";
    const fs::path pcd = dir_ / ("run" + std::to_string(runs++) + ".pcd");
    const CliResult run = Run("scan --world cluttered --quiet --config " + config.string() +
                           " --out " + pcd.string());
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return Slurp(pcd);
  };
  const std::string first = scan_with_seed(5), again = scan_with_seed(5), other = scan_with_seed(6);
  ASSERT_GT(first.size(), 1000u);
  EXPECT_TRUE(first == again) << "same seed, different bytes";
  EXPECT_FALSE(first == other) << "different seeds, same bytes";
}

struct BadInput {
  std::string args;
  std::string message;  ///< a phrase the error must contain
};

TEST_F(ScanCli, BadInputGivesAClearErrorANonZeroExitAndNoFile) {
  std::ofstream(dir_ / "bad_value.yaml") << "lms200: {resolution_deg: 0.3}\n";
  std::ofstream(dir_ / "bad_yaml.yaml") << "lms200: [unclosed\n";
  std::ofstream(dir_ / "bad_section.yaml") << "lazer: {}\n";
  const std::string d = dir_.path().string();
  const BadInput cases[] = {
      {"--world atlantis", "unknown world 'atlantis'"},
      {"--world urban --pose 100,0,0", "outside the world"},
      {"--world office --pose 3,1,0", "not on drivable ground"},  // on top of a wall
      {"--world office --pose -8,0", "needs 3 comma-separated numbers"},
      {"--world office --pose a,0,0", "is not a number"},
      {"--world office --config /nonexistent.yaml", "cannot read config file"},
      {"--world office --config " + d + "/bad_value.yaml", "lms200.resolution_deg"},
      {"--world office --config " + d + "/bad_yaml.yaml", "not valid YAML"},
      {"--world office --config " + d + "/bad_section.yaml", "unknown section 'lazer'"},
      {"--world office --robot p4", "'p4' is not a robot"},
      {"--world office --frobnicate", "unknown option '--frobnicate'"},
  };
  for (const BadInput& c : cases) {
    const fs::path pcd = dir_ / "never.pcd";
    const CliResult run = Run("scan --quiet " + c.args + " --out " + pcd.string());
    EXPECT_NE(run.exit_code, 0) << c.args;
    EXPECT_NE(run.err.find(c.message), std::string::npos) << c.args << " said: " << run.err;
    EXPECT_FALSE(fs::exists(pcd)) << c.args;
  }
}

TEST_F(ScanCli, HelpListsTheOptionsAndExitsZero) {
  const CliResult run = Run("scan --help");
  EXPECT_EQ(run.exit_code, 0);
  for (const char* option : {"--world", "--pose", "--config", "--out", "--json"}) {
    EXPECT_NE(run.out.find(option), std::string::npos) << option;
  }
  EXPECT_NE(Run("").exit_code, 0);
  EXPECT_NE(Run("teleport").exit_code, 0);
}

}  // namespace
}  // namespace pitchlab
