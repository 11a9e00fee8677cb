// Elevation map (Eq. 2, 3, inclination) on hand-built clouds with known answers.

#include <gtest/gtest.h>

#include <mujoco/mujoco.h>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/TransverseMercator.hpp>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>

#include "pitchlab/mapping/atomic_file.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/elevation_truth.hpp"
#include "pitchlab/sensors/ray_caster.hpp"
#include "file_size_limit.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mapping {
namespace {

constexpr double kHeightTolM = 1e-5;
constexpr double kAngleTolRad = 1e-4;

using test_support::ScopedTempDir;

// Points on a regular lattice of `step_m` over [x0, x1) x [y0, y1) at height f(x, y).
template <typename F>
std::vector<Eigen::Vector3f> Lattice(double x0, double x1, double y0, double y1, double step_m,
                                     F f) {
  std::vector<Eigen::Vector3f> pts;
  for (double y = y0 + step_m / 2; y < y1; y += step_m)
    for (double x = x0 + step_m / 2; x < x1; x += step_m)
      pts.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(f(x, y)));
  return pts;
}

TEST(ElevationMap, Eq2GridSizeIsAreaOverCellRounded) {
  const GridGeometry g = GridGeometry::FromArea(-5, -2.5, 10.04, 4.96, 0.1);
  EXPECT_EQ(g.size_x, 100);
  EXPECT_EQ(g.size_y, 50);
  EXPECT_EQ(g.IndexOf(-4.95, -2.45), (CellIndex{0, 0}));
  EXPECT_EQ(g.IndexOf(4.95, 2.45), (CellIndex{99, 49}));
  EXPECT_THROW(GridGeometry::FromArea(0, 0, 1, 1, 0.0), std::invalid_argument);
  EXPECT_LE(ElevationMap::kBytesPerCell, 64u);
}

TEST(ElevationMap, AMapMadeFromCellsHoldsThemAndChecksTheirCount) {
  const GridGeometry g{1.0, 2.0, 0.5, 3, 2};
  std::vector<CellStats> cells(6);
  cells[4].count = 7;
  cells[4].mean_z = 0.25f;
  const ElevationMap map(g, cells, GeodeticOrigin{46.77, 23.59, 360});
  EXPECT_EQ(map.at({1, 1}).count, 7u);
  EXPECT_EQ(map.at({1, 1}).mean_z, 0.25f);
  EXPECT_FALSE(map.at({0, 0}).known());
  ASSERT_TRUE(map.geodetic_origin());
  EXPECT_EQ(map.geodetic_origin()->height_m, 360);
  EXPECT_THROW(ElevationMap(g, std::vector<CellStats>(5), std::nullopt), std::invalid_argument);
  EXPECT_THROW(ElevationMap(GridGeometry{0, 0, 0.5, 0, 2}, {}, std::nullopt),
               std::invalid_argument);
}

TEST(ElevationMap, TiltedPlaneGivesItsInclination) {
  const double bx = 0.2, by = -0.1;
  const auto plane = [&](double x, double y) { return 1.0 + bx * x + by * y; };
  ElevationMap map(GridGeometry::FromArea(0, 0, 2, 2, 0.2));
  const auto pts = Lattice(0, 2, 0, 2, 0.02, plane);
  const InsertStats s = map.InsertPoints(pts.data(), pts.size());
  EXPECT_EQ(s.inserted, pts.size());
  const ElevationLayers L = ComputeLayers(map);
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i) {
      const std::size_t k = L.geometry.Linear({i, j});
      ASSERT_EQ(L.state[k], CellState::kObserved);
      EXPECT_NEAR(L.phi_x[k], std::atan(bx), kAngleTolRad) << i << "," << j;
      EXPECT_NEAR(L.phi_y[k], std::atan(by), kAngleTolRad) << i << "," << j;
      const Eigen::Vector2d c = L.geometry.CenterOf({i, j});
      EXPECT_NEAR(L.mean_z[k], plane(c.x(), c.y()), kHeightTolM);  // lattice symmetric in cell
    }
  EXPECT_NEAR(L.Tilt(0), std::atan(std::hypot(bx, by)), kAngleTolRad);
}

// A wide fit region (a robot's footprint) reads a plane as exactly, and a cell-sized bump on it
// much less: the bump tilts the 3 x 3 fits around it, hardly the 5 x 5 ones.
TEST(ElevationMap, AWiderInclinationRegionReadsThePlaneNotTheBump) {
  const double bx = 0.2;
  const auto ground = [&](double x, double y) {
    const bool bump = x > 1.0 && x < 1.1 && y > 1.0 && y < 1.1;
    return bx * x + (bump ? 0.05 : 0.0);
  };
  ElevationMap map(GridGeometry::FromArea(0, 0, 2, 2, 0.1));
  const auto pts = Lattice(0, 2, 0, 2, 0.01, ground);
  map.InsertPoints(pts.data(), pts.size());
  LayerConfig narrow, wide;
  wide.inclination_radius_cells = 2;
  const ElevationLayers a = ComputeLayers(map, narrow), b = ComputeLayers(map, wide);
  // Far from the bump both read the plane.
  const std::size_t far = a.geometry.Linear({4, 4});
  EXPECT_NEAR(a.phi_x[far], std::atan(bx), kAngleTolRad);
  EXPECT_NEAR(b.phi_x[far], std::atan(bx), kAngleTolRad);
  // Beside the bump (one cell west of it) the 3 x 3 fit tilts more than the 5 x 5 one.
  const std::size_t beside = a.geometry.Linear({9, 10});
  const double err_narrow = std::abs(a.Tilt(beside) - std::atan(bx));
  const double err_wide = std::abs(b.Tilt(beside) - std::atan(bx));
  EXPECT_GT(err_narrow, 0.02);
  EXPECT_LT(err_wide, 0.5 * err_narrow);
  LayerConfig bad;
  bad.inclination_radius_cells = 0;
  EXPECT_THROW(ComputeLayers(map, bad), std::invalid_argument);
}

TEST(ElevationMap, SingleScanLineStillGetsAnInclinationFromItsNeighbours) {
  // Each cell sees points on one line along x only: the pooled fit along y is degenerate per
  // cell, but the 3 x 3 region spans rows, so the inclination is still known.
  ElevationMap map(GridGeometry::FromArea(0, 0, 1, 1, 0.1));
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < 10; ++j)
    for (int s = 0; s < 20; ++s) {
      const float x = 0.0025f + s * 0.05f, y = 0.05f + j * 0.1f;
      pts.emplace_back(x, y, 0.3f * y);
    }
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = ComputeLayers(map);
  const std::size_t k = L.geometry.Linear({5, 5});
  EXPECT_NEAR(L.phi_x[k], 0.0, kAngleTolRad);
  EXPECT_NEAR(L.phi_y[k], std::atan(0.3), kAngleTolRad);
}

