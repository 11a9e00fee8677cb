// Bad PCD input and a full disk: each case is an error naming the file, never a crash, a
// 20-second allocation, or a file left behind (issue 18).

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include "pitchlab/sensors/cloud_file.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"
#include "file_size_limit.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::sensors {
namespace {

namespace fs = std::filesystem;

class PcdRobustness : public ::testing::Test {
 protected:
  static pcl::PointCloud<pcl::PointXYZ> Cloud(int n) {
    pcl::PointCloud<pcl::PointXYZ> cloud;
    for (int i = 0; i < n; ++i) cloud.push_back(pcl::PointXYZ(1.0f + i, 0.5f * i, -0.25f));
    return cloud;
  }
  std::string Text(const fs::path& file) const {
    std::ifstream in(file, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  void Rewrite(const fs::path& file, const std::string& text) const {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
  }
  // A compressed PCD of 100 points with its uncompressed-size word replaced by `size`.
  fs::path CompressedWithUncompressedSize(std::uint32_t size) const {
    const fs::path file = dir_ / "compressed.pcd";
    EXPECT_EQ(pcl::io::savePCDFileBinaryCompressed(file.string(), Cloud(100)), 0);
    std::string text = Text(file);
    const std::size_t data = text.find("DATA binary_compressed\n") + 23;
    std::memcpy(&text[data + 4], &size, sizeof(size));
    Rewrite(file, text);
    return file;
  }
  // A PCD of 3 points with its VIEWPOINT line replaced.
  fs::path WithViewpoint(const std::string& viewpoint) const {
    const fs::path file = dir_ / "viewpoint.pcd";
    EXPECT_EQ(pcl::io::savePCDFileASCII(file.string(), Cloud(3)), 0);
    std::string text = Text(file);
    const std::size_t at = text.find("VIEWPOINT");
    text.replace(at, text.find('\n', at) - at, "VIEWPOINT " + viewpoint);
    Rewrite(file, text);
    return file;
  }

  const test_support::ScopedTempDir dir_{"pcdrob"};
};

TEST_F(PcdRobustness, CompressedHeaderWithUncompressedSizeZeroIsAnErrorNotACrash) {
  const fs::path file = CompressedWithUncompressedSize(0);
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find(file.string()), std::string::npos);
  EXPECT_NE(read.error().message.find("uncompressed size 0"), std::string::npos)
      << read.error().message;
}

TEST_F(PcdRobustness, CompressedHeaderWithAHugeSizeIsRejectedBeforeReading) {
  const fs::path file = CompressedWithUncompressedSize(1000000000u);
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find("uncompressed size 1000000000"), std::string::npos)
      << read.error().message;
}

TEST_F(PcdRobustness, AnIntactCompressedFileStillReads) {
  const fs::path file = dir_ / "ok.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(file.string(), Cloud(100)), 0);
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->points.size(), 100u);
}

TEST_F(PcdRobustness, AnAsciiHeaderPromisingMorePointsThanTheFileHoldsIsAnError) {
  const fs::path file = dir_ / "ascii.pcd";
  ASSERT_EQ(pcl::io::savePCDFileASCII(file.string(), Cloud(3)), 0);
  std::string text = Text(file);
  for (const char* key : {"WIDTH 3", "POINTS 3"}) {
    const std::size_t at = text.find(key);
    text.replace(at, std::strlen(key), std::string(key, std::strlen(key) - 1) + "1000000000");
  }
  Rewrite(file, text);
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find("1000000000 points"), std::string::npos)
      << read.error().message;
}

TEST_F(PcdRobustness, AbsurdViewpointsAreErrorsNamingTheValue) {
  const struct {
    const char* viewpoint;
    const char* says;
  } kCases[] = {
      {"1e9 0 0 1 0 0 0", "VIEWPOINT translation (1e+09 0 0)"},
      {"nan 0 0 1 0 0 0", "VIEWPOINT translation (nan 0 0)"},
      {"0 0 0 0 0 0 0", "VIEWPOINT quaternion (0 0 0 0)"},
      {"0 0 0 nan 0 0 0", "VIEWPOINT quaternion (nan 0 0 0)"},
  };
  for (const auto& c : kCases) {
    const fs::path file = WithViewpoint(c.viewpoint);
    Result<Scan3D> read = ReadScanPcd(file.string());
    ASSERT_FALSE(read) << c.viewpoint;
    EXPECT_NE(read.error().message.find(c.says), std::string::npos) << read.error().message;
  }
}

TEST_F(PcdRobustness, AHandWrittenUnitQuaternionIsAccepted) {
  const fs::path file = WithViewpoint("1 2 0 0.7071 0 0 0.7071");  // 0.99999 long
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_NEAR(read->T_world_base.translation().y(), 2.0, 1e-6);
}

TEST_F(PcdRobustness, EightByteFloatXyzIsRead) {
  pcl::PCLPointCloud2 cloud;
  for (const char* name : {"x", "y", "z"}) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = static_cast<std::uint32_t>(8 * cloud.fields.size());
    f.datatype = pcl::PCLPointField::FLOAT64;
    f.count = 1;
    cloud.fields.push_back(f);
  }
  const double xyz[2][3] = {{1.5, -2.25, 0.125}, {40000.5, 3, 4}};
  cloud.width = 2;
  cloud.height = 1;
  cloud.point_step = 24;
  cloud.row_step = 48;
  cloud.data.resize(48);
  std::memcpy(cloud.data.data(), xyz, sizeof(xyz));
  const fs::path file = dir_ / "doubles.pcd";
  ASSERT_EQ(pcl::PCDWriter().writeBinary(file.string(), cloud), 0);
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_EQ(read->points.size(), 2u);
  EXPECT_EQ(read->points[0].y, -2.25f);
  EXPECT_EQ(read->points[1].x, 40000.5f);
}

TEST_F(PcdRobustness, APointFarOutsideAnyScanIsAnErrorNamingIt) {
  pcl::PointCloud<pcl::PointXYZ> cloud = Cloud(5);
  cloud[3].x = 1e30f;
  const fs::path file = dir_ / "far.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(file.string(), cloud), 0);
  Result<Scan3D> read = ReadCloudFile(file.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find("point 3 at (1e+30, 1.5, -0.25) m"), std::string::npos)
      << read.error().message;
}

// A full disk, as a file-size limit makes it portably (no tmpfs to mount in a test): the write
// fails with its reason, names the path, and leaves neither the file nor its temporary.
TEST_F(PcdRobustness, AFullDiskIsAnErrorWithItsReasonAndLeavesNothing) {
  Scan3D scan;
  scan.points.resize(20000);  // 560 kB of records
  const fs::path file = dir_ / "scan.pcd";
  const int names_it = test_support::InChildWithFileSizeLimit(64 * 1024, [&] {
    const Result<void> written = WriteScanPcd(scan, file.string());
    return !written && written.error().message.find(file.string()) != std::string::npos &&
                   written.error().message.find(std::strerror(EFBIG)) != std::string::npos
               ? 0
               : 1;
  });
  EXPECT_EQ(names_it, 0) << "no error naming the path and 'File too large'";
  EXPECT_TRUE(fs::is_empty(dir_.path())) << "a partial or temporary file was left behind";
}

}  // namespace
}  // namespace pitchlab::sensors
