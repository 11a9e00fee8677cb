// Bridged gaps checked from close by (mission/src/line_gaps.hpp): the radius within which a
// nodding scan's lines lie closer than a cell, where they begin to meet the ground, and the
// bridged gaps a scan from there refutes.

#include "line_gaps.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/planning/planner.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kCell = 0.1;
constexpr int kSizeX = 40, kSizeY = 30;

sensors::Scan3D LinesEvery(double step_rad, int lines) {
  sensors::Scan3D scan;
  for (int i = 0; i < lines; ++i) {
    sensors::LaserLine line;
    line.pitch_rad = -0.3 + step_rad * i;
    scan.lines.push_back(line);
  }
  return scan;
}

TEST(LineGaps, WithinTheRadiusTheLinesMeetTheGroundLessThanACellApart) {
  const double h = 0.54, step = 0.45 * kDeg;
  const double r = DenseLinesRadius(LinesEvery(step, 200), h, kCell);
  EXPECT_NEAR(r, 2.566, 0.001);
  // Two lines about the one that meets the ground at r: their hits lie one cell apart.
  const double t = std::atan2(h, r);
  const double spacing = h / std::tan(t - 0.5 * step) - h / std::tan(t + 0.5 * step);
  EXPECT_NEAR(spacing, kCell, 1e-3);
  EXPECT_LT(h / std::tan(t - 0.5 * step + step / 4) - h / std::tan(t + 0.5 * step + step / 4),
            kCell);  // nearer: closer
  EXPECT_EQ(DenseLinesRadius(LinesEvery(step, 1), h, kCell), 0.0);
  EXPECT_EQ(DenseLinesRadius(LinesEvery(0.0, 50), h, kCell), 0.0);
}

// A level floor of 4 x 3 m, 4 points a cell 0.015 m either side of its centre, columns 20 and 21
// unseen, crossed by rays `ray_m` above the floor: a gap of two cells whose points lie 0.25 m
// apart (their spans reach sqrt(3) x 0.015 m from the centres), a line gap.
mapping::ElevationLayers FloorWithStripe(float ray_m) {
  mapping::ElevationMap map(mapping::GridGeometry{0, 0, kCell, kSizeX, kSizeY});
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < kSizeY; ++j)
    for (int i = 0; i < kSizeX; ++i)
      if (i != 20 && i != 21)
        for (const double dx : {-0.015, 0.015})
          for (const double dy : {-0.015, 0.015})
            pts.emplace_back((i + 0.5) * kCell + dx, (j + 0.5) * kCell + dy, 0.0f);
  (void)map.InsertPoints(pts.data(), pts.size());
  mapping::ElevationLayers L = mapping::ComputeLayers(map);
  for (int j = 0; j < kSizeY; ++j)
    for (int i = 20; i <= 21; ++i) L.clearance_z[L.geometry.Linear({i, j})] = ray_m;
  return L;
}

bool PathAcross(const planning::TraversabilityGrid& T) {
  return planning::PlanPath(T, {0.6, 1.5}, {3.4, 1.5}, planning::Algorithm::kAStar).has_value();
}

TEST(LineGaps, OnlyGapsAheadAndWithinTheRadiusAreRefuted) {
  const mapping::ElevationLayers L = FloorWithStripe(0.03f);
  const planning::TraversabilityGrid T =
      planning::BuildTraversability(L, planning::PlannerConfig{});
  const std::size_t k = T.geometry.Linear({20, 15});
  ASSERT_TRUE(T.line_gap[k]);
  ASSERT_TRUE(PathAcross(T));  // from afar the stripe is ground between lines

  std::vector<RefutedGap> refuted;
  const Eigen::Vector2d laser(1.5, 1.5);
  EXPECT_EQ(RefuteBridges(T, L, laser, M_PI, 0.0, 2.0, refuted), 0u);  // behind the laser
  EXPECT_EQ(RefuteBridges(T, L, laser, 0.0, 0.0, 0.4, refuted), 0u);   // nearest 0.5 m off
  // Facing it from 0.5-0.65 m, within a radius of 1 m: the cells within 1 m of the laser.
  const std::size_t marked = RefuteBridges(T, L, laser, 0.0, 0.0, 1.0, refuted);
  std::size_t expected = 0;
  for (int j = 0; j < kSizeY; ++j)
    for (int i = 20; i <= 21; ++i) expected += (T.geometry.CenterOf({i, j}) - laser).norm() <= 1.0;
  EXPECT_EQ(marked, expected);
  EXPECT_GT(marked, 20u);
  EXPECT_EQ(refuted[k], RefutedGap::kUnseen);                         // rays 3 cm above the floor
  EXPECT_EQ(refuted[T.geometry.Linear({20, 0})], RefutedGap::kNone);  // 1.5 m to the side
  EXPECT_EQ(RefuteBridges(T, L, laser, 0.0, 0.0, 1.0, refuted), 0u);      // each cell once
}

TEST(LineGaps, NothingNearerThanTheScanMeetsTheGroundIsRefuted) {
  const mapping::ElevationLayers L = FloorWithStripe(0.03f);
  const planning::TraversabilityGrid T =
      planning::BuildTraversability(L, planning::PlannerConfig{});
  // The stripe's cells lie 0.5-0.7 m ahead of the laser: a scan whose lines meet the ground from
  // 0.75 m on saw none of them, one from 0.6 m on the second column (centres 0.55 and 0.65 m).
  const Eigen::Vector2d laser(1.5, 1.5);
  std::vector<RefutedGap> refuted;
  EXPECT_EQ(RefuteBridges(T, L, laser, 0.0, 0.75, 2.0, refuted), 0u);
  EXPECT_EQ(RefuteBridges(T, L, laser, 0.0, 0.6, 2.0, refuted), std::size_t{kSizeY});
  EXPECT_EQ(refuted[T.geometry.Linear({20, 15})], RefutedGap::kNone);
  EXPECT_EQ(refuted[T.geometry.Linear({21, 15})], RefutedGap::kUnseen);
}