TEST(ElevationMap, BoxGivesItsHeightAndAStepEdge) {
  // Ground z = 0 over 4 x 4 m; a 1 x 1 m box of height 0.3 m at [1.5, 2.5]^2, sides sampled.
  const double h = 0.3;
  const auto inside = [](double x, double y) { return x > 1.5 && x < 2.5 && y > 1.5 && y < 2.5; };
  auto pts = Lattice(0, 4, 0, 4, 0.02, [&](double x, double y) { return inside(x, y) ? h : 0.0; });
  for (double z = 0.0; z <= h; z += 0.02)
    for (double t = 1.5; t < 2.5; t += 0.02) pts.emplace_back(1.5f, float(t), float(z));
  ElevationMap map(GridGeometry::FromArea(0, 0, 4, 4, 0.2));
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = ComputeLayers(map);
  const auto k = [&](double x, double y) { return L.geometry.Linear(L.geometry.IndexOf(x, y)); };
  EXPECT_NEAR(L.mean_z[k(2.0, 2.0)], h, kHeightTolM);
  EXPECT_NEAR(L.roughness[k(2.0, 2.0)], 0.0, kHeightTolM);
  EXPECT_NEAR(L.mean_z[k(0.5, 0.5)], 0.0, kHeightTolM);
  // The edge cell x in [1.4, 1.6) holds ground, the wall and the top: min 0, max 0.3.
  EXPECT_NEAR(L.min_z[k(1.5, 2.0)], 0.0, kHeightTolM);
  EXPECT_NEAR(L.max_z[k(1.5, 2.0)], h, kHeightTolM);
  EXPECT_GT(L.roughness[k(1.5, 2.0)], 0.1);
  // Neighbouring cells across the edge differ by the box height.
  EXPECT_NEAR(L.mean_z[k(1.7, 2.0)] - L.mean_z[k(1.3, 2.0)], h, kHeightTolM);
}

TEST(ElevationMap, AWallsFootInANeighbourDoesNotTiltTheFloorBesideIt) {
  // Flat floor z = 0 at 0.1 m cells; the cell [1.0, 1.1) x [1.0, 1.1) also holds a few points of a
  // wall's end (a door jamb) from 0.1 to 0.5 m: its mean stays within the 60 deg fit rule of
  // its diagonal neighbours' while its highest point stands 0.45 m over that mean.
  auto pts = Lattice(0, 3, 0, 3, 0.02, [](double, double) { return 0.0; });
  for (double z = 0.1; z <= 0.5 + 1e-9; z += 0.1) pts.emplace_back(1.09f, 1.05f, float(z));
  ElevationMap map(GridGeometry::FromArea(0, 0, 3, 3, 0.1));
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = ComputeLayers(map);
  const auto k = [&](double x, double y) { return L.geometry.Linear(L.geometry.IndexOf(x, y)); };
  ASSERT_GT(L.max_z[k(1.05, 1.05)] - L.mean_z[k(1.05, 1.05)], 0.4);
  ASSERT_LT(std::abs(L.mean_z[k(1.05, 1.05)] - L.mean_z[k(1.15, 1.15)]),
            LayerConfig{}.max_fit_slope * 0.1 * std::sqrt(2.0));
  // Every floor cell around it reads level (with the jamb's points pooled, 26-30 deg: too steep
  // for the P3-AT, and the doorway closed).
  for (double x : {0.95, 1.05, 1.15}) {
    for (double y : {0.95, 1.05, 1.15}) {
      if (x == 1.05 && y == 1.05) continue;
      EXPECT_NEAR(L.Tilt(k(x, y)), 0.0, kAngleTolRad) << "cell at " << x << ", " << y;
    }
  }
}

// The slope of a region is the ground's, not where the scanner put its points: a mound whose flank
// rises 35 deg from x = 1.0, the flat ground before it seen densely (2 cm lattice) and the flank
// sparsely (one point a cell, as from behind the mound). The cell at the foot reads what the same
// ground sampled evenly reads (one point a cell everywhere: 27.7 deg); pooled by point it read
// 19.0 deg, the dense flat side outweighing the flank.
TEST(ElevationMap, ARegionsSlopeCountsEachCellOnceHoweverDenselyItWasSeen) {
  const double grade = std::tan(35.0 * M_PI / 180.0);
  const auto ground = [&](double x, double) { return x < 1.0 ? 0.0 : grade * (x - 1.0); };
  auto dense = Lattice(0, 1.0, 0, 2, 0.02, ground);        // the flat side, ~25 points a cell
  const auto sparse = Lattice(1.0, 2, 0, 2, 0.1, ground);  // the flank, one a cell
  const auto even = Lattice(0, 2, 0, 2, 0.1, ground);      // every cell alike
  dense.insert(dense.end(), sparse.begin(), sparse.end());
  ElevationMap seen(GridGeometry::FromArea(0, 0, 2, 2, 0.1)), evenly(seen.geometry());
  (void)seen.InsertPoints(dense.data(), dense.size());
  (void)evenly.InsertPoints(even.data(), even.size());
  const ElevationLayers L = ComputeLayers(seen), E = ComputeLayers(evenly);
  const std::size_t foot = L.geometry.Linear(L.geometry.IndexOf(1.05, 1.05));
  ASSERT_GT(L.count[L.geometry.Linear(L.geometry.IndexOf(0.95, 1.05))], 20u);
  ASSERT_EQ(L.count[foot], 1u);
  EXPECT_GT(E.Tilt(foot), 16.0 * M_PI / 180.0);  // the evenly seen foot: too steep to drive
  EXPECT_NEAR(L.Tilt(foot), E.Tilt(foot), 1.0 * M_PI / 180.0)
      << L.Tilt(foot) * 180 / M_PI << " deg against " << E.Tilt(foot) * 180 / M_PI;
}

TEST(ElevationMap, PlaneResidualIsZeroOnATiltedPlaneAndAQuarterOfAStepInside) {
  const GridGeometry g = GridGeometry::FromArea(0, 0, 1, 1, 0.5);
  ElevationMap map(g);
  // Cell (0, 0): the plane z = 0.3 x - 0.2 y; cell (1, 0): a 0.2 m step across its middle.
  auto pts = Lattice(0, 0.5, 0, 0.5, 0.005, [](double x, double y) { return 0.3 * x - 0.2 * y; });
  const auto step =
      Lattice(0.5, 1, 0, 0.5, 0.005, [](double x, double) { return x < 0.75 ? 0 : 0.2; });
  pts.insert(pts.end(), step.begin(), step.end());
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = ComputeLayers(map);
  EXPECT_NEAR(L.plane_residual[g.Linear({0, 0})], 0.0, 1e-4);
  // A step h through the middle of uniformly sampled ground: residual variance h^2/4 (the
  // step's) minus 3 h^2/16 (what the best plane explains), so RMS h / 4.
  EXPECT_NEAR(L.plane_residual[g.Linear({1, 0})], 0.2 / 4, 1e-3);
  EXPECT_TRUE(std::isnan(L.plane_residual[g.Linear({0, 1})]));  // unknown
}

