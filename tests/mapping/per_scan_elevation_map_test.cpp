// PerScanElevationMap (issue 20, re-posed maps): a map whose scans were moved or taken out and put
// back is the map built from scratch with the scans where they are now, bit for bit, on any
// number of threads; one scan alone is ElevationMap::InsertScan's map; a scan's cell floating
// over another scan's ray is left out whatever the order.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "pitchlab/mapping/per_scan_elevation_map.hpp"
#include "pitchlab/mapping/registration.hpp"

namespace pitchlab::mapping {
namespace {

constexpr double kDeg = M_PI / 180;
const Eigen::Vector3f kSensorBase(0.0f, 0.0f, 0.54f);  // the P3's laser over base_link

// The scene: floor z = 0, a 0.4 m box at x in [3, 3.6], y in [-0.5, 0.5], a 2.5 m wall at x = 7.
// Distance along the ray from o in direction d to the first surface, or +inf.
double Cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  if (d.z() < 0) best = -o.z() / d.z();
  if (d.x() > 0) {
    const double t = (7.0 - o.x()) / d.x();
    if (t > 0 && t < best && (o + t * d).z() <= 2.5) best = t;
    const double tb = (3.0 - o.x()) / d.x();  // the box's front face
    const Eigen::Vector3d p = o + tb * d;
    if (tb > 0 && tb < best && std::abs(p.y()) <= 0.5 && p.z() <= 0.4) best = tb;
  }
  if (d.z() < 0) {  // the box's top
    const double tt = (0.4 - o.z()) / d.z();
    const Eigen::Vector3d p = o + tt * d;
    if (tt > 0 && tt < best && p.x() >= 3 && p.x() <= 3.6 && std::abs(p.y()) <= 0.5) best = tt;
  }
  return best;
}

// A coarse nodding scan (60 lines of 91 beams over 180 x 80 deg) from T_world_base, in base_link.
std::vector<Eigen::Vector3f> Scan(const Eigen::Isometry3d& T_world_base) {
  const Eigen::Vector3d o = T_world_base * kSensorBase.cast<double>();
  std::vector<Eigen::Vector3f> points;
  for (int line = 0; line < 60; ++line) {
    const double pitch = (-60.0 + 80.0 * line / 59) * kDeg;
    for (int beam = 0; beam < 91; ++beam) {
      const double a = (-90.0 + 2.0 * beam) * kDeg;
      const Eigen::Vector3d d_base(std::cos(pitch) * std::cos(a), std::cos(pitch) * std::sin(a),
                                   std::sin(pitch));
      const double t = Cast(o, T_world_base.linear() * d_base);
      if (t < 10.0) points.push_back((kSensorBase.cast<double>() + t * d_base).cast<float>());
    }
  }
  return points;
}

Eigen::Isometry3d Stop(int k) { return PoseFromXyzRpyDeg(0.7 * k, 0.2 * (k % 2), 0, 0, 0, 5 * k); }

GridGeometry Area() { return GridGeometry::FromArea(-3, -6, 12, 12, 0.1); }

// Every field of every cell equal (== on floats: +inf equals +inf, nothing here is NaN).
void ExpectSameCells(const ElevationMap& a, const ElevationMap& b) {
  ASSERT_EQ(a.cells().size(), b.cells().size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.cells().size(); ++k) {
    const CellStats& x = a.at(k);
    const CellStats& y = b.at(k);
    differing += !(x.count == y.count && x.mean_x == y.mean_x && x.mean_y == y.mean_y &&
                   x.mean_z == y.mean_z && x.c_xx == y.c_xx && x.c_xy == y.c_xy &&
                   x.c_xz == y.c_xz && x.c_yy == y.c_yy && x.c_yz == y.c_yz && x.c_zz == y.c_zz &&
                   x.min_z == y.min_z && x.max_z == y.max_z && x.clearance_z == y.clearance_z);
  }
  EXPECT_EQ(differing, 0u);
}

// Same known cells, heights within `rounding_m` (the per-scan grid's origin is whole cells away,
// so cell offsets round differently).
void ExpectSameCellsToRounding(const ElevationMap& a, const ElevationMap& b, float rounding_m) {
  ASSERT_EQ(a.cells().size(), b.cells().size());
  for (std::size_t k = 0; k < a.cells().size(); ++k) {
    const CellStats& x = a.at(k);
    const CellStats& y = b.at(k);
    ASSERT_EQ(x.count, y.count) << "cell " << k;
    if (!x.known()) continue;
    EXPECT_NEAR(x.mean_z, y.mean_z, rounding_m) << "cell " << k;
    EXPECT_NEAR(x.min_z, y.min_z, rounding_m) << "cell " << k;
    EXPECT_NEAR(x.max_z, y.max_z, rounding_m) << "cell " << k;
  }
}

std::size_t KnownCells(const ElevationMap& m) {
  std::size_t n = 0;
  for (const CellStats& c : m.cells()) n += c.known();
  return n;
}

// Scans taken at the true stops, inserted at poses off by up to 5 cm / 1 deg (drift), then
// re-posed to the truth after an optimisation.
TEST(PerScanElevationMap, ARePosedMapEqualsOneBuiltFromScratchAtTheNewPosesBitForBit) {
  std::vector<std::vector<Eigen::Vector3f>> scans;
  PerScanElevationMap drifted(Area());
  for (int k = 0; k < 5; ++k) {
    scans.push_back(Scan(Stop(k)));
    const Eigen::Isometry3d off =
        Stop(k) * PoseFromXyzRpyDeg(0.01 * k, -0.01 * k, 0, 0, 0, 0.2 * k);
    ASSERT_TRUE(drifted.Insert(k, scans[k], kSensorBase, off));
  }
  const ElevationMap before = drifted.map();
  // Scans 0 and 1 barely drifted and stay; 2, 3 and 4 move to the truth.
  Result<std::size_t> moved = drifted.Repose({{2, Stop(2)}, {3, Stop(3)}, {4, Stop(4)}});
  ASSERT_TRUE(moved) << moved.error().message;
  EXPECT_EQ(*moved, 3u);
  PerScanElevationMap scratch(Area());
  for (int k = 0; k < 5; ++k) {
    const Eigen::Isometry3d at = k < 2 ? drifted.pose(k) : Stop(k);
    ASSERT_TRUE(scratch.Insert(k, scans[k], kSensorBase, at));
  }
  ExpectSameCells(drifted.map(), scratch.map());
  // Not vacuous: the re-posing changed the map.
  std::size_t changed = 0;
  for (std::size_t k = 0; k < before.cells().size(); ++k) {
    changed += before.at(k).count != drifted.map().at(k).count;
  }
  EXPECT_GT(changed, 100u);
  // Poses that did not change re-insert nothing.
  EXPECT_EQ(*drifted.Repose({{2, Stop(2)}, {0, drifted.pose(0)}}), 0u);
}

// Repose re-inserts scans on several threads: the map is the same bits on one thread or four.
TEST(PerScanElevationMap, ARePoseOnFourThreadsEqualsOneOnOneThreadBitForBit) {
  PerScanElevationMap one(Area()), four(Area());
  one.set_threads(1);
  four.set_threads(4);
  std::vector<std::pair<std::size_t, Eigen::Isometry3d>> truth;
  for (int k = 0; k < 7; ++k) {
    const std::vector<Eigen::Vector3f> scan = Scan(Stop(k));
    const Eigen::Isometry3d off = Stop(k) * PoseFromXyzRpyDeg(0.02, -0.01 * k, 0, 0, 0, 0.3);
    ASSERT_TRUE(one.Insert(k, scan, kSensorBase, off));
    ASSERT_TRUE(four.Insert(k, scan, kSensorBase, off));
    truth.emplace_back(k, Stop(k));
  }
  EXPECT_EQ(*one.Repose(truth), 7u);
  EXPECT_EQ(*four.Repose(truth), 7u);
  ExpectSameCells(one.map(), four.map());
  EXPECT_GT(KnownCells(four.map()), 500u);
}

TEST(PerScanElevationMap, RemovingAScanThenInsertingItBackGivesTheSameMapBitForBit) {
  PerScanElevationMap map(Area());
  PerScanElevationMap without_two(Area());
  std::vector<std::vector<Eigen::Vector3f>> scans;
  for (int k = 0; k < 4; ++k) {
    scans.push_back(Scan(Stop(k)));
    ASSERT_TRUE(map.Insert(k, scans[k], kSensorBase, Stop(k)));
    if (k != 2) ASSERT_TRUE(without_two.Insert(k, scans[k], kSensorBase, Stop(k)));
  }
  const ElevationMap full = map.map();
  ASSERT_TRUE(map.Remove(2));
  ExpectSameCells(map.map(), without_two.map());
  ASSERT_TRUE(map.Insert(2, scans[2], kSensorBase, Stop(2)));
  ExpectSameCells(map.map(), full);
  EXPECT_EQ(map.scan_count(), 4u);
}

// The per-scan map inserts each scan over its own extent: cell positions relative to a grid
// origin a whole number of cells away, so floats round differently in the last bits.
TEST(PerScanElevationMap, OneScanGivesInsertScansMapToFloatRounding) {
  constexpr float kRoundingM = 1e-5f;  // ~100 float ulps at 10 m
  const Eigen::Isometry3d at = Stop(3);
  const std::vector<Eigen::Vector3f> scan = Scan(at);
  PerScanElevationMap per_scan(Area());
  ASSERT_TRUE(per_scan.Insert(0, scan, kSensorBase, at));
  ElevationMap plain(Area());
  std::vector<Eigen::Vector3f> in_map;
  for (const Eigen::Vector3f& p : scan) in_map.push_back(at.cast<float>() * p);
  (void)plain.InsertScan(in_map.data(), in_map.size(), at.cast<float>() * kSensorBase);
  ASSERT_GT(KnownCells(plain), 500u);
  ExpectSameCellsToRounding(plain, per_scan.map(), kRoundingM);
}

// The ground under the robot (inside the laser's blind zone, so no ray reaches it) goes in
// without a ray, after the scan: as InsertScan followed by InsertPoints on one map.
TEST(PerScanElevationMap, GroundPointsGoInAfterTheScanWithoutRays) {
  constexpr float kRoundingM = 1e-5f;  // as above
  const Eigen::Isometry3d at = Stop(2);
  const std::vector<Eigen::Vector3f> scan = Scan(at);
  std::vector<Eigen::Vector3f> ground;  // a 0.4 m square footprint at 0.1 m, on the floor
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) ground.emplace_back(0.1f * i, 0.1f * j, 0.0f);
  }
  PerScanElevationMap per_scan(Area());
  ASSERT_TRUE(per_scan.Insert(0, scan, kSensorBase, at, ground));
  ElevationMap plain(Area());
  std::vector<Eigen::Vector3f> in_map, ground_map;
  for (const Eigen::Vector3f& p : scan) in_map.push_back(at.cast<float>() * p);
  for (const Eigen::Vector3f& p : ground) ground_map.push_back(at.cast<float>() * p);
  (void)plain.InsertScan(in_map.data(), in_map.size(), at.cast<float>() * kSensorBase);
  ElevationMap scan_only = plain;
  (void)plain.InsertPoints(ground_map.data(), ground_map.size());
  ExpectSameCellsToRounding(plain, per_scan.map(), kRoundingM);
  // Not vacuous: the footprint's cells, unseen by the scan, are known now.
  EXPECT_GE(KnownCells(plain), KnownCells(scan_only) + 9u);
}

