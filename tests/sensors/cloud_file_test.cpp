#include "pitchlab/sensors/cloud_file.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <tuple>

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include "pitchlab/sensors/scan_pcd.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::sensors {
namespace {

namespace fs = std::filesystem;

const fs::path kCorridor = PITCHLAB_3DTK_CORRIDOR_DIR;
constexpr double kDegToRad = M_PI / 180.0;
// Text files hold points to 6-9 significant digits and ScanPoint keeps floats: 1e-6 m is below
// both.
constexpr double kPointTolM = 1e-6;

class CloudFile : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& bytes) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path.string();
  }
  const test_support::ScopedTempDir dir_{"cloud"};
};

Eigen::Vector3d At(const ScanPoint& p) { return Eigen::Vector3d(p.x, p.y, p.z); }

double AngleDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.rotation().transpose() * b.rotation()).angle() / kDegToRad;
}

// --- 3DTK ---------------------------------------------------------------------------------------

TEST(ThreeDtk, AxisChangeMapsForwardRightUpToReP103) {
  // 3DTK: x right, y up, z forward [cm]. REP-103: x forward, y left, z up [m].
  EXPECT_TRUE(PointFrom3dtk({0, 0, 100}).isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_TRUE(PointFrom3dtk({100, 0, 0}).isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE(PointFrom3dtk({0, 100, 0}).isApprox(Eigen::Vector3d(0, 0, 1)));
}

TEST(ThreeDtk, ConvertedPoseMovesConvertedPointsAs3dtkMovesItsOwn) {
  // C T C^-1: converting then applying the converted pose = applying 3DTK's pose then converting.
  const Eigen::Matrix4d T3 = Matrix3dtkFromPose({-3.1, -7.5, 156.9}, {12.0, -35.0, 71.0});
  const Eigen::Isometry3d T = TransformFrom3dtk(T3);
  EXPECT_NEAR(T.rotation().determinant(), 1.0, 1e-12);  // a rotation, not a reflection
  for (const Eigen::Vector3d p :
       {Eigen::Vector3d(10, -20, 300), Eigen::Vector3d(-250, 40, 7), Eigen::Vector3d(0, 0, 0)}) {
    const Eigen::Vector3d moved3 = (T3 * p.homogeneous()).head<3>();
    EXPECT_TRUE((T * PointFrom3dtk(p)).isApprox(PointFrom3dtk(moved3), 1e-12)) << p.transpose();
  }
}

TEST(ThreeDtk, PoseRotationIsRxRyRzAsSlam6dBuildsIt) {
  // slam6d's EulerToMatrix4 entries for rx, ry, rz (column-major alignxf[8] = sin ry, etc.).
  const double rx = 0.3, ry = -0.2, rz = 0.7;
  const Eigen::Matrix4d T = Matrix3dtkFromPose({0, 0, 0}, Eigen::Vector3d(rx, ry, rz) / kDegToRad);
  EXPECT_NEAR(T(0, 0), std::cos(ry) * std::cos(rz), 1e-12);
  EXPECT_NEAR(T(1, 0), std::sin(rx) * std::sin(ry) * std::cos(rz) + std::cos(rx) * std::sin(rz),
              1e-12);
  EXPECT_NEAR(T(0, 2), std::sin(ry), 1e-12);
  EXPECT_NEAR(T(1, 2), -std::sin(rx) * std::cos(ry), 1e-12);
  EXPECT_NEAR(T(2, 2), std::cos(rx) * std::cos(ry), 1e-12);
}

TEST_F(CloudFile, TinyThreeDtkScanGivesHandComputedPointsAndPose) {
  // Pose: 1 m right, 2 m forward, turned +90 deg about 3DTK's y (up): forward becomes right, i.e.
  // in REP-103 a yaw of -90 deg at (2, -1, 0).
  Write("scan007.pose", "100 0 200\n0 90 0\n");
  const std::string path = Write("scan007.3d",
                                 "0 0 100\n"   // 1 m forward -> (1, 0, 0)
                                 "100 0 0\n"   // 1 m right -> (0, -1, 0)
                                 "0 50 200\n"  // 2 m forward, 0.5 m up -> (2, 0, 0.5)
                                 "0 0 3276\n"  // the maximum-range code: a no-return
                                 "10.1 0 0\n"  // under 48 cm: dropped
                                 "\n");
  Result<Scan3D> scan = ReadCloudFile(path);
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->points.size(), 3u);
  EXPECT_TRUE(At(scan->points[0]).isApprox(Eigen::Vector3d(1, 0, 0), kPointTolM));
  EXPECT_TRUE(At(scan->points[1]).isApprox(Eigen::Vector3d(0, -1, 0), kPointTolM));
  EXPECT_TRUE(At(scan->points[2]).isApprox(Eigen::Vector3d(2, 0, 0.5), kPointTolM));
  EXPECT_NEAR(scan->points[2].range_m, std::sqrt(4.25), kPointTolM);
  EXPECT_EQ(scan->no_returns, 1u);
  EXPECT_TRUE(scan->has_odometry);
  EXPECT_FALSE(scan->has_truth);
  ASSERT_TRUE(scan->sensor_origin);
  EXPECT_EQ(*scan->sensor_origin, Eigen::Vector3d::Zero());
  Eigen::Isometry3d expected = Eigen::Isometry3d::Identity();
  expected.translation() = Eigen::Vector3d(2, -1, 0);
  expected.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(scan->T_world_base.isApprox(expected, 1e-12)) << scan->T_world_base.matrix();
  // The forward point lands 2 m right-of-start... in the world: (2, -2, 0).
  EXPECT_TRUE((scan->T_world_base * At(scan->points[0])).isApprox(Eigen::Vector3d(2, -2, 0), 1e-6));
}

TEST_F(CloudFile, ThreeDtkScanWithoutItsPoseNamesThePoseFileItLookedFor) {
  const std::string path = Write("scan003.3d", "0 0 100\n");
  Result<Scan3D> scan = ReadCloudFile(path);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find((dir_ / "scan003.pose").string()), std::string::npos)
      << scan.error().message;
}

