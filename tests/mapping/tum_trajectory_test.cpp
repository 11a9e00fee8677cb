// The TUM trajectory writer and reader: known lines, a bit-exact round trip, refused input.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <gtest/gtest.h>

#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mapping/tum_trajectory.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mapping {
namespace {

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<StampedPose> RandomTrajectory(unsigned seed, int n) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> position(-50, 50), angle(-180, 180), step(0.01, 5);
  std::vector<StampedPose> out;
  double stamp_s = 1.7e9;  // a Unix time, as real logs carry: 10 digits before the point
  for (int i = 0; i < n; ++i) {
    stamp_s += step(rng);
    out.push_back({stamp_s, PoseFromXyzRpyDeg(position(rng), position(rng), position(rng),
                                              angle(rng), angle(rng) / 2, angle(rng))});
  }
  return out;
}

TEST(TumTrajectory, WritesOneLineOfEightNumbersPerPose) {
  const std::vector<StampedPose> poses{
      {0.5, Eigen::Isometry3d::Identity()},
      {2.0, PoseFromXyzRpyDeg(1, -2, 0.25, 0, 0, 180)}};  // half a turn: q = (0, 0, 1, 0)
  const auto text = FormatTumTrajectory(poses);
  ASSERT_TRUE(text) << text.error().message;
  EXPECT_EQ(*text,
            "# timestamp tx ty tz qx qy qz qw\n"
            "0.5 0 0 0 0 0 0 1\n"
            "2 1 -2 0.25 0 0 1 6.123233995736766e-17\n");
}

TEST(TumTrajectory, ReadsALineAsTimestampPositionAndScalarLastQuaternion) {
  const auto poses = ParseTumTrajectory(
      "# comment\n\n1.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n", "text");
  ASSERT_TRUE(poses) << poses.error().message;
  ASSERT_EQ(poses->size(), 1u);
  EXPECT_EQ(poses->front().stamp_s, 1.5);
  EXPECT_TRUE(poses->front().T_map_base.isApprox(PoseFromXyzRpyDeg(1, 2, 3, 0, 0, 90), 1e-15));
}

TEST(TumTrajectory, WriteThenReadGivesTheSamePoses) {
  const std::vector<StampedPose> poses = RandomTrajectory(7, 200);
  const test_support::ScopedTempDir dir("tum_trajectory");
  const std::string path = (dir / "round_trip.txt").string();
  ASSERT_TRUE(WriteTumTrajectory(path, poses));
  const auto read = ReadTumTrajectory(path);
  ASSERT_TRUE(read) << read.error().message;
  ASSERT_EQ(read->size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ((*read)[i].stamp_s, poses[i].stamp_s) << i;  // bit for bit
    EXPECT_EQ((*read)[i].T_map_base.translation(), poses[i].T_map_base.translation()) << i;
    // matrix -> quaternion -> matrix rounds in the last bits only.
    EXPECT_TRUE((*read)[i].T_map_base.linear().isApprox(poses[i].T_map_base.linear(), 1e-15)) << i;
  }
}

TEST(TumTrajectory, QuaternionsAreWrittenWithNonNegativeW) {
  const auto text = FormatTumTrajectory(RandomTrajectory(3, 100));
  ASSERT_TRUE(text);
  const auto poses = ParseTumTrajectory(*text, "text");
  ASSERT_TRUE(poses);
  std::istringstream in(*text);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double v[8];
    for (double& x : v) fields >> x;
    EXPECT_GE(v[7], 0.0) << line;
  }
}

void ExpectRefused(const std::string& text, const std::string& message_part) {
  const auto poses = ParseTumTrajectory(text, "traj.txt");
  ASSERT_FALSE(poses) << "accepted: " << text;
  EXPECT_NE(poses.error().message.find(message_part), std::string::npos) << poses.error().message;
}

TEST(TumTrajectory, BadLinesAreRefusedNamingTheLine) {
  const std::string good = "# t x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n";
  ExpectRefused(good + "2 0 0 0 0 0 1\n", "traj.txt:3: expected 8 numbers");
  ExpectRefused(good + "2 0 0 zero 0 0 0 1\n", "traj.txt:3: 'zero' is not a number");
  ExpectRefused(good + "2 0 0 nan 0 0 0 1\n", "traj.txt:3: 'nan' is not finite");
  ExpectRefused(good + "2 0 0 0 0 0 0 1.1\n", "traj.txt:3: quaternion norm");
  ExpectRefused(good + "1 0 0 0 0 0 0 1\n", "traj.txt:3: timestamp 1 is not after");
  ExpectRefused(good + "2 0 0 0 0 0 0 1 5\n", "found 9 fields");
}

TEST(TumTrajectory, ANearlyUnitQuaternionIsNormalised) {
  // Four decimals per component, as some tools print: norm 0.99999 for a 90 deg yaw.
  const auto poses = ParseTumTrajectory("0 0 0 0 0 0 0.7071 0.7071\n", "text");
  ASSERT_TRUE(poses) << poses.error().message;
  const Eigen::Matrix3d R = poses->front().T_map_base.linear();
  EXPECT_TRUE((R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-15));
  EXPECT_NEAR(R(1, 0), 1.0, 1e-15);  // x turned onto y
}

TEST(TumTrajectory, AFailedWriteLeavesTheFileAsItWas) {
  const test_support::ScopedTempDir dir("tum_trajectory");
  const std::string path = (dir / "kept.txt").string();
  ASSERT_TRUE(WriteTumTrajectory(path, RandomTrajectory(1, 5)));
  const std::string before = Slurp(path);
  std::vector<StampedPose> backwards = RandomTrajectory(2, 5);
  std::swap(backwards[1], backwards[3]);  // stamps no longer increase
  const auto result = WriteTumTrajectory(path, backwards);
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("is not after the previous"), std::string::npos);
  EXPECT_EQ(Slurp(path), before);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  std::vector<StampedPose> sheared = RandomTrajectory(2, 5);
  sheared[2].T_map_base.linear()(0, 1) += 0.1;
  EXPECT_FALSE(WriteTumTrajectory(path, sheared));
  EXPECT_EQ(Slurp(path), before);
}

TEST(TumTrajectory, UnreadableOrUnwritablePathsAreErrors) {
  const test_support::ScopedTempDir dir("tum_trajectory");
  EXPECT_FALSE(ReadTumTrajectory((dir / "does_not_exist.txt").string()));
  const auto directory = ReadTumTrajectory(dir.path().string());
  ASSERT_FALSE(directory);
  EXPECT_NE(directory.error().message.find("is a directory"), std::string::npos);
  EXPECT_FALSE(WriteTumTrajectory((dir / "no_such_dir/traj.txt").string(), RandomTrajectory(1, 2)));
}

}  // namespace
}  // namespace pitchlab::mapping
