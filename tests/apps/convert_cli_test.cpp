// `pitchlab convert` (apps/convert_command.cpp) and the shared cloud input (apps/cloud_input.cpp),
// called directly; exit codes as main maps them (CliError 2, any other exception 1).

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_args.hpp"
#include "cloud_input.hpp"
#include "commands.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::apps {
namespace {

namespace fs = std::filesystem;

// Runs `convert` on `args` as main would: its return value, 2 for a CliError, 1 for any other.
int Convert(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  ::testing::internal::CaptureStdout();
  int code = 0;
  try {
    code = RunConvert(static_cast<int>(argv.size()), argv.data());
  } catch (const CliError&) {
    code = 2;
  } catch (const std::exception&) {
    code = 1;
  }
  ::testing::internal::GetCapturedStdout();
  return code;
}

class ConvertCli : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return (dir_ / name).string();
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  const test_support::ScopedTempDir dir_{"convert"};
};

TEST_F(ConvertCli, ThreeDtkScanBecomesAPcdWithTheSamePointsPoseAndOrigin) {
  Write("scan000.pose", "-3.10605 -7.50803 156.917\n1.35694 -0.852409 -0.56224\n");
  const std::string in = Write("scan000.3d", "0 0 100\n100 0 0\n0 50 200\n0 0 3276\n");
  const std::string out = Path("scan000.pcd");
  ASSERT_EQ(Convert({in, "--out", out}), 0);
  Result<sensors::Scan3D> direct = sensors::ReadCloudFile(in);
  Result<sensors::Scan3D> back = sensors::ReadScanPcd(out);
  ASSERT_TRUE(direct) << direct.error().message;
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->points.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back->points[i].x, direct->points[i].x);
    EXPECT_EQ(back->points[i].y, direct->points[i].y);
    EXPECT_EQ(back->points[i].z, direct->points[i].z);
  }
  // The PCD's VIEWPOINT is float: 1e-6 relative of a 1.6 m pose.
  EXPECT_TRUE(back->T_world_base.isApprox(direct->T_world_base, 1e-6));
  EXPECT_NEAR(back->T_world_base.translation().x(), 1.56917, 1e-6);
  EXPECT_TRUE(back->has_odometry);
  EXPECT_FALSE(back->has_truth);
  ASSERT_TRUE(back->sensor_origin);
  EXPECT_EQ(*back->sensor_origin, Eigen::Vector3d::Zero());
}

TEST_F(ConvertCli, PoseFromFramesReplacesThePoseAndOriginOverrideIsKept) {
  const std::string in = Write("cloud.xyz", "1 2 3\n4 5 6\n");
  // A slam6d line: identity rotation, translation (10, 20, 150) cm in 3DTK's frame, type 2.
  const std::string frames = Write("scan001.frames",
                                   "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 1\n"
                                   "1 0 0 0 0 1 0 0 0 0 1 0 10 20 150 1 2\n");
  const std::string out = Path("cloud.pcd");
  ASSERT_EQ(Convert({in, "--out", out, "--pose-from", frames, "--sensor-origin", "0.1,0,0.54"}), 0);
  Result<sensors::Scan3D> back = sensors::ReadScanPcd(out);
  ASSERT_TRUE(back) << back.error().message;
  // (10, 20, 150) cm 3DTK = 1.5 m forward, 0.1 m right, 0.2 m up.
  EXPECT_TRUE(back->T_world_base.translation().isApprox(Eigen::Vector3d(1.5, -0.1, 0.2), 1e-6));
  EXPECT_FALSE(back->has_odometry);  // a registered reference pose, not odometry
  ASSERT_TRUE(back->sensor_origin);
  EXPECT_TRUE(back->sensor_origin->isApprox(Eigen::Vector3d(0.1, 0, 0.54)));
}

