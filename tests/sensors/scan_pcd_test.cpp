#include "pitchlab/sensors/scan_pcd.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "scoped_temp_dir.hpp"

namespace pitchlab::sensors {
namespace {

namespace fs = std::filesystem;
using test_support::ScopedTempDir;

Scan3D SmallScan() {
  Scan3D scan;
  for (int i = 0; i < 5; ++i) {
    ScanPoint p;
    p.x = 1.0f + i;
    p.y = -0.5f * i;
    p.z = 0.25f;
    p.range_m = 2.0f + i;
    p.line = static_cast<std::uint16_t>(i / 2);
    p.beam = static_cast<std::uint16_t>(i);
    p.stamp_s = 100.0 + 0.04 * i;
    scan.points.push_back(p);
  }
  scan.has_truth = true;
  scan.T_world_base = Eigen::Isometry3d::Identity();
  scan.T_world_base.translate(Eigen::Vector3d(3.0, -2.0, 0.5));
  scan.T_world_base.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  return scan;
}

TEST(ScanPcd, RoundTripKeepsPointsFieldsAndViewpoint) {
  const ScopedTempDir dir("pcd");
  const fs::path file = dir / "scan.pcd";
  const Scan3D scan = SmallScan();
  ASSERT_TRUE(WriteScanPcd(scan, file.string()));
  Result<Scan3D> back = ReadScanPcd(file.string());
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_EQ(back->points.size(), scan.points.size());
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    EXPECT_EQ(back->points[i].x, scan.points[i].x);
    EXPECT_EQ(back->points[i].range_m, scan.points[i].range_m);
    EXPECT_EQ(back->points[i].line, scan.points[i].line);
    EXPECT_EQ(back->points[i].beam, scan.points[i].beam);
    EXPECT_EQ(back->points[i].stamp_s, scan.points[i].stamp_s);
  }
  EXPECT_TRUE(back->has_truth);
  EXPECT_TRUE(back->T_world_base.isApprox(scan.T_world_base, 1e-6));
  std::ifstream in(file);
  std::string header((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(header.find("DATA binary"), std::string::npos);
  EXPECT_NE(header.find("FIELDS x y z range ring beam stamp"), std::string::npos);
}

TEST(ScanPcd, AnUnwritableDirectoryIsAnErrorAndLeavesNoFile) {
  const ScopedTempDir dir("pcd");
  const fs::path file = dir / "no_such_dir" / "scan.pcd";
  Result<void> written = WriteScanPcd(SmallScan(), file.string());
  ASSERT_FALSE(written);
  EXPECT_NE(written.error().message.find(file.string()), std::string::npos);
  EXPECT_FALSE(fs::exists(file));
}

TEST(ScanPcd, CorruptOrMissingFilesAreErrorsNamingThePath) {
  const ScopedTempDir dir("pcd");
  EXPECT_FALSE(ReadScanPcd((dir / "missing.pcd").string()));
  const fs::path garbage = dir / "garbage.pcd";
  std::ofstream(garbage) << "this is not a point cloud\n\x01\x02";
  Result<Scan3D> read = ReadScanPcd(garbage.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find("garbage.pcd"), std::string::npos);
}

TEST(ScanPcd, ATruncatedFileIsAnErrorNotACrash) {
  const ScopedTempDir dir("pcd");
  const fs::path file = dir / "scan.pcd";
  ASSERT_TRUE(WriteScanPcd(SmallScan(), file.string()));
  std::string text;
  {
    std::ifstream in(file, std::ios::binary);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t body = text.find("DATA binary\n") + 12;  // PCL pads files to whole pages
  fs::resize_file(file, body + 2 * 28);                       // keep 2 of 5 records
  Result<Scan3D> read = ReadScanPcd(file.string());
  ASSERT_FALSE(read);
  EXPECT_NE(read.error().message.find("truncated"), std::string::npos) << read.error().message;
}

}  // namespace
}  // namespace pitchlab::sensors