TEST_F(CloudFile, ThreeDtkErrorsNameTheFileAndLine) {
  Write("scan004.pose", "0 0 0 0 0 0\n");
  const std::string path = Write("scan004.3d", "0 0 100\n0 0 nan\n");
  Result<Scan3D> scan = ReadCloudFile(path);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find(path + "' line 2"), std::string::npos)
      << scan.error().message;
  Write("scan005.pose", "0 0 0 0 0\n");  // five numbers: one short
  scan = ReadCloudFile(Write("scan005.3d", "0 0 100\n"));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("scan005.pose"), std::string::npos) << scan.error().message;
  Write("scan006.pose", "0 0 0 0 0 0\n");
  scan = ReadCloudFile(Write("scan006.3d", ""));
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("scan006.3d"), std::string::npos) << scan.error().message;
}

TEST(ThreeDtk, RealCorridorScansReadWithTheirCountsAndOdometry) {
  // Counts from the files themselves (awk over r = |p|): 48 cm < r <= 3275 cm kept, r > 3275 cm
  // the maximum-range code; each file has 81360 readings.
  Result<Scan3D> scan0 = ReadCloudFile((kCorridor / "scan000.3d").string());
  Result<Scan3D> scan1 = ReadCloudFile((kCorridor / "scan001.3d").string());
  ASSERT_TRUE(scan0) << scan0.error().message;
  ASSERT_TRUE(scan1) << scan1.error().message;
  EXPECT_EQ(scan0->points.size(), 77614u);
  EXPECT_EQ(scan0->no_returns, 1481u);
  EXPECT_EQ(scan1->points.size(), 77831u);
  EXPECT_EQ(scan1->no_returns, 1313u);
  EXPECT_TRUE(scan0->T_world_base.isApprox(Eigen::Isometry3d::Identity()));
  // scan001.pose: (-3.10605, -7.50803, 156.917) cm = 1.569 m forward, 3 cm left, 7.5 cm down;
  // SOURCES.md: the scans were taken ~1.6 m apart.
  const Eigen::Vector3d t = scan1->T_world_base.translation();
  EXPECT_NEAR(t.x(), 1.56917, 1e-6);
  EXPECT_NEAR(t.y(), 0.0310605, 1e-7);
  EXPECT_NEAR(t.z(), -0.0750803, 1e-7);
  // Its rotation (1.36, -0.85, -0.56 deg about 3DTK's x, y, z) is small: under 2 deg in all.
  EXPECT_LT(AngleDeg(scan1->T_world_base, Eigen::Isometry3d::Identity()), 2.0);
  // The axis change puts the scan where a 180 deg LMS looks: nothing behind the scanner (x >= 0;
  // 3DTK's z), returns out to 31.8 m ahead and down to 1.77 m below it (awk over the file:
  // x 0..31.8, z -1.77..7.96 m).
  Eigen::AlignedBox3d box;
  for (const ScanPoint& p : scan1->points) box.extend(At(p));
  EXPECT_GT(box.min().x(), -0.001);
  EXPECT_NEAR(box.max().x(), 31.80, 0.01);
  EXPECT_NEAR(box.min().z(), -1.768, 0.001);
}