TEST_F(ConvertCli, BadInputExitsOneAndWritesNothing) {
  const std::string in = Write("bad.xyz", "1 2 3\n4 5 6\nseven 8 9\n");
  const std::string out = Path("bad.pcd");
  EXPECT_EQ(Convert({in, "--out", out}), 1);
  EXPECT_FALSE(fs::exists(out));
  Write("scan002.3d", "0 0 100\n");  // no scan002.pose beside it
  EXPECT_EQ(Convert({Path("scan002.3d"), "--out", out}), 1);
  EXPECT_EQ(Convert({Path("missing.ply"), "--out", out}), 1);
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_.path()), fs::directory_iterator()), 2);
}

TEST_F(ConvertCli, ExistingOutputIsRefusedAndLeftAlone) {
  const std::string in = Write("cloud.xyz", "1 2 3\n");
  const std::string out = Write("taken.pcd", "not ours");
  EXPECT_EQ(Convert({in, "--out", out, "--sensor-origin", "0,0,0"}), 1);
  std::ifstream kept(out);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), "not ours");
}

TEST_F(ConvertCli, CommandLineMistakesExitTwo) {
  const std::string in = Write("cloud.xyz", "1 2 3\n");
  EXPECT_EQ(Convert({in}), 2);                          // no --out
  EXPECT_EQ(Convert({in, "--out", Path("x.ply")}), 2);  // not a PCD name
  EXPECT_EQ(Convert({in, "--out", Path("x.pcd"), "--sensor-origin", "1,2"}), 2);
  EXPECT_EQ(Convert({in, "--out", Path("x.pcd"), "--sensor-origin", "1,nan,2"}), 2);
  EXPECT_EQ(Convert({in, "--out", Path("x.pcd"), "--pose-from", Path("x.txt")}), 2);
  EXPECT_EQ(Convert({in, in, "--out", Path("x.pcd")}), 2);
  EXPECT_FALSE(fs::exists(Path("x.pcd")));
}

TEST_F(ConvertCli, HelpListsTheFormats) {
  std::vector<std::string> args = {"--help"};
  std::vector<char*> argv = {args[0].data()};
  ::testing::internal::CaptureStdout();
  EXPECT_EQ(RunConvert(1, argv.data()), 0);
  const std::string help = ::testing::internal::GetCapturedStdout();
  for (const char* ext : {".pcd", ".3d", ".ply", ".xyz"}) {
    EXPECT_NE(help.find(ext), std::string::npos) << ext << " missing from:\n" << help;
  }
}

TEST_F(ConvertCli, UnknownOriginWarnsOnceAndAssumesTheFrameOrigin) {
  const std::string in = Write("cloud.xyz", "3 4 0\n");
  ::testing::internal::CaptureStderr();
  const sensors::Scan3D scan = LoadInputCloud(in, std::nullopt);
  const std::string warning = ::testing::internal::GetCapturedStderr();
  ASSERT_TRUE(scan.sensor_origin);
  EXPECT_EQ(*scan.sensor_origin, Eigen::Vector3d::Zero());
  EXPECT_EQ(std::count(warning.begin(), warning.end(), '\n'), 1) << warning;
  EXPECT_NE(warning.find("--sensor-origin"), std::string::npos) << warning;
  EXPECT_NE(warning.find(in), std::string::npos) << warning;

  ::testing::internal::CaptureStderr();
  const sensors::Scan3D given = LoadInputCloud(in, Eigen::Vector3d(3, 0, 0));
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_FLOAT_EQ(given.points[0].range_m, 4.0f);  // ranges follow the given origin
  EXPECT_THROW(LoadInputCloud(Path("nothing.xyz"), std::nullopt), std::runtime_error);
}

TEST(SensorOrigin, ParsesThreeFiniteNumbersOnly) {
  EXPECT_EQ(ParseSensorOrigin("0.1,-2,5e-1"), Eigen::Vector3d(0.1, -2, 0.5));
  for (const char* bad : {"", "1,2", "1,2,3,4", "1,2,x", "1,2,inf", "1,,3", "1,2,3,"}) {
    EXPECT_THROW(ParseSensorOrigin(bad), CliError) << bad;
  }
}

}  // namespace
}  // namespace pitchlab::apps
