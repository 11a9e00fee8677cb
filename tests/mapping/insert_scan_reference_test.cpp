// ElevationMap::InsertScan's fast path (issue 20: re-posing 40 scans <= 0.2 s) against the
// straightforward one it replaced (insert_scan_reference.hpp): the same cells bit for bit, every
// field (clearance_z included) and the same InsertStats, over scans that exercise every rule
// (rays' clearance, overhang, height band, undersides, z limits, non-finite points, points and
// sensors off the grid) and with rays landing on a map that already holds a scan.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "insert_scan_reference.hpp"
#include "pitchlab/mapping/elevation_map.hpp"

namespace pitchlab::mapping {
namespace {

constexpr double kDeg = M_PI / 180;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// The scene: floor z = 0, a 0.4 m box at x in [3, 3.6], |y| <= 0.5, a 2.5 m wall at x = 7, a
// 2.4 m ceiling over x < 5 (undersides), a table top at 0.7 m over x in [1.5, 2.5], y in [1, 2]
// (an underside the laser looks up at). Distance from o along d to the first surface, or +inf.
double Cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double best = std::numeric_limits<double>::infinity();
  const auto plane_z = [&](double z, double x0, double x1, double y0, double y1) {
    if (d.z() == 0) return;
    const double t = (z - o.z()) / d.z();
    const Eigen::Vector3d p = o + t * d;
    if (t > 0 && t < best && p.x() >= x0 && p.x() <= x1 && p.y() >= y0 && p.y() <= y1) best = t;
  };
  constexpr double kFar = 1e9;
  plane_z(0.0, -kFar, kFar, -kFar, kFar);
  plane_z(0.4, 3.0, 3.6, -0.5, 0.5);
  plane_z(2.4, -kFar, 5.0, -kFar, kFar);
  plane_z(0.7, 1.5, 2.5, 1.0, 2.0);
  if (d.x() > 0) {
    const double t = (7.0 - o.x()) / d.x();
    if (t > 0 && t < best && (o + t * d).z() <= 2.5) best = t;
    const double tb = (3.0 - o.x()) / d.x();  // the box's front face
    const Eigen::Vector3d p = o + tb * d;
    if (tb > 0 && tb < best && std::abs(p.y()) <= 0.5 && p.z() <= 0.4) best = tb;
  }
  return best;
}

// A nodding scan (80 lines of 181 beams over 180 x 100 deg, 1 cm range noise) from `sensor`
// turned `yaw_deg`, in the map frame; then scattered points (random heights, some over the
// sensor: planes of every tilt for SeenFrom), non-finite points and points far off the grid.
std::vector<Eigen::Vector3f> Scan(const Eigen::Vector3d& sensor, double yaw_deg, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Eigen::Vector3f> points;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ()).matrix();
  for (int line = 0; line < 80; ++line) {
    const double pitch = (-60.0 + 100.0 * line / 79) * kDeg;
    for (int beam = 0; beam < 181; ++beam) {
      const double a = (-90.0 + beam) * kDeg;
      const Eigen::Vector3d d = R * Eigen::Vector3d(std::cos(pitch) * std::cos(a),
                                                    std::cos(pitch) * std::sin(a), std::sin(pitch));
      const double t = Cast(sensor, d);
      if (t < 12.0) points.push_back((sensor + (t + noise(rng)) * d).cast<float>());
    }
  }
  std::uniform_real_distribution<float> xy(-4.0f, 9.0f), z(-0.3f, 2.6f);
  for (int k = 0; k < 3000; ++k) points.emplace_back(xy(rng), xy(rng) - 2.5f, z(rng));
  points.emplace_back(kNaN, 1.0f, 0.0f);
  points.emplace_back(2.0f, kInfinity, 0.0f);
  points.emplace_back(2.0f, 1.0f, -kInfinity);
  points.emplace_back(400.0f, 1.0f, 0.0f);
  points.emplace_back(2.0f, -300.0f, 0.5f);
  points.emplace_back(2.0f, 1.0f, 1e7f);
  points.push_back(sensor.cast<float>());  // no horizontal extent: no ray
  return points;
}

bool SameStats(const InsertStats& a, const InsertStats& b) {
  return a.inserted == b.inserted && a.outside == b.outside && a.non_finite == b.non_finite &&
         a.clearance_cells == b.clearance_cells && a.overhang == b.overhang &&
         a.above_band == b.above_band && a.underside == b.underside;
}

// Two scans, one after the other (the second's rays land on the first's cells), through the fast
// path and the reference; every cell's bytes equal.
void ExpectFastEqualsReference(const GridGeometry& area, const InsertConfig& config) {
  ElevationMap fast(area);
  std::vector<CellStats> reference(area.cell_count());
  const Eigen::Vector3d sensors[2] = {{0.3, -0.2, 0.54}, {2.1, 0.7, 0.61}};
  for (int s = 0; s < 2; ++s) {
    const std::vector<Eigen::Vector3f> scan = Scan(sensors[s], 17.0 * s - 8, 7 + s);
    const Eigen::Vector3f origin = sensors[s].cast<float>();
    const InsertStats a = fast.InsertScan(scan.data(), scan.size(), origin, config);
    const InsertStats b =
        reference::InsertScan(area, reference, scan.data(), scan.size(), origin, config);
    EXPECT_TRUE(SameStats(a, b)) << "scan " << s;
    EXPECT_GT(a.inserted, 2000u);
    EXPECT_EQ(a.non_finite, 3u);
  }
  std::size_t differing = 0, known = 0, cleared = 0;
  for (std::size_t k = 0; k < reference.size(); ++k) {
    differing += std::memcmp(&fast.at(k), &reference[k], sizeof(CellStats)) != 0;
    known += reference[k].known();
    cleared += std::isfinite(reference[k].clearance_z);
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(known, 500u);  // not vacuous
  if (config.clearance_length_m > 0) EXPECT_GT(cleared, 500u);
}

GridGeometry Office() { return GridGeometry::FromArea(-6, -9, 18, 18, 0.1); }

TEST(InsertScanReference, DefaultsGiveTheReferencesCellsBitForBit) {
  const InsertConfig config;
  ExpectFastEqualsReference(Office(), config);
}

TEST(InsertScanReference, EveryRuleOnGivesTheReferencesCellsBitForBit) {
  InsertConfig config;
  config.max_height_m = 0.8;  // the band: the box and the far wall's top rise above it
  config.min_z_m = -0.2;
  config.max_z_m = 2.3;
  ExpectFastEqualsReference(Office(), config);
  config.clearance_length_m = 40.0;  // whole rays, from the sensor
  ExpectFastEqualsReference(Office(), config);
}

TEST(InsertScanReference, RulesOffGiveTheReferencesCellsBitForBit) {
  InsertConfig config;
  config.drop_undersides = false;
  config.overhang_headroom_m = 0.0;
  ExpectFastEqualsReference(Office(), config);
  config.clearance_length_m = 0.0;  // no rays
  ExpectFastEqualsReference(Office(), config);
}

// A grid smaller than the scan and a sensor off it: rays enter and leave the grid.
TEST(InsertScanReference, AGridSmallerThanTheScanGivesTheReferencesCellsBitForBit) {
  const InsertConfig config;
  ExpectFastEqualsReference(GridGeometry::FromArea(1.05, -2.35, 5.2, 4.1, 0.1), config);
  ExpectFastEqualsReference(GridGeometry::FromArea(-6, -9, 18, 18, 0.25), config);
}

}  // namespace
}  // namespace pitchlab::mapping