TEST(ThreeDtk, Slam6dFramesOfScan001AreWithinSourcesFigureOfTheOdometry) {
  Result<Eigen::Isometry3d> frames =
      Read3dtkFrames((kCorridor / "scan001.frames.slam6d_2009").string());
  Result<Eigen::Isometry3d> odometry = Read3dtkPose((kCorridor / "scan001.pose").string());
  ASSERT_TRUE(frames) << frames.error().message;
  ASSERT_TRUE(odometry) << odometry.error().message;
  // SOURCES.md (measured independently): odometry vs slam6d for scan001 = 0.71 deg / 1.7 cm.
  EXPECT_NEAR(AngleDeg(*frames, *odometry), 0.71, 0.01);
  EXPECT_NEAR((frames->translation() - odometry->translation()).norm(), 0.017, 0.0005);
  Result<Eigen::Isometry3d> first =
      Read3dtkFrames((kCorridor / "scan000.frames.slam6d_2009").string());
  ASSERT_TRUE(first) << first.error().message;
  EXPECT_TRUE(first->isApprox(Eigen::Isometry3d::Identity()));
}

TEST_F(CloudFile, FramesThatAreNotRigidTransformsAreRefused) {
  const std::string path = Write("bad.frames", "2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 2\n");
  Result<Eigen::Isometry3d> frames = Read3dtkFrames(path);
  ASSERT_FALSE(frames);
  EXPECT_NE(frames.error().message.find(path + "' line 1"), std::string::npos)
      << frames.error().message;
  EXPECT_FALSE(Read3dtkFrames(Write("empty.frames", "")));
}

// --- PLY ----------------------------------------------------------------------------------------

// The points every PLY below holds; each coordinate exact in float.
const std::vector<Eigen::Vector3d> kPlyPoints = {
    {1.5, -2.25, 0.125}, {10, 20, -30}, {-4.75, 0.5, 1000}};

enum class Ply { kAscii, kLittle, kBig };

template <typename T>
void Put(std::string& out, T value, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big) std::reverse(b, b + sizeof(T));  // the test machine is little-endian (x86-64, arm64)
  out.append(b, sizeof(T));
}

// A PLY with faces before the vertices, an element after them, and properties before, between and
// after x (double), y (float), z (double), including a list inside the vertex element.
std::string MakePly(Ply format) {
  std::string s = "ply\nformat ";
  s += format == Ply::kAscii    ? "ascii"
       : format == Ply::kLittle ? "binary_little_endian"
                                : "binary_big_endian";
  s += " 1.0\ncomment written by cloud_file_test\n"
       "element face 2\nproperty list uchar int vertex_indices\n"
       "element vertex 3\nproperty uchar red\nproperty double x\nproperty float32 y\n"
       "property short confidence\nproperty float64 z\nproperty list uint8 float tags\n"
       "property float intensity\n"
       "element edge 1\nproperty int vertex1\nproperty int32 vertex2\nend_header\n";
  if (format == Ply::kAscii) {
    s += "3 0 1 2\n4 0 1 2 0\n";
    for (const Eigen::Vector3d& p : kPlyPoints) {
      s += "200 " + std::to_string(p.x()) + " " + std::to_string(p.y()) + " -7 " +
           std::to_string(p.z()) + " 2 0.5 0.25 0.75\n";
    }
    return s + "0 1\n";
  }
  const bool big = format == Ply::kBig;
  for (int n : {3, 4}) {
    Put<std::uint8_t>(s, n, big);
    for (int i = 0; i < n; ++i) Put<std::int32_t>(s, i % 3, big);
  }
  for (const Eigen::Vector3d& p : kPlyPoints) {
    Put<std::uint8_t>(s, 200, big);
    Put<double>(s, p.x(), big);
    Put<float>(s, static_cast<float>(p.y()), big);
    Put<std::int16_t>(s, -7, big);
    Put<double>(s, p.z(), big);
    Put<std::uint8_t>(s, 2, big);
    Put<float>(s, 0.5f, big);
    Put<float>(s, 0.25f, big);
    Put<float>(s, 0.75f, big);
  }
  Put<std::int32_t>(s, 0, big);
  Put<std::int32_t>(s, 1, big);
  return s;
}