TEST(ElevationMap, RoughnessOfAKnownDistribution) {
  // Heights N(0.5, 0.04^2) in one cell; Eq. 3 T is their standard deviation.
  const double sigma_m = 0.04, tol_m = 0.0005;
  std::mt19937 rng(7);
  std::normal_distribution<float> z(0.5f, static_cast<float>(sigma_m));
  std::uniform_real_distribution<float> xy(0.0f, 0.5f);
  std::vector<Eigen::Vector3f> pts(200000);
  for (auto& p : pts) p = {xy(rng), xy(rng), z(rng)};
  ElevationMap map(GridGeometry::FromArea(0, 0, 0.5, 0.5, 0.5));
  (void)map.InsertPoints(pts.data(), pts.size());
  EXPECT_NEAR(Roughness(map.at({0, 0})), sigma_m, tol_m);
  EXPECT_NEAR(map.at({0, 0}).mean_z, 0.5, tol_m);
}

TEST(ElevationMap, PointSpanIsWhereTheCellsPointsLie) {
  ElevationMap map(GridGeometry::FromArea(0, 0, 0.3, 0.1, 0.1));
  // Cell 0: one point 0.03 m right of the centre and 0.01 m below it; cell 1: two points, 0.06 m
  // apart in x; cell 2: 101 points spread evenly over x (sqrt(3) sigma: the cell's half width).
  std::vector<Eigen::Vector3f> pts = {{0.08f, 0.04f, 0}, {0.12f, 0.05f, 0}, {0.18f, 0.05f, 0}};
  for (int k = 0; k <= 100; ++k) pts.emplace_back(0.2f + 0.001f * k, 0.05f, 0.0f);
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = ComputeLayers(map);
  ASSERT_EQ(L.point_span.size(), 3u);
  EXPECT_NEAR(L.point_span[0].lo_x, 0.03, 1e-6);
  EXPECT_NEAR(L.point_span[0].hi_x, 0.03, 1e-6);
  EXPECT_NEAR(L.point_span[0].lo_y, -0.01, 1e-6);
  EXPECT_NEAR(L.point_span[1].lo_x, -0.03, 1e-6);  // two points: exactly where they lie
  EXPECT_NEAR(L.point_span[1].hi_x, 0.03, 1e-6);
  EXPECT_NEAR(L.point_span[1].hi_y, 0.0, 1e-6);
  EXPECT_NEAR(L.point_span[2].lo_x, -0.05, 0.002);  // evenly spread: the cell's edges
  EXPECT_NEAR(L.point_span[2].hi_x, 0.05, 0.002);
}

TEST(ElevationMap, UnknownWhereNoPointFellAndOutsidePointsCounted) {
  ElevationMap map(GridGeometry::FromArea(0, 0, 1, 1, 0.5));
  const std::vector<Eigen::Vector3f> pts = {
      {0.1f, 0.1f, 1.0f}, {5.0f, 0.1f, 1.0f}, {0.1f, -0.1f, 1.0f}, {NAN, 0.1f, 1.0f}};
  const InsertStats s = map.InsertPoints(pts.data(), pts.size());
  EXPECT_EQ(s.inserted, 1u);
  EXPECT_EQ(s.outside, 2u);
  EXPECT_EQ(s.non_finite, 1u);
  const ElevationLayers L = ComputeLayers(map);
  EXPECT_EQ(L.state[0], CellState::kObserved);
  EXPECT_EQ(L.state[3], CellState::kUnknown);
  EXPECT_TRUE(std::isnan(L.mean_z[3]));
}

// A cell keeps its two lowest and two highest points whatever order they came in: the second
// ones are what a step inside the cell needs (two points beyond the limit, not one).
TEST(ElevationMap, SecondExtremesAreTheSecondLowestAndHighestPoints) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> u(0.01f, 0.09f), h(-0.2f, 0.2f);
  for (int n : {1, 2, 3, 17}) {
    ElevationMap map(GridGeometry::FromArea(0, 0, 0.1, 0.1, 0.1));
    std::vector<Eigen::Vector3f> pts;
    std::vector<float> z;
    for (int k = 0; k < n; ++k) {
      pts.emplace_back(u(rng), u(rng), h(rng));
      z.push_back(pts.back().z());
    }
    (void)map.InsertPoints(pts.data(), pts.size());
    std::sort(z.begin(), z.end());
    const CellStats& c = map.at(0);
    ASSERT_EQ(c.count, static_cast<std::uint32_t>(n));
    EXPECT_EQ(c.min_z, z.front());
    EXPECT_EQ(c.max_z, z.back());
    if (n == 1) {
      EXPECT_EQ(c.next_min_z, std::numeric_limits<float>::infinity());
      EXPECT_EQ(c.next_max_z, -std::numeric_limits<float>::infinity());
    } else {
      EXPECT_EQ(c.next_min_z, z[1]) << n << " points";
      EXPECT_EQ(c.next_max_z, z[z.size() - 2]) << n << " points";
    }
    const mapping::ElevationLayers L = ComputeLayers(map);
    EXPECT_EQ(L.next_min_z[0], c.next_min_z);
    EXPECT_EQ(L.next_max_z[0], c.next_max_z);
  }
}

TEST(ElevationMap, MergeEqualsInsertingBothClouds) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 2.0f), n(-0.05f, 0.05f);
  std::vector<Eigen::Vector3f> a(5000), b(7000);
  // x drawn first: the plane's height needs it (a braced initialiser cannot read its own x).
  for (auto& p : a) {
    const float x = u(rng);
    p = {x, u(rng), 0.1f * x + n(rng)};
  }
  for (auto& p : b) {
    const float x = u(rng) + 1.0f;
    p = {x, u(rng), 0.1f * x + n(rng)};
  }
  const GridGeometry ga = GridGeometry::FromArea(0, 0, 3, 2, 0.25);
  const GridGeometry gb = GridGeometry::FromArea(1, 0, 2, 2, 0.25);  // offset by 4 cells
  ElevationMap all(ga), ma(ga), mb(gb);
  (void)all.InsertPoints(a.data(), a.size());
  (void)all.InsertPoints(b.data(), b.size());
  (void)ma.InsertPoints(a.data(), a.size());
  (void)mb.InsertPoints(b.data(), b.size());
  const auto merged = ma.Merge(mb);
  ASSERT_TRUE(merged) << merged.error().message;
  EXPECT_EQ(*merged, 0u);
  for (std::size_t k = 0; k < ga.cell_count(); ++k) {
    const CellStats &x = all.at(k), &y = ma.at(k);
    ASSERT_EQ(x.count, y.count);
    EXPECT_NEAR(x.mean_z, y.mean_z, 1e-5);
    EXPECT_NEAR(Roughness(x), Roughness(y), 1e-4);
    EXPECT_EQ(x.min_z, y.min_z);
    EXPECT_EQ(x.max_z, y.max_z);
    EXPECT_EQ(x.next_min_z, y.next_min_z);
    EXPECT_EQ(x.next_max_z, y.next_max_z);
  }
  ElevationMap misaligned(GridGeometry::FromArea(0.1, 0, 1, 1, 0.25));
  EXPECT_FALSE(ma.Merge(misaligned));
}

