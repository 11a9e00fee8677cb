// The cloud fuzzer's input handling and contract check (fuzz/cloud_input.hpp) against known
// answers: every seed of its corpus is a file the readers read within the contract, the first
// byte picks the format as the fuzzer's seeds assume, and the check reports each way a reader
// could break the contract. The fuzzer itself (fuzz/cloud_fuzz.cpp) aborts on such a report.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "fuzz/cloud_input.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> Bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(CloudFuzzContract, EverySeedIsReadWithinTheContract) {
  const fs::path corpus = fs::path(PITCHLAB_SOURCE_DIR) / "tests/hw/fuzz/corpus/cloud";
  const test_support::ScopedTempDir dir("cloud_contract");
  int seeds = 0, read = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(corpus)) {
    const std::vector<std::uint8_t> bytes = Bytes(e.path());
    const std::string path =
        WriteCloudInput(bytes.data(), bytes.size(), (dir / e.path().filename()).string());
    ASSERT_FALSE(path.empty()) << e.path();
    const Result<sensors::Scan3D> scan = sensors::ReadCloudFile(path);
    EXPECT_EQ(CloudContractBreach(scan, path), "") << e.path();
    // A seed is a valid file of its format: it reads, with points, or it seeds nothing useful.
    EXPECT_TRUE(scan && !scan->points.empty())
        << e.path() << ": " << (scan ? "no points" : scan.error().message);
    ++seeds;
    read += scan.has_value();
  }
  EXPECT_GE(seeds, 9);  // one of each format and encoding
  EXPECT_EQ(read, seeds);
}

TEST(CloudFuzzContract, TheFirstBytePicksTheFormat) {
  const test_support::ScopedTempDir dir("cloud_contract_format");
  const std::string stem = (dir / "in").string();
  const std::uint8_t xyz[] = {2, '1', ' ', '2', ' ', '3', '\n'};
  const std::string path = WriteCloudInput(xyz, sizeof(xyz), stem);
  EXPECT_EQ(path, stem + ".xyz");
  const Result<sensors::Scan3D> scan = sensors::ReadCloudFile(path);
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->points.size(), 1u);
  EXPECT_EQ(scan->points[0].z, 3.0f);
  const std::uint8_t uos[] = {3, '1', '0', ' ', '2', '0', ' ', '3', '0', '\n'};  // cm, left-handed
  EXPECT_EQ(WriteCloudInput(uos, sizeof(uos), stem), stem + ".3d");
  EXPECT_TRUE(fs::exists(stem + ".pose"));  // the 3DTK reader needs its pose
  EXPECT_EQ(WriteCloudInput(uos, 0, stem), "");
}

TEST(CloudFuzzContract, TheCheckReportsEveryBreach) {
  const std::string path = "/some/scan.pcd";
  sensors::Scan3D good;
  good.points.push_back({1, 2, 3});
  good.sensor_origin = Eigen::Vector3d(0, 0, 0.5);
  EXPECT_EQ(CloudContractBreach(good, path), "");
  EXPECT_EQ(CloudContractBreach(Fail(Error::Code::kInvalidArgument,
                                               path + ": line 3: not a number"),
                                path),
            "");

  const float nan = std::numeric_limits<float>::quiet_NaN();
  sensors::Scan3D bad_point = good;
  bad_point.points.push_back({0, nan, 0});
  EXPECT_EQ(CloudContractBreach(bad_point, path), "a point is not finite");
  sensors::Scan3D bad_pose = good;
  bad_pose.T_world_base.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(CloudContractBreach(bad_pose, path), "the pose is not finite");
  sensors::Scan3D bad_origin = good;
  bad_origin.sensor_origin->z() = std::nan("");
  EXPECT_EQ(CloudContractBreach(bad_origin, path), "the sensor origin is not finite");
  EXPECT_NE(CloudContractBreach(
                Fail(Error::Code::kInvalidArgument, "line 3: not a number"),
                path),
            "");
}

}  // namespace
}  // namespace pitchlab::fuzz