TEST_F(CloudFile, PlyAsciiLittleAndBigEndianGiveTheSamePoints) {
  for (const auto& [format, name] :
       {std::pair{Ply::kAscii, "ascii.ply"}, std::pair{Ply::kLittle, "little.PLY"},
        std::pair{Ply::kBig, "big.ply"}}) {
    Result<Scan3D> scan = ReadCloudFile(Write(name, MakePly(format)));
    ASSERT_TRUE(scan) << name << ": " << scan.error().message;
    ASSERT_EQ(scan->points.size(), kPlyPoints.size()) << name;
    for (std::size_t i = 0; i < kPlyPoints.size(); ++i) {
      EXPECT_EQ(At(scan->points[i]), kPlyPoints[i]) << name << " point " << i;
    }
    EXPECT_FALSE(scan->sensor_origin) << name;  // a PLY does not say where its sensor was
    EXPECT_FALSE(scan->has_odometry || scan->has_truth) << name;
  }
}

TEST_F(CloudFile, PlyPointsAreWhatPclsPlyReaderReads) {
  // A peer reader on the same bytes: PCL's PLY parser, on the layout it handles (float x y z, then
  // faces). It misplaces fields when a list or a narrower property sits inside the vertex element
  // (it read y as x for MakePly's files), so MakePly's own layout is checked against hand values.
  for (const bool big : {false, true}) {
    std::string ply = std::string("ply\nformat ") +
                      (big ? "binary_big_endian" : "binary_little_endian") +
                      " 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n";
    for (const Eigen::Vector3d& p : kPlyPoints) {
      for (int axis = 0; axis < 3; ++axis) Put<float>(ply, static_cast<float>(p[axis]), big);
    }
    Put<std::uint8_t>(ply, 3, big);
    for (int i = 0; i < 3; ++i) Put<std::int32_t>(ply, i, big);
    const std::string path = Write(big ? "big.ply" : "little.ply", ply);
    pcl::PointCloud<pcl::PointXYZ> peer;
    ASSERT_EQ(pcl::io::loadPLYFile(path, peer), 0) << path;
    Result<Scan3D> ours = ReadPly(path);
    ASSERT_TRUE(ours) << ours.error().message;
    ASSERT_EQ(peer.size(), ours->points.size()) << path;
    for (std::size_t i = 0; i < peer.size(); ++i) {
      EXPECT_EQ(peer[i].getVector3fMap(), At(ours->points[i]).cast<float>()) << path << " " << i;
      EXPECT_EQ(At(ours->points[i]), kPlyPoints[i]) << path << " " << i;
    }
  }
}

TEST_F(CloudFile, PlySensorOriginCommentSetsTheOrigin) {
  std::string ply = MakePly(Ply::kLittle);
  ply.insert(ply.find("comment"), "obj_info sensor_origin 0.1 0 0.54\n");
  Result<Scan3D> scan = ReadPly(Write("origin.ply", ply));
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_TRUE(scan->sensor_origin);
  EXPECT_TRUE(scan->sensor_origin->isApprox(Eigen::Vector3d(0.1, 0, 0.54)));
  EXPECT_NEAR(scan->points[0].range_m, (kPlyPoints[0] - Eigen::Vector3d(0.1, 0, 0.54)).norm(),
              kPointTolM);
}