TEST(ElevationMap, MergeOfUnknownCellsLeavesSeenGroundAsItWas) {
  // The map has seen x in [0, 2) at z = 0; a view shifted 0.3 m up covers x in [1, 3): only its
  // part over x in [2, 3) enters, and a cell the map has seen keeps its points and clearance.
  const GridGeometry g = GridGeometry::FromArea(0, 0, 3, 1, 0.25);
  std::vector<Eigen::Vector3f> seen, view;
  for (float x = 0.05f; x < 2.0f; x += 0.1f) {
    for (float y = 0.05f; y < 1.0f; y += 0.1f) seen.emplace_back(x, y, 0.0f);
  }
  for (float x = 1.05f; x < 3.0f; x += 0.1f) {
    for (float y = 0.05f; y < 1.0f; y += 0.1f) view.emplace_back(x, y, 0.3f);
  }
  ElevationMap map(g), shifted(g);
  (void)map.InsertPoints(seen.data(), seen.size());
  // Seen from above (from below, drop_undersides would leave the view's points out).
  (void)shifted.InsertScan(view.data(), view.size(), Eigen::Vector3f(1.0f, 0.5f, 0.8f));
  const ElevationMap before = map;
  const auto merged = map.Merge(shifted, ElevationMap::MergeCells::kUnknown);
  ASSERT_TRUE(merged) << merged.error().message;
  EXPECT_EQ(*merged, 0u);
  for (std::size_t k = 0; k < g.cell_count(); ++k) {
    const double x = g.CenterOf(g.FromLinear(k)).x();
    const CellStats &now = map.at(k), &was = before.at(k);
    if (x < 2.0) {
      EXPECT_EQ(now.count, was.count) << "x " << x;
      EXPECT_EQ(now.max_z, 0.0f) << "x " << x;
      EXPECT_EQ(now.clearance_z, was.clearance_z) << "x " << x;
    } else {
      EXPECT_EQ(now.count, shifted.at(k).count) << "x " << x;
      EXPECT_NEAR(now.mean_z, 0.3f, 1e-6) << "x " << x;
    }
  }
  // Merging everything blends the two heights where they overlap.
  ElevationMap blended = before;
  ASSERT_TRUE(blended.Merge(shifted));
  EXPECT_NEAR(blended.at(g.Linear(g.IndexOf(1.5, 0.5))).max_z, 0.3f, 1e-6);
}

TEST(ElevationMap, DitchShowsAsDropNotAsUnknown) {
  // Flat ground z = 0 except a ditch 1 m wide and 1 m deep at x in [4, 5). A laser at (0, 0, 0.55)
  // sees the near and the far ground, never into the ditch (its rays pass over it); a second one
  // standing in the ditch (at x = 4.05, 0.55 m up: z = -0.45) sees its far wall 0.45 m under the
  // rim. Its rays cross the ditch 0.45 m below the near rim's ground, beside it: a drop there,
  // flooded along the ditch under the same rim.
  const Eigen::Vector3f sensor(0.0f, 0.0f, 0.55f), in_ditch(4.05f, 0.0f, -0.45f);
  std::vector<Eigen::Vector3f> pts, across;
  for (int n = -20; n < 20; ++n) {  // 5 cm apart, by index: the rim stays in its cell
    const float y = 0.05f * n;
    for (int m = 10; m < 80; ++m) pts.emplace_back(0.05f * m, y, 0.0f);
    for (int m = 102; m < 160; ++m) pts.emplace_back(0.05f * m, y, 0.0f);
    across.emplace_back(5.0f, y, -0.45f);
  }
  ElevationMap map(GridGeometry::FromArea(0, -1, 8, 2, 0.1));
  const InsertStats s = map.InsertScan(pts.data(), pts.size(), sensor);
  EXPECT_GT(s.clearance_cells, 0u);
  (void)map.InsertScan(across.data(), across.size(), in_ditch);
  const ElevationLayers L = ComputeLayers(map);
  int drops = 0, unknown = 0;
  for (int i = 40; i < 50; ++i) {
    const std::size_t k = L.geometry.Linear({i, 10});
    drops += L.state[k] == CellState::kDrop;
    unknown += L.state[k] == CellState::kUnknown;
  }
  EXPECT_GE(drops, 8) << "ditch cells marked drop";
  EXPECT_EQ(L.state[L.geometry.Linear({20, 10})], CellState::kObserved);
  // Without rays the same ditch is merely unknown.
  ElevationMap no_rays(map.geometry());
  (void)no_rays.InsertPoints(pts.data(), pts.size());
  EXPECT_EQ(ComputeLayers(no_rays).state[L.geometry.Linear({45, 10})], CellState::kUnknown);
}

TEST(ElevationMap, ADropSeededBySomethingTallDoesNotFloodTheWholeShadow) {
  // Ground z = 0 up to x = 2.9, a wall 0.2 m thick seen only on its flat 0.8 m top in the cells
  // [2.9, 3.1) (a rim), then a shadow up to a far wall at x = 7.95, seen from beyond the wall
  // 0.55 m up and hit 0.5 m up: those rays cross the shadow at about 0.5 m, 0.3 m under the wall
  // top. The cell beside the wall is a drop by the rule (its only observed neighbour is the wall
  // top); the flood from it stops after drop_flood_m instead of running over the whole shadow,
  // which is flat ground the laser merely did not see.
  const Eigen::Vector3f sensor(0.0f, 0.0f, 0.55f), beyond(3.15f, 0.0f, 0.55f);
  std::vector<Eigen::Vector3f> pts, top, far;
  for (double y = -0.5; y < 0.5; y += 0.05) {
    for (double x = 0.52; x < 2.9; x += 0.05) pts.emplace_back(float(x), float(y), 0.0f);
    for (double x = 2.92; x < 3.1; x += 0.04) top.emplace_back(float(x), float(y), 0.8f);
    far.emplace_back(7.95f, float(y), 0.5f);
  }
  const GridGeometry g = GridGeometry::FromArea(0, -0.5, 8, 1, 0.1);
  ElevationMap map(g);
  (void)map.InsertScan(pts.data(), pts.size(), sensor);
  (void)map.InsertPoints(top.data(), top.size());  // seen from above (a laser 0.55 m up cannot)
  (void)map.InsertScan(far.data(), far.size(), beyond);
  const ElevationLayers L = ComputeLayers(map);
  const auto state = [&](double x) { return L.state[g.Linear(g.IndexOf(x, 0.05))]; };
  EXPECT_EQ(state(3.15), CellState::kDrop);
  EXPECT_EQ(state(4.35), CellState::kUnknown);  // beyond 1 m of the seed
  EXPECT_EQ(state(6.05), CellState::kUnknown);
  LayerConfig unbounded;
  unbounded.drop_flood_m = 100;
  EXPECT_EQ(ComputeLayers(map, unbounded).state[g.Linear(g.IndexOf(6.05, 0.05))],
            CellState::kDrop);  // what the flood did before it was bounded
}