// A one-cell gap, narrower than the P3-AT's wheels span (0.21 m), is a bridge too, and a scan
// from close by that still shows it refutes it: its width was measured between points that may
// lie on a crack's walls, below its rims.
TEST(LineGaps, AGapTheWheelsSpanIsRefutedToo) {
  mapping::ElevationMap map(mapping::GridGeometry{0, 0, kCell, kSizeX, kSizeY});
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < kSizeY; ++j)
    for (int i = 0; i < kSizeX; ++i)
      if (i != 20)
        for (const double dx : {-0.015, 0.015})
          for (const double dy : {-0.015, 0.015})
            pts.emplace_back((i + 0.5) * kCell + dx, (j + 0.5) * kCell + dy, 0.0f);
  (void)map.InsertPoints(pts.data(), pts.size());
  mapping::ElevationLayers L = mapping::ComputeLayers(map);
  for (int j = 0; j < kSizeY; ++j) L.clearance_z[L.geometry.Linear({20, j})] = -0.02f;
  const planning::TraversabilityGrid T =
      planning::BuildTraversability(L, planning::PlannerConfig{});
  const std::size_t k = T.geometry.Linear({20, 15});
  ASSERT_TRUE(std::isfinite(T.z_m[k]));  // bridged
  ASSERT_FALSE(T.line_gap[k]);           // as a gap the wheels span
  std::vector<RefutedGap> refuted;
  // Column 20's centres lie 0.55 m ahead: 16 of them within 1 m (|dy| <= 0.75 m).
  EXPECT_EQ(RefuteBridges(T, L, {1.5, 1.5}, 0.0, 0.0, 1.0, refuted), 16u);
  EXPECT_EQ(refuted[k], RefutedGap::kDepression);  // the ray passed 2 cm below the floor
  MarkRefutedGaps(L, refuted);
  EXPECT_EQ(L.state[k], mapping::CellState::kDrop);
}

// Where the steepest line's forward beam meets level ground: the LMS200 on the P3's mount (pitch
// axis 0.45 m up and 0.1 m ahead, mirror 0.09 m above it) looking 40 deg down meets the ground
// at x = 0.1 + 0.09 sin 40 + (0.45 + 0.09 cos 40) / tan 40 in base_link; from the laser at pitch 0
// (x = 0.1) that is 0.09 sin 40 + (0.45 + 0.09 cos 40) / tan 40.
TEST(LineGaps, TheScanMeetsTheGroundWhereItsSteepestLineDoes) {
  const sensors::MountConfig mount;
  const double t = 40 * kDeg;
  sensors::Scan3D scan = LinesEvery(0.5 * kDeg, 3);  // -0.3 rad up to -0.2826 rad: all up
  EXPECT_TRUE(std::isinf(NearestGroundAhead(scan, mount)));
  scan.lines[1].pitch_rad = t;
  const double expected = 0.09 * std::sin(t) + (0.45 + 0.09 * std::cos(t)) / std::tan(t);
  EXPECT_NEAR(NearestGroundAhead(scan, mount), expected, 1e-9);
  EXPECT_TRUE(std::isinf(NearestGroundAhead(sensors::Scan3D{}, mount)));
}

TEST(LineGaps, ARefutedGapIsUnknownAboveTheGroundAndADropBelowIt) {
  const Eigen::Vector2d laser(1.5, 1.5);
  const planning::PlannerConfig config;
  for (const float ray_m : {0.03f, -0.02f}) {
    mapping::ElevationLayers L = FloorWithStripe(ray_m);
    const planning::TraversabilityGrid T = planning::BuildTraversability(L, config);
    std::vector<RefutedGap> refuted;
    EXPECT_EQ(RefuteBridges(T, L, laser, 0.0, 0.0, 2.0, refuted), 2u * kSizeY);  // the whole stripe
    refuted[T.geometry.Linear({5, 5})] = RefutedGap::kDepression;  // seen: keeps what it is
    MarkRefutedGaps(L, refuted);
    EXPECT_EQ(L.state[T.geometry.Linear({5, 5})], mapping::CellState::kObserved);
    const std::size_t k = T.geometry.Linear({20, 15});
    const planning::TraversabilityGrid after = planning::BuildTraversability(L, config);
    EXPECT_FALSE(PathAcross(after));  // unknown cells forbidden, drops a hazard
    if (ray_m > 0) {
      // Unseen: no longer a bridge, unknown for the planner's policy, which may cross it.
      EXPECT_EQ(L.state[k], mapping::CellState::kUnknown);
      EXPECT_EQ(after.blocked[k], planning::Blocked::kUnknown);
      planning::PlannerConfig penalise = config;
      penalise.unknown = planning::UnknownPolicy::kPenalise;
      EXPECT_TRUE(PathAcross(planning::BuildTraversability(L, penalise)));
    } else {
      // A ray 2 cm below the floor around it: the ground falls away, a drop the footprint keeps
      // off whatever the policy.
      EXPECT_EQ(L.state[k], mapping::CellState::kDrop);
      EXPECT_EQ(after.blocked[k], planning::Blocked::kDrop);
      planning::PlannerConfig penalise = config;
      penalise.unknown = planning::UnknownPolicy::kPenalise;
      EXPECT_FALSE(PathAcross(planning::BuildTraversability(L, penalise)));
    }
  }
}

}  // namespace
}  // namespace pitchlab::mission