TEST_F(CloudFile, PlyWithoutVerticesTruncatedOrNanIsAnErrorNamingTheFile) {
  const std::string faces = Write("faces.ply",
                                  "ply\nformat ascii 1.0\nelement face 1\n"
                                  "property list uchar int vertex_indices\nend_header\n3 0 1 2\n");
  Result<Scan3D> scan = ReadCloudFile(faces);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find(faces), std::string::npos) << scan.error().message;
  EXPECT_NE(scan.error().message.find("vertex"), std::string::npos) << scan.error().message;

  const std::string binary = MakePly(Ply::kBig);
  const std::string cut = Write("cut.ply", binary.substr(0, binary.size() - 30));
  scan = ReadCloudFile(cut);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find(cut), std::string::npos) << scan.error().message;

  std::string ascii = MakePly(Ply::kAscii);
  ascii.replace(ascii.find(std::to_string(-2.25)), std::to_string(-2.25).size(), "nan");
  const std::string nan = Write("nan.ply", ascii);
  scan = ReadCloudFile(nan);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find(nan + "': line 20"), std::string::npos)
      << scan.error().message;

  const std::string empty = Write("empty.ply", "");
  scan = ReadCloudFile(empty);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find(empty), std::string::npos) << scan.error().message;
}

// --- XYZ ----------------------------------------------------------------------------------------

TEST_F(CloudFile, XyzTakesSpacesTabsCommasAndSkipsCommentsAndExtraColumns) {
  Result<Scan3D> scan = ReadCloudFile(Write("cloud.xyz",
                                            "# x y z intensity\n"
                                            "//X Y Z\n"
                                            "1.5 -2.25 0.125 17\n"
                                            "\n"
                                            "10\t20\t-30\r\n"
                                            "-4.75, 0.5, 1e3, a label\n"));
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->points.size(), kPlyPoints.size());
  for (std::size_t i = 0; i < kPlyPoints.size(); ++i) EXPECT_EQ(At(scan->points[i]), kPlyPoints[i]);
  EXPECT_FALSE(scan->sensor_origin);
  EXPECT_FLOAT_EQ(scan->points[1].range_m, static_cast<float>(kPlyPoints[1].norm()));
}

TEST_F(CloudFile, XyzWithTextWhereNumbersBelongNamesTheFileAndLine) {
  const std::string path = Write("cloud.txt", "1 2 3\n# comment\n4 five 6\n");
  Result<Scan3D> scan = ReadCloudFile(path);
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find(path + "' line 3"), std::string::npos)
      << scan.error().message;
  EXPECT_NE(scan.error().message.find("five"), std::string::npos) << scan.error().message;
}

TEST_F(CloudFile, XyzNonFiniteShortOrEmptyIsAnError) {
  for (const auto& [name, text, where] :
       {std::tuple{"nan.xyz", "1 2 3\n1 nan 3\n", "line 2"},
        std::tuple{"inf.xyz", "1 2 -inf\n", "line 1"},
        std::tuple{"short.xyz", "1 2 3\n4 5\n", "line 2"}, std::tuple{"empty.xyz", "", "no points"},
        std::tuple{"comments.xyz", "# only\n\n", "no points"}}) {
    const std::string path = Write(name, text);
    Result<Scan3D> scan = ReadCloudFile(path);
    ASSERT_FALSE(scan) << name;
    EXPECT_NE(scan.error().message.find(path), std::string::npos) << scan.error().message;
    EXPECT_NE(scan.error().message.find(where), std::string::npos) << scan.error().message;
  }
}

// --- PCD and dispatch ---------------------------------------------------------------------------