TEST(ElevationMap, FloorUnderADeskTopIsNoDrop) {
  // Floor z = 0 out to x = 3 and beyond x = 4.5, a desk top at 0.75 m over x in [3, 4.5) seen from
  // (0, 0, 0.55), and rays under it to a wall at x = 6 hit 0.3 m up: under the top they pass at
  // 0.33-0.45 m, more than drop_depth below the top. The floor between the desk's legs is unseen,
  // not a drop: the top's own cells had rays pass under them, so the top is no ground reference.
  const Eigen::Vector3f sensor(0.0f, 0.0f, 0.55f);
  std::vector<Eigen::Vector3f> pts;
  for (double y = -0.5; y < 0.5; y += 0.05) {
    for (double x = 0.52; x < 3.0; x += 0.05) pts.emplace_back(float(x), float(y), 0.0f);
    for (double x = 3.05; x < 4.5; x += 0.1) pts.emplace_back(float(x), float(y), 0.75f);
    pts.emplace_back(6.0f, float(y), 0.3f);
  }
  const GridGeometry g = GridGeometry::FromArea(0, -0.5, 7, 1, 0.1);
  ElevationMap map(g);
  (void)map.InsertScan(pts.data(), pts.size(), sensor);
  const ElevationLayers L = ComputeLayers(map);
  int drops = 0;
  for (std::size_t k = 0; k < g.cell_count(); ++k) drops += L.state[k] == CellState::kDrop;
  EXPECT_EQ(drops, 0);
  // The cells beyond the desk's far edge: unknown, crossed by rays, beside the top only.
  EXPECT_EQ(L.state[g.Linear(g.IndexOf(4.55, 0.05))], CellState::kUnknown);
  EXPECT_TRUE(std::isfinite(L.clearance_z[g.Linear(g.IndexOf(4.55, 0.05))]));
}

TEST(ElevationMap, SignOverOpenGroundIsLeftOutOfTheGroundCells) {
  // Flat ground z = 0 seen from (0, 0, 0.55) out to x = 6, and a sign plate at z = 2.5 over
  // x in [3, 3.5): the rays to the ground behind it pass under it (at < 0.55 m), so the plate's
  // points float more than the 0.6 m headroom over a ray of their cell.
  const Eigen::Vector3f sensor(0.0f, 0.0f, 0.55f);
  std::vector<Eigen::Vector3f> pts;
  for (double y = -0.5; y < 0.5; y += 0.05) {
    for (double x = 0.52; x < 6.0; x += 0.05) pts.emplace_back(float(x), float(y), 0.0f);
    for (double x = 3.02; x < 3.5; x += 0.05) pts.emplace_back(float(x), float(y), 2.5f);
  }
  const GridGeometry g = GridGeometry::FromArea(0, -0.5, 6, 1, 0.1);
  ElevationMap map(g);
  const InsertStats s = map.InsertScan(pts.data(), pts.size(), sensor);
  // Every plate point, 10 along x, 20 along y: seen from below (drop_undersides) or, with that
  // rule off, over a lower ray.
  EXPECT_EQ(s.underside, 10u * 20u);
  InsertConfig rays_only;
  rays_only.drop_undersides = false;
  ElevationMap by_rays(g);
  EXPECT_EQ(by_rays.InsertScan(pts.data(), pts.size(), sensor, rays_only).overhang, 10u * 20u);
  const ElevationLayers L = ComputeLayers(map);
  const std::size_t under = g.Linear(g.IndexOf(3.25, 0.05));
  EXPECT_NEAR(L.mean_z[under], 0.0, kHeightTolM);
  EXPECT_NEAR(L.max_z[under], 0.0, kHeightTolM);
  // With the filter off the plate is averaged into the ground, as Eq. 2 alone would do.
  InsertConfig keep_all;
  keep_all.overhang_headroom_m = 0;
  keep_all.drop_undersides = false;
  ElevationMap raw(g);
  EXPECT_EQ(raw.InsertScan(pts.data(), pts.size(), sensor, keep_all).overhang, 0u);
  EXPECT_GT(ComputeLayers(raw).mean_z[under], 1.0);
}

TEST(ElevationMap, WallPointsOverTheCellEdgeAboveLowerRaysAreLeftOut) {
  // A wall face at x = 3 (a cell edge) from z = 0 to 3 m seen from (0, 0, 0.55); range noise
  // puts part of its points 5 mm short, into the ground cell [2.9, 3.0). The rays that hit the
  // wall low cross that cell under the high wall points, which go; the low ones stay (a step).
  const Eigen::Vector3f sensor(0.0f, 0.0f, 0.55f);
  std::vector<Eigen::Vector3f> pts;
  for (double y = -0.5; y < 0.5; y += 0.05) {
    for (double x = 0.52; x < 3.0; x += 0.05) pts.emplace_back(float(x), float(y), 0.0f);
    int n = 0;
    for (double z = 0.01; z < 3.0; z += 0.02, ++n)
      pts.emplace_back(n % 2 ? 2.995f : 3.005f, float(y), float(z));
  }
  const GridGeometry g = GridGeometry::FromArea(0, -0.5, 4, 1, 0.1);
  ElevationMap map(g);
  (void)map.InsertScan(pts.data(), pts.size(), sensor);
  const ElevationLayers L = ComputeLayers(map);
  const std::size_t front = g.Linear(g.IndexOf(2.95, 0.05));
  // The lowest ray through the cell runs from the laser to the wall at z = 0.01: at x = 3.0 it
  // is that low, so nothing above 0.6 m (plus the ray's rise across the cell) is kept.
  EXPECT_LT(L.max_z[front], 0.65);
  EXPECT_GT(L.max_z[front] - L.mean_z[front], 0.089) << "the wall's foot is still a step";
  EXPECT_LT(L.mean_z[front], 0.3);  // the ground and the wall's foot; 1.4 m with every point
}

