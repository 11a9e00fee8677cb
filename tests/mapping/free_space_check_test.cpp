// FreeSpaceCheck (mapping/src): a pose is refuted by what either scan saw through, in a corridor
// of known geometry whose one end wall both scans see.

#include "free_space_check.hpp"

#include <gtest/gtest.h>

namespace pitchlab::mapping {
namespace {

constexpr double kBin_deg = 1.0;

// What a forward-looking scan from (x0, 0, 0.5) sees of a corridor along +x in its own frame (the
// sensor at (0, 0, 0.5)): the floor z = 0 and the side walls y = +-1 from 1.5 m ahead to the end
// wall at x = 10 (world), and the end wall itself (z in [0, 2]), every 5 cm.
PointCloud CorridorSeenFrom(float x0) {
  PointCloud out;
  for (float x = x0 + 1.5f; x < 10.0f; x += 0.05f) {
    for (float y = -1.0f; y <= 1.0f; y += 0.05f) out.emplace_back(x - x0, y, 0.0f);
    for (float z = 0.05f; z <= 2.0f; z += 0.05f) {
      out.emplace_back(x - x0, -1.0f, z);
      out.emplace_back(x - x0, 1.0f, z);
    }
  }
  for (float y = -1.0f; y <= 1.0f; y += 0.05f) {
    for (float z = 0.0f; z <= 2.0f; z += 0.05f) out.emplace_back(10.0f - x0, y, z);
  }
  return out;
}

Eigen::Isometry3d Along(double x) { return Eigen::Isometry3d(Eigen::Translation3d(x, 0.0, 0.0)); }

struct Corridor {
  // The target scanned at x = 0, the source at x = 2: the true T_target_source is Along(2).
  PointCloud target = CorridorSeenFrom(0.0f), source = CorridorSeenFrom(2.0f);
  Eigen::Vector3f sensor{0.0f, 0.0f, 0.5f};
  LazySeenSpace target_seen{target, sensor, kBin_deg, SeenMargins{}};
  LazySeenSpace source_seen{source, sensor, kBin_deg, SeenMargins{}};
};

TEST(FreeSpaceCheck, TheTruthIsNotRefuted) {
  Corridor c;
  FreeSpaceCheck check(&c.target_seen, c.source, &c.source_seen, c.target, Along(2.0));
  EXPECT_FALSE(check.Refutes(Along(2.0)));
  EXPECT_FALSE(check.Refutes(Along(2.02)));  // within the margins
}

TEST(FreeSpaceCheck, ThePoseShortOfTheTruthIsRefutedByTheTargetsView) {
  // The source 1 m short: its end wall stands 1 m in front of the target's.
  Corridor c;
  FreeSpaceCheck check(&c.target_seen, c.source, nullptr, c.target, Along(2.0));
  EXPECT_TRUE(check.Refutes(Along(1.0)));
}

TEST(FreeSpaceCheck, ThePoseBeyondTheTruthIsRefutedOnlyByTheSourcesView) {
  // The source 1 m too far towards the end: its end wall lies behind the target's, where the
  // target saw nothing, and every other point slides along the corridor. From the source's view
  // the target's end wall then stands 1 m in front of the source's.
  Corridor c;
  FreeSpaceCheck one_way(&c.target_seen, c.source, nullptr, c.target, Along(2.0));
  EXPECT_FALSE(one_way.Refutes(Along(3.0)));
  FreeSpaceCheck both_ways(&c.target_seen, c.source, &c.source_seen, c.target, Along(2.0));
  EXPECT_TRUE(both_ways.Refutes(Along(3.0)));
  FreeSpaceCheck source_view_only(nullptr, c.source, &c.source_seen, c.target, Along(2.0));
  EXPECT_TRUE(source_view_only.Refutes(Along(3.0)));
  EXPECT_FALSE(source_view_only.Refutes(Along(1.0)));  // the target's end wall is then behind
}

TEST(FreeSpaceCheck, ViolationsAlreadyAtThePoseRaiseTheBar) {
  // Judged around a pose that is itself 1 m beyond: the same violations there as at the probe
  // refute nothing (a probe must show kRefutedOverAt times as many).
  Corridor c;
  FreeSpaceCheck check(&c.target_seen, c.source, &c.source_seen, c.target, Along(3.0));
  EXPECT_FALSE(check.Refutes(Along(3.0)));
  EXPECT_FALSE(check.Refutes(Along(2.9)));
}

TEST(FreeSpaceCheck, NothingSeenRefutesNothing) {
  Corridor c;
  FreeSpaceCheck check(nullptr, c.source, nullptr, c.target, Along(2.0));
  EXPECT_FALSE(check.Refutes(Along(1.0)));
  EXPECT_FALSE(check.Refutes(Along(3.0)));
  const PointCloud none;
  FreeSpaceCheck empty(&c.target_seen, none, &c.source_seen, none, Along(2.0));
  EXPECT_FALSE(empty.Refutes(Along(1.0)));
}

// The points of `scan` on the plane x = x_end (the end wall), or off it.
PointCloud EndWall(const PointCloud& scan, float x_end, bool on) {
  PointCloud out;
  for (const Eigen::Vector3f& p : scan) {
    if ((std::abs(p.x() - x_end) < 1e-3f) == on) out.push_back(p);
  }
  return out;
}

TEST(FreeSpaceAt, TheTruthLeavesNothingWhereEitherScanSawThrough) {
  Corridor c;
  const RegistrationResult::FreeSpace at =
      FreeSpaceAt(&c.target_seen, c.source, &c.source_seen, c.target, Along(2.0));
  // Every point but those nearer than the mirror's offset or at the view's edge is judged.
  EXPECT_GT(at.source_judged, static_cast<int>(0.8 * c.source.size()));
  EXPECT_GT(at.target_judged, static_cast<int>(0.5 * c.target.size()));
  EXPECT_EQ(at.source_violating, 0.0);
  EXPECT_EQ(at.target_violating, 0.0);
  EXPECT_EQ(FreeSpaceRefutation(at, c.source.size(), c.target.size()), "");
}

TEST(FreeSpaceAt, APoseShortOfTheTruthPutsTheEndWallWhereTheTargetSawThrough) {
  // 1 m short, the source's floor and walls slide along the target's; its end wall (x = 8 in its
  // own frame) stands 1 m in front of the target's: those points, and only those, violate.
  Corridor c;
  const RegistrationResult::FreeSpace at =
      FreeSpaceAt(&c.target_seen, c.source, &c.source_seen, c.target, Along(1.0));
  // Only the end wall: off it the source violates nothing, and of the wall's points those whose
  // bins lie clear of the floor's and the side walls' returns (nearer than the margin) all do.
  const PointCloud wall = EndWall(c.source, 8.0f, true), rest = EndWall(c.source, 8.0f, false);
  const RegistrationResult::FreeSpace off_wall =
      FreeSpaceAt(&c.target_seen, rest, nullptr, c.target, Along(1.0));
  EXPECT_GT(off_wall.source_judged, static_cast<int>(0.8 * rest.size()));
  EXPECT_EQ(off_wall.source_violating, 0.0);
  const RegistrationResult::FreeSpace on_wall =
      FreeSpaceAt(&c.target_seen, wall, nullptr, c.target, Along(1.0));
  EXPECT_GT(on_wall.source_violating, 0.5);
  EXPECT_NEAR(at.source_violating * at.source_judged,
              on_wall.source_violating * on_wall.source_judged, 0.5);
  EXPECT_GT(at.source_violating, kChangedViewShare);
  const std::string why = FreeSpaceRefutation(at, c.source.size(), c.target.size());
  EXPECT_NE(why.find("of the source's points the target's scan could judge"), std::string::npos)
      << why;
  // Without the target's view nothing judges the source: the source's view alone sees the
  // target's end wall behind its own, where it saw nothing.
  const RegistrationResult::FreeSpace blind =
      FreeSpaceAt(nullptr, c.source, &c.source_seen, c.target, Along(1.0));
  EXPECT_EQ(blind.source_judged, 0);
  EXPECT_EQ(blind.target_violating, 0.0);
  EXPECT_EQ(FreeSpaceRefutation(blind, c.source.size(), c.target.size()), "");
}

TEST(FreeSpaceRefutation, NeedsMoreThanTheChangedShareAndMoreThanAFewPoints) {
  RegistrationResult::FreeSpace at;
  at.source_judged = 2000;
  at.source_violating = kChangedViewShare;  // a scene that changed this much is still accepted
  EXPECT_EQ(FreeSpaceRefutation(at, 3000, 50000), "");
  at.source_violating = 0.06;  // 120 points, 4 % of the source's 3000
  EXPECT_NE(FreeSpaceRefutation(at, 3000, 50000).find("6 % of the source's points"),
            std::string::npos)
      << FreeSpaceRefutation(at, 3000, 50000);
  // Half of 20 judged points: 10 points, a thin pole's worth, under kRefuted of 3000.
  at.source_judged = 20;
  at.source_violating = 0.5;
  EXPECT_EQ(FreeSpaceRefutation(at, 3000, 50000), "");
  // The target's view decides alike, against the target's size.
  at = {};
  at.target_judged = 40000;
  at.target_violating = 0.08;
  EXPECT_NE(FreeSpaceRefutation(at, 3000, 50000).find("8 % of the target's points"),
            std::string::npos);
}

}  // namespace
}  // namespace pitchlab::mapping