TEST_F(CloudFile, PcdRoundTripKeepsSensorOriginAndOdometryAndPclStillReadsIt) {
  Scan3D scan;
  for (const Eigen::Vector3d& p : kPlyPoints) {
    ScanPoint sp;
    sp.x = static_cast<float>(p.x());
    sp.y = static_cast<float>(p.y());
    sp.z = static_cast<float>(p.z());
    sp.range_m = 3.0f;
    scan.points.push_back(sp);
  }
  scan.sensor_origin = Eigen::Vector3d(0.1, -0.02, 0.54);
  scan.has_odometry = true;
  scan.T_world_base.translate(Eigen::Vector3d(1.5, 0.03, -0.07));
  scan.T_world_base.rotate(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()));
  const std::string path = (dir_ / "odometry.pcd").string();
  ASSERT_TRUE(WriteScanPcd(scan, path));
  Result<Scan3D> back = ReadCloudFile(path);
  ASSERT_TRUE(back) << back.error().message;
  ASSERT_TRUE(back->sensor_origin);
  EXPECT_EQ(*back->sensor_origin, *scan.sensor_origin);  // 17 digits: the double comes back
  EXPECT_TRUE(back->has_odometry);
  EXPECT_FALSE(back->has_truth);
  EXPECT_TRUE(back->T_world_base.isApprox(scan.T_world_base, 1e-6));
  ASSERT_EQ(back->points.size(), scan.points.size());
  EXPECT_EQ(back->points[2].range_m, 3.0f);  // the stored range, not recomputed
  // PCL 1.13's own reader skips our comment lines (they follow its first line).
  pcl::PointCloud<pcl::PointXYZ> cloud;
  ASSERT_EQ(pcl::io::loadPCDFile(path, cloud), 0);
  ASSERT_EQ(cloud.size(), scan.points.size());
  EXPECT_EQ(cloud[2].z, 1000.0f);
  EXPECT_NEAR(cloud.sensor_origin_.x(), 1.5, 1e-6);
  std::ifstream in(path);
  std::string first, second;
  std::getline(in, first);
  std::getline(in, second);
  EXPECT_EQ(second.rfind("# sensor_origin 0.10000000000000001 -0.02", 0), 0u) << second;
}

TEST_F(CloudFile, SimulatedScanWithoutOriginKeepsItsTruthFlag) {
  Scan3D scan;
  scan.points.resize(1);
  scan.has_truth = true;
  const std::string path = (dir_ / "truth.pcd").string();
  ASSERT_TRUE(WriteScanPcd(scan, path));  // identity truth: the comment, not the pose, says so
  Result<Scan3D> back = ReadScanPcd(path);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_TRUE(back->has_truth);
  EXPECT_FALSE(back->has_odometry);
  EXPECT_FALSE(back->sensor_origin);  // ours, written without one: still unknown, not (0,0,0)
}

TEST_F(CloudFile, ForeignPcdHasItsSensorAtThePointsFrameOrigin) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  cloud.push_back(pcl::PointXYZ(3.0f, 4.0f, 0.0f));
  cloud.push_back(pcl::PointXYZ(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
  cloud.sensor_origin_ = Eigen::Vector4f(5.0f, 6.0f, 0.0f, 0.0f);
  const std::string path = (dir_ / "foreign.pcd").string();
  ASSERT_EQ(pcl::io::savePCDFileBinary(path, cloud), 0);
  Result<Scan3D> scan = ReadCloudFile(path);
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->points.size(), 1u);
  EXPECT_EQ(scan->no_returns, 1u);  // PCL's NaN point: a missing return
  ASSERT_TRUE(scan->sensor_origin);
  EXPECT_EQ(*scan->sensor_origin, Eigen::Vector3d::Zero());
  EXPECT_FLOAT_EQ(scan->points[0].range_m, 5.0f);  // no range field: distance from the sensor
  EXPECT_TRUE(scan->T_world_base.translation().isApprox(Eigen::Vector3d(5, 6, 0)));
}

TEST_F(CloudFile, EmptyPcdAndUnknownExtensionsAreErrorsNamingTheFile) {
  for (const std::string& name : {"empty.pcd", "cloud.las", "noextension"}) {
    const std::string path = Write(name, "");
    Result<Scan3D> scan = ReadCloudFile(path);
    ASSERT_FALSE(scan) << name;
    EXPECT_NE(scan.error().message.find(path), std::string::npos) << scan.error().message;
  }
  Result<Scan3D> missing = ReadCloudFile((dir_ / "missing.ply").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("missing.ply"), std::string::npos);
}

TEST(CloudFile3dtk, SetSensorOriginRecomputesRanges) {
  Scan3D scan;
  scan.points.resize(1);
  scan.points[0].x = 3.0f;
  SetSensorOrigin(scan, Eigen::Vector3d(0, 4, 0));
  EXPECT_FLOAT_EQ(scan.points[0].range_m, 5.0f);
  ASSERT_TRUE(scan.sensor_origin);
}

}  // namespace
}  // namespace pitchlab::sensors