TEST(ElevationMapIo, SaveLoadIsLosslessAndInsertionContinues) {
  const ScopedTempDir dir("elev_io");
  ElevationMap map(GridGeometry::FromArea(-1, -1, 2, 2, 0.1), GeodeticOrigin{39.5, -104.3, 1500});
  auto pts = Lattice(-1, 1, -1, 0, 0.03, [](double x, double y) { return 0.1 * x * y; });
  (void)map.InsertScan(pts.data(), pts.size(), Eigen::Vector3f(0, 0, 0.5f));
  const std::string path = (dir / "m.plem").string();
  ASSERT_TRUE(SaveElevationMap(map, path));
  auto loaded = LoadElevationMap(path);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_TRUE(loaded->geometry().SameAs(map.geometry()));
  ASSERT_TRUE(loaded->geodetic_origin());
  EXPECT_EQ(loaded->geodetic_origin()->latitude_deg, 39.5);
  auto more = Lattice(-1, 1, 0, 1, 0.03, [](double x, double) { return x; });
  (void)map.InsertPoints(more.data(), more.size());
  (void)loaded->InsertPoints(more.data(), more.size());
  ASSERT_TRUE(SaveElevationMap(*loaded, (dir / "b.plem").string()));
  ASSERT_TRUE(SaveElevationMap(map, (dir / "a.plem").string()));
  std::ifstream fa(dir / "a.plem", std::ios::binary), fb(dir / "b.plem", std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {}),
      sb((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_EQ(sa, sb);
  // Corruption is detected.
  std::string bad = sa;
  bad[200] ^= 1;
  std::ofstream(dir / "bad.plem", std::ios::binary) << bad;
  EXPECT_FALSE(LoadElevationMap((dir / "bad.plem").string()));
  EXPECT_FALSE(LoadElevationMap((dir / "missing.plem").string()));
}

// The .plem file format's FNV-1a 64 hash (elevation_io.hpp), for files written by hand here.
std::uint64_t Fnv1a(const std::string& bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
  return h;
}

// A map that saw a corner patch, a patch in the middle (with the cells its rays crossed) and the
// last cell: the file holds the header, 8 bytes per run of unseen or seen cells, the seen cells'
// records and the hash, nothing for the cells nothing reached, and loads cell for cell as saved.
// The dense files of earlier versions (PLELEV01: every record) load as the same map; runs that
// do not fit the grid are refused.
TEST(ElevationMapIo, StoresOnlyTheSeenCellsAndReadsEarlierDenseFiles) {
  const ScopedTempDir dir("elev_io");
  const GridGeometry g = GridGeometry::FromArea(0, 0, 20, 15, 0.1);  // 200 x 150 cells
  ElevationMap map(g, GeodeticOrigin{46.77, 23.59, 360});
  auto corner = Lattice(0, 0.5, 0, 0.3, 0.03, [](double x, double) { return 0.1 * x; });
  (void)map.InsertPoints(corner.data(), corner.size());
  auto middle = Lattice(9, 11, 7, 8, 0.03, [](double, double y) { return 0.05 * y; });
  (void)map.InsertScan(middle.data(), middle.size(), Eigen::Vector3f(6, 7.5, 0.6f));
  const Eigen::Vector3f last(19.97f, 14.97f, 0.2f);
  (void)map.InsertPoints(&last, 1);
  // A pair (unseen, seen) per run of seen cells, one more for unseen cells at the end.
  std::size_t seen = 0, pairs = 0, ray_only = 0;
  bool was_seen = false;
  for (const CellStats& c : map.cells()) {
    const bool s = c.count > 0 || std::isfinite(c.clearance_z);
    seen += s;
    ray_only += c.count == 0 && std::isfinite(c.clearance_z);
    pairs += s && !was_seen;
    was_seen = s;
  }
  pairs += !was_seen;
  ASSERT_TRUE(was_seen) << "the last cell is seen";
  ASSERT_GT(ray_only, 0u) << "the middle patch's rays crossed no cell before it";
  ASSERT_LT(seen, g.cell_count() / 20);
  const std::string path = (dir / "sparse.plem").string();
  ASSERT_TRUE(SaveElevationMap(map, path));
  EXPECT_EQ(std::filesystem::file_size(path), 72 + 8 * pairs + 60 * seen + 8);
  const auto loaded = LoadElevationMap(path);
  ASSERT_TRUE(loaded) << loaded.error().message;
  ASSERT_EQ(loaded->cells().size(), map.cells().size());
  EXPECT_EQ(std::memcmp(loaded->cells().data(), map.cells().data(),
                        map.cells().size() * sizeof(CellStats)),
            0);

  std::ifstream in(path, std::ios::binary);
  const std::string sparse((std::istreambuf_iterator<char>(in)), {});
  // Earlier versions' files, of 52-byte records without the second extremes: every record in
  // order (PLELEV01) or runs (PLELEV02). They load cell for cell, each cell's extremes standing
  // for its second ones, so their steps read as they did.
  std::string header = sparse.substr(8, 64);  // the same header, but for the record size
  const std::uint32_t record52 = 52;
  std::memcpy(header.data() + 60, &record52, 4);
  const auto old_record = [](const CellStats& c) {
    return std::string(reinterpret_cast<const char*>(&c), 52);
  };
  std::string dense = "PLELEV01" + header;
  for (const CellStats& c : map.cells()) dense += old_record(c);
  std::string runs = "PLELEV02" + header;
  const auto unseen = [&](std::size_t k) {
    return map.at(k).count == 0 && !std::isfinite(map.at(k).clearance_z);
  };
  for (std::size_t k = 0; k < map.cells().size();) {
    std::uint32_t n_unseen = 0, n_seen = 0;
    while (k < map.cells().size() && unseen(k)) ++k, ++n_unseen;
    std::string records;
    while (k < map.cells().size() && !unseen(k)) records += old_record(map.at(k++)), ++n_seen;
    runs.append(reinterpret_cast<const char*>(&n_unseen), 4);
    runs.append(reinterpret_cast<const char*>(&n_seen), 4);
    runs += records;
  }
  for (auto [name, bytes] : {std::pair{"dense.plem", dense}, {"runs.plem", runs}}) {
    const std::uint64_t hash = Fnv1a(bytes);
    bytes.append(reinterpret_cast<const char*>(&hash), 8);
    std::ofstream(dir / name, std::ios::binary) << bytes;
    const auto old = LoadElevationMap((dir / name).string());
    ASSERT_TRUE(old) << name << ": " << old.error().message;
    EXPECT_TRUE(old->geometry().SameAs(g));
    int differ = 0;
    for (std::size_t k = 0; k < map.cells().size(); ++k) {
      const CellStats &a = old->at(k), &b = map.at(k);
      differ += std::memcmp(&a, &b, 52) != 0;
      if (b.known()) {
        differ += a.next_min_z != b.min_z || a.next_max_z != b.max_z;
      } else {
        differ += std::memcmp(&a, &b, sizeof(CellStats)) != 0;
      }
    }
    EXPECT_EQ(differ, 0) << name;
  }

  std::string overrun = sparse.substr(0, sparse.size() - 8);
  const std::uint32_t too_many = static_cast<std::uint32_t>(g.cell_count());  // + the seen ones
  std::memcpy(overrun.data() + 72, &too_many, 4);
  const std::uint64_t overrun_hash = Fnv1a(overrun);
  overrun.append(reinterpret_cast<const char*>(&overrun_hash), 8);
  std::ofstream(dir / "overrun.plem", std::ios::binary) << overrun;
  const auto refused = LoadElevationMap((dir / "overrun.plem").string());
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("does not fit the grid of 30000"), std::string::npos)
      << refused.error().message;
}

TEST(ElevationMapIo, EsriGridHasHeaderRowsNorthFirstAndPrj) {
  const ScopedTempDir dir("elev_asc");
  ElevationMap map(GridGeometry::FromArea(10, 20, 0.3, 0.2, 0.1));
  const std::vector<Eigen::Vector3f> pts = {{10.05f, 20.15f, 1.5f}, {10.25f, 20.05f, -2.0f}};
  (void)map.InsertPoints(pts.data(), pts.size());
  const std::string asc = (dir / "m.asc").string();
  ASSERT_TRUE(WriteEsriAsciiGrid(ComputeLayers(map), std::nullopt, asc));
  std::ifstream in(asc);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("ncols 3\nnrows 2\nxllcorner 10.000000\nyllcorner 20.000000\n"),
            std::string::npos);
  EXPECT_NE(text.find("1.5000 -9999 -9999\n-9999 -9999 -2.0000\n"), std::string::npos) << text;
  EXPECT_TRUE(std::filesystem::exists(dir / "m.prj"));
}