// Scan "under" stands at the origin and sees the floor out to 6 m; its rays to the far floor pass
// 0.1-0.3 m over the cells at x in [3, 4]. Scan "top" sees only a canopy's top over those cells,
// 2 m up (as from a ledge: no ray of its own passes under it). Whatever the order, the canopy is
// left out and the cells keep the floor.
TEST(PerScanElevationMap, AScansCellFloatingOverAnotherScansRayIsLeftOutWhateverTheOrder) {
  std::vector<Eigen::Vector3f> floor;
  for (float x = 0.55f; x < 6.0f; x += 0.1f) {
    for (float y = -0.45f; y < 0.5f; y += 0.1f) floor.emplace_back(x, y, 0.0f);
  }
  // The canopy's top, seen from a sensor 3 m up at x = 8 (points in that scan's base_link).
  const Eigen::Isometry3d T_map_top = PoseFromXyzRpyDeg(8, 0, 2.46, 0, 0, 0);
  std::vector<Eigen::Vector3f> canopy;
  for (float x = 3.05f; x < 4.0f; x += 0.1f) {
    for (float y = -0.45f; y < 0.5f; y += 0.1f) {
      canopy.push_back((T_map_top.inverse() * Eigen::Vector3d(x, y, 2.0)).cast<float>());
    }
  }
  for (const bool canopy_first : {true, false}) {
    PerScanElevationMap map(Area());
    const std::size_t under = canopy_first ? 1 : 0, top = canopy_first ? 0 : 1;
    ASSERT_TRUE(map.Insert(top, canopy, kSensorBase, T_map_top));
    ASSERT_TRUE(map.Insert(under, floor, kSensorBase, Eigen::Isometry3d::Identity()));
    const GridGeometry& g = map.map().geometry();
    for (int i = g.IndexOf(3.05, 0).i; i <= g.IndexOf(3.95, 0).i; ++i) {
      const CellStats& c = map.map().at({i, g.IndexOf(0, 0.05).j});
      ASSERT_TRUE(c.known());
      EXPECT_NEAR(c.max_z, 0.0f, 1e-6f) << "x cell " << i << ", canopy first: " << canopy_first;
    }
    EXPECT_EQ(map.overhang_cells(), canopy.size()) << "canopy first: " << canopy_first;
  }
  // Control: keeping every point (no headroom), the canopy does reach those cells.
  InsertConfig keep_all;
  keep_all.overhang_headroom_m = 0;
  PerScanElevationMap control(Area(), keep_all);
  ASSERT_TRUE(control.Insert(0, canopy, kSensorBase, T_map_top));
  ASSERT_TRUE(control.Insert(1, floor, kSensorBase, Eigen::Isometry3d::Identity()));
  const GridGeometry& g = control.map().geometry();
  EXPECT_NEAR(control.map().at(g.IndexOf(3.55, 0.05)).max_z, 2.0f, 1e-5f);
  EXPECT_EQ(control.overhang_cells(), 0u);
}

TEST(PerScanElevationMap, BadRequestsAreErrorsAndLeaveTheMapAsItWas) {
  PerScanElevationMap map(Area());
  ASSERT_TRUE(map.Insert(0, Scan(Stop(0)), kSensorBase, Stop(0)));
  const ElevationMap before = map.map();
  Result<void> twice = map.Insert(0, Scan(Stop(1)), kSensorBase, Stop(1));
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().message.find("already"), std::string::npos) << twice.error().message;
  Eigen::Isometry3d nan = Stop(1);
  nan.translation().x() = std::nan("");
  ASSERT_FALSE(map.Insert(1, Scan(Stop(1)), kSensorBase, nan));
  Eigen::Isometry3d scaled = Stop(1);
  scaled.linear() *= 1.1;
  Result<std::size_t> moved = map.Repose({{0, scaled}});
  ASSERT_FALSE(moved);
  EXPECT_NE(moved.error().message.find("rotation"), std::string::npos) << moved.error().message;
  EXPECT_FALSE(map.Repose({{7, Stop(1)}}));
  EXPECT_FALSE(map.Remove(7));
  ExpectSameCells(map.map(), before);
  EXPECT_EQ(map.scan_count(), 1u);
}

}  // namespace
}  // namespace pitchlab::mapping