TEST(ElevationMapIo, PrjTransverseMercatorMatchesTheLocalEnuFrame) {
  // The .prj's TM centred on the origin must put map (x, y) where LocalCartesian ENU does.
  const GeodeticOrigin o{39.571, -104.304, 1500};
  EXPECT_NE(ProjectionWkt(o).find("Transverse_Mercator"), std::string::npos);
  const GeographicLib::LocalCartesian enu(o.latitude_deg, o.longitude_deg, 0);
  const GeographicLib::TransverseMercator tm(GeographicLib::Constants::WGS84_a(),
                                             GeographicLib::Constants::WGS84_f(), 1.0);
  double x0, y0, x, y, lat, lon, h;
  tm.Forward(o.longitude_deg, o.latitude_deg, o.longitude_deg, x0, y0);
  for (const auto& p : {Eigen::Vector2d(100, 0), Eigen::Vector2d(-70, 250)}) {
    enu.Reverse(p.x(), p.y(), 0, lat, lon, h);
    tm.Forward(o.longitude_deg, lat, lon, x, y);
    EXPECT_NEAR(x - x0, p.x(), 0.002);
    EXPECT_NEAR(y - y0, p.y(), 0.002);
  }
}

TEST(ElevationMapIo, PngShowsUnknownAndDropsDistinctly) {
  const ScopedTempDir dir("elev_png");
  ElevationMap map(GridGeometry::FromArea(0, 0, 1, 1, 0.1));
  auto pts = Lattice(0, 0.5, 0, 1, 0.02, [](double x, double) { return x; });
  (void)map.InsertPoints(pts.data(), pts.size());
  ImageOptions options;
  options.pixels_per_cell = 2;
  const RgbImage img = RenderElevationImage(ComputeLayers(map), options);
  EXPECT_EQ(img.width, 20);
  EXPECT_EQ(img.height, 20);
  const auto px = [&](int x, int y) {
    const std::uint8_t* p = &img.rgb[(y * img.width + x) * 3];
    return std::array<int, 3>{p[0], p[1], p[2]};
  };
  const auto unknown = px(19, 19);
  EXPECT_EQ(unknown[0], unknown[1]);  // grey
  EXPECT_NE(px(0, 0), unknown);
  const std::string path = (dir / "m.png").string();
  ASSERT_TRUE(WritePng(img, path));
  std::ifstream in(path, std::ios::binary);
  char sig[8];
  in.read(sig, 8);
  EXPECT_EQ(std::string(sig + 1, 3), "PNG");
}

// A full disk, as a file-size limit makes it (file_size_limit.hpp): each writer says why, names
// the file and leaves nothing behind.
TEST(ElevationMapIo, AFullDiskIsAnErrorWithItsReasonAndLeavesNothing) {
  const ScopedTempDir dir("elev_full");
  RgbImage img;
  img.width = img.height = 256;
  img.rgb.resize(256 * 256 * 3);
  std::mt19937 rng(1);  // noise: deflate cannot shrink it under the limit
  for (std::uint8_t& b : img.rgb) b = static_cast<std::uint8_t>(rng());
  const std::string png = (dir / "m.png").string(), bytes = (dir / "m.bin").string();
  const int failed = test_support::InChildWithFileSizeLimit(16 * 1024, [&] {
    const auto says = [](const Result<void>& r, const std::string& path) {
      return !r && r.error().message == path + ": cannot write: " + std::strerror(EFBIG);
    };
    const bool png_ok = says(WritePng(img, png), png);
    const bool bytes_ok = says(WriteFileAtomically(bytes, std::string(64 * 1024, 'x')), bytes);
    return (png_ok ? 0 : 1) | (bytes_ok ? 0 : 2);
  });
  ASSERT_GE(failed, 0) << "the child did not exit";
  EXPECT_EQ(failed & 1, 0) << "WritePng: no error '<path>: cannot write: File too large'";
  EXPECT_EQ(failed & 2, 0)
      << "WriteFileAtomically: no error '<path>: cannot write: File too large'";
  EXPECT_TRUE(std::filesystem::is_empty(dir.path())) << "a partial or temporary file was left";
}

// A world z = 0.5 + 0.1 x for rays cast straight down (the caster contract, analytically).
class SlopeCaster : public sensors::RayCaster {
 public:
  void Cast(const float* o, const float* d, std::size_t n, float max_range, float* range,
            int* geom) const override {
    for (std::size_t r = 0; r < n; ++r) {
      const float z = 0.5f + 0.1f * o[3 * r];
      const float t = (o[3 * r + 2] - z) / -d[3 * r + 2];
      const bool hit = o[3 * r] < 3.0f && t >= 0 && t <= max_range;  // nothing beyond x = 3
      range[r] = hit ? t : std::numeric_limits<float>::infinity();
      if (geom) geom[r] = hit ? 0 : -1;
    }
  }
  void Refresh() override {}
};

TEST(ElevationTruth, DownwardRaysGiveTheTrueSurfaceAndCompareReportsErrors) {
  const GridGeometry g = GridGeometry::FromArea(0, 0, 4, 1, 0.25);
  TruthConfig config;
  config.samples_per_side = 4;
  const ElevationMap truth = ComputeTrueElevationMap(SlopeCaster{}, g, config);
  const ElevationLayers T = ComputeLayers(truth);
  const std::size_t k = g.Linear({2, 2});
  EXPECT_NEAR(T.mean_z[k], 0.5 + 0.1 * g.CenterOf({2, 2}).x(), 1e-4);
  EXPECT_NEAR(T.phi_x[k], std::atan(0.1), kAngleTolRad);
  EXPECT_EQ(T.state[g.Linear({13, 2})], CellState::kUnknown);  // x > 3: off the world
  // An estimate 2 cm too high on half of the known cells.
  ElevationMap est(g);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 4; ++j) {
      const Eigen::Vector2d c = g.CenterOf({i, j});
      pts.emplace_back(float(c.x()), float(c.y()), float(0.52 + 0.1 * c.x()));
    }
  (void)est.InsertPoints(pts.data(), pts.size());
  const MapErrorReport rep = CompareToTruth(ComputeLayers(est), T);
  EXPECT_EQ(rep.truth_cells, 48u);
  EXPECT_EQ(rep.compared_cells, 24u);
  EXPECT_NEAR(rep.coverage, 0.5, 1e-9);
  EXPECT_NEAR(rep.rmse_m, 0.02, 1e-4);
  EXPECT_NEAR(rep.mean_error_m, 0.02, 1e-4);
  EXPECT_EQ(rep.wall_cells, 0u);  // a 0.1 slope is no wall
  EXPECT_NEAR(rep.all_rmse_m, 0.02, 1e-4);
}

TEST(ElevationTruth, WallCellsAreScoredApartFromTheSurface) {
  // Truth: ground at 0 for x < 1, a 3 m roof for x >= 1 (a wall on the edge of cells 9 and 10
  // at 0.1 m). Estimate: right everywhere but 2 cm high on the ground, and with wall points in
  // the cells on both sides of the face (mean 1.5 m).
  const GridGeometry g = GridGeometry::FromArea(0, 0, 2, 0.5, 0.1);
  const auto surface = [](double x, double) { return x < 1.0 ? 0.0 : 3.0; };
  ElevationMap truth(g), est(g);
  const auto t = Lattice(0, 2, 0, 0.5, 0.1 / 3, surface);
  (void)truth.InsertPoints(t.data(), t.size());
  auto e = Lattice(0, 2, 0, 0.5, 0.05, [&](double x, double y) {
    return x > 0.9 && x < 1.1 ? 1.5 : surface(x, y) + (x < 1.0 ? 0.02 : 0.0);
  });
  (void)est.InsertPoints(e.data(), e.size());
  const MapErrorReport r = CompareToTruth(ComputeLayers(est), ComputeLayers(truth));
  // Wall cells: columns 9 and 10 (the face is in their 3 x 3 blocks), 5 rows.
  EXPECT_EQ(r.wall_cells, 2u * 5u);
  EXPECT_EQ(r.surface_cells, 18u * 5u);
  EXPECT_EQ(r.compared_cells, 20u * 5u);
  // Surface: 9 columns on the ground 2 cm high, 9 on the roof exact.
  EXPECT_NEAR(r.rmse_m, std::sqrt(0.5 * 0.02 * 0.02), 1e-5);
  EXPECT_NEAR(r.max_abs_error_m, 0.02, 1e-5);
  EXPECT_NEAR(r.wall_rmse_m, 1.5, 1e-5);
  EXPECT_NEAR(r.all_max_abs_error_m, 1.5, 1e-5);
  // Without telling walls apart, they are in the surface figures.
  CompareConfig no_walls;
  no_walls.wall_slope = 0;
  EXPECT_NEAR(CompareToTruth(ComputeLayers(est), ComputeLayers(truth), no_walls).max_abs_error_m,
              1.5, 1e-5);
}

// Over a plane floor: a table (top 0.72-0.75 m, one leg), a tree (sphere crown of radius 1 m
// centred 3 m up, a 0.1 m capsule trunk into it), a building on a slab (faces touching), a car
// cabin on its chassis (faces touching, chassis 0.25 m above the floor) and a low box shelf
// (underside 0.3 m up: less headroom than the robot needs).
constexpr char kScene[] = R"(
<mujoco model="overhangs">
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <geom name="table_top" type="box" pos="1 1 0.735" size="0.6 0.4 0.015"/>
    <geom name="table_leg" type="box" pos="0.45 0.65 0.36" size="0.02 0.02 0.36"/>
    <geom name="crown" type="sphere" pos="4.05 1.05 3" size="1"/>
    <geom name="trunk" type="capsule" fromto="4.05 1.05 0 4.05 1.05 3" size="0.1"/>
    <geom name="slab" type="box" pos="1 4 -1" size="0.8 0.8 1.14"/>
    <geom name="building" type="box" pos="1 4 1.64" size="0.5 0.5 1.5"/>
    <geom name="chassis" type="box" pos="4 4 0.55" size="0.8 0.5 0.3"/>
    <geom name="cabin" type="box" pos="4 4 1.15" size="0.5 0.4 0.3"/>
    <geom name="shelf" type="box" pos="6.5 1 0.4" size="0.3 0.3 0.1"/>
  </worldbody>
</mujoco>)";

class Scene {
 public:
  Scene() {
    const ScopedTempDir dir("overhangs");  // the file is needed only while loading
    const auto file = dir / "overhangs.xml";
    std::ofstream(file) << kScene;
    char error[1000] = "";
    model_ = mj_loadXML(file.c_str(), nullptr, error, sizeof(error));
    if (!model_) throw std::runtime_error(std::string("overhang scene: ") + error);
    data_ = mj_makeData(model_);
    mj_forward(model_, data_);
    caster_ = sensors::MakeEmbreeRayCaster(model_, data_, sensors::RayCasterOptions{"", true});
  }
  ~Scene() {
    caster_.reset();
    mj_deleteData(data_);
    mj_deleteModel(model_);
  }
  const sensors::RayCaster& caster() const { return *caster_; }

 private:
  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::unique_ptr<sensors::RayCaster> caster_;
};

TEST(ElevationTruth, FloorUnderAnOverhangCountsNotTheOverhang) {
  constexpr double kRayTolM = 1e-4;  // float rays cast from 200 m up
  const Scene scene;
  const GridGeometry g = GridGeometry::FromArea(0, 0, 8, 5.5, 0.1);
  const ElevationLayers headroom = ComputeLayers(ComputeTrueElevationMap(scene.caster(), g));
  TruthConfig first_hit;
  first_hit.min_headroom_m = 0;
  const ElevationLayers from_above =
      ComputeLayers(ComputeTrueElevationMap(scene.caster(), g, first_hit));
  const auto at = [&](const ElevationLayers& L, double x, double y) {
    return L.mean_z[g.Linear(g.IndexOf(x, y))];
  };
  // Under the table top and the crown: the floor (the first hit from above was the overhang).
  EXPECT_NEAR(at(from_above, 1.2, 1.1), 0.75, kRayTolM);
  EXPECT_NEAR(at(headroom, 1.2, 1.1), 0.0, kRayTolM);
  EXPECT_NEAR(at(from_above, 4.55, 1.05), 3 + std::sqrt(1 - 0.5 * 0.5), 0.02);
  EXPECT_NEAR(at(headroom, 4.55, 1.05), 0.0, kRayTolM);
  // Through the trunk (inside the crown), the building on its slab, the cabin on its chassis and
  // the shelf too low to drive under: the first surface from above, as before.
  EXPECT_NEAR(at(headroom, 4.05, 1.05), at(from_above, 4.05, 1.05), kRayTolM);
  EXPECT_GT(at(headroom, 4.05, 1.05), 3.9);
  EXPECT_NEAR(at(headroom, 1.05, 4.05), 3.14, kRayTolM);
  EXPECT_NEAR(at(headroom, 4.05, 4.05), 1.45, kRayTolM);
  EXPECT_NEAR(at(headroom, 4.65, 4.05), 0.85, kRayTolM);  // chassis beside the cabin
  EXPECT_NEAR(at(headroom, 6.55, 1.05), 0.5, kRayTolM);
  // The slab's top beside the building, and open floor, are unchanged.
  EXPECT_NEAR(at(headroom, 1.65, 4.05), 0.14, kRayTolM);
  EXPECT_NEAR(at(headroom, 7.55, 5.05), 0.0, kRayTolM);
}

}  // namespace
}  // namespace pitchlab::mapping
