// The rules that make real scans mappable, on a synthetic nodding scan with known answers: a flat
// floor under a ceiling 2.5 m up, seen by a scanner whose frame is tilted 4 deg (as the 3DTK
// corridor's), with range noise. Levelling by the floor, the height band and the underside rule,
// the slope's support, and drops that need a rim.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/ground_level.hpp"
#include "pitchlab/planning/traversability.hpp"

namespace pitchlab::mapping {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kSensorHeightM = 0.5;  // the laser above the floor
constexpr double kCeilingM = 2.5;       // the ceiling above the floor
constexpr double kTiltRad = 4.0 * kDeg;

// The scanner's frame is turned by `tilt` about an axis between x and y; the world is level.
Eigen::Matrix3d SensorTilt() {
  return Eigen::AngleAxisd(kTiltRad, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
}

// A nodding LMS200 scan: 0.5 deg beams over 180 deg, lines every 0.45 deg of pitch from -40 to
// +40 deg (DESIGN.md's sensor), rays from the laser (at the origin of the sensor frame) to a
// level floor kSensorHeightM below and a ceiling above, up to 15 m; range noise 1 cm (real LMS
// data: 1-3 cm). Points in the tilted sensor frame.
std::vector<Eigen::Vector3f> NoddingScan(double noise_m = 0.01, double line_error_rad = 0.0) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_m), line_error(0.0, line_error_rad);
  const Eigen::Matrix3d R = SensorTilt();  // sensor -> world
  std::vector<Eigen::Vector3f> points;
  for (double pitch = -40.0; pitch <= 40.0 + 1e-9; pitch += 0.45) {
    const double error = line_error(rng);
    for (double beam = -90.0; beam <= 90.0 + 1e-9; beam += 0.5) {
      const Eigen::Vector3d d_sensor =
          Eigen::AngleAxisd(pitch * kDeg, Eigen::Vector3d::UnitY()) *
          Eigen::Vector3d(std::cos(beam * kDeg), std::sin(beam * kDeg), 0.0);
      const Eigen::Vector3d d = R * d_sensor;  // world direction
      double range = 0;
      if (d.z() < -1e-6) range = kSensorHeightM / -d.z();
      if (d.z() > 1e-6) range = (kCeilingM - kSensorHeightM) / d.z();
      if (!(range > 0.5 && range < 15.0)) continue;
      // The encoder's (or the pose's) error turns the whole line: it lands where the world says,
      // and is reported at the pitch the scanner believed.
      const Eigen::Vector3d d_believed =
          Eigen::AngleAxisd(-error, Eigen::Vector3d::UnitY()) * d_sensor;
      points.push_back(((range + noise(rng)) * d_believed).cast<float>());
    }
  }
  return points;
}

struct Levelled {
  GroundLevel level;
  std::vector<Eigen::Vector3f> points;  // levelled frame
};

Levelled LevelScan(const std::vector<Eigen::Vector3f>& scan) {
  Result<GroundLevel> level = FitGroundLevel(scan, Eigen::Vector3f::Zero());
  EXPECT_TRUE(level.has_value()) << level.error().message;
  Levelled out{*level, {}};
  const Eigen::Matrix3f R = level->R_level.cast<float>();
  for (const Eigen::Vector3f& p : scan) out.points.push_back(R * p);
  return out;
}

TEST(GroundLevel, RemovesAFourDegreeTiltToATenthOfADegree) {
  const Levelled l = LevelScan(NoddingScan());
  EXPECT_NEAR(l.level.tilt_rad, kTiltRad, 0.1 * kDeg);
  // The world's up seen in the sensor frame, turned by the levelling, must be z again.
  const Eigen::Vector3d up = l.level.R_level * SensorTilt().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up.z())), 0.1 * kDeg);
  // Residual: the range noise (1 cm) seen along the floor's normal, per cell of a few points.
  EXPECT_GT(l.level.residual_m, 0.0005);
  EXPECT_LT(l.level.residual_m, 0.01);
  EXPECT_NEAR(l.level.sensor_height_m, kSensorHeightM, 0.01);
  EXPECT_GT(l.level.inliers, 500u);
}

TEST(GroundLevel, TooFewPointsNearTheSensorIsAnErrorNamingTheCount) {
  const std::vector<Eigen::Vector3f> few = {{1, 0, -0.5f}, {2, 0, -0.5f}, {1, 1, -0.5f}};
  const Result<GroundLevel> level = FitGroundLevel(few, Eigen::Vector3f::Zero());
  ASSERT_FALSE(level.has_value());
  EXPECT_NE(level.error().message.find("3 cells"), std::string::npos) << level.error().message;
  // The band as people write it (NumberText), not as "0.500000..4.000000 m".
  EXPECT_NE(level.error().message.find("within 0.5..4 m of it"), std::string::npos)
      << level.error().message;
}

// The levelled scan in a map around the sensor, the band and the underside rule as given.
ElevationLayers MapScan(const Levelled& l, double max_height_m, bool drop_undersides,
                        const LayerConfig& layer_config = {}) {
  ElevationMap map(GridGeometry::FromArea(-1, -16, 17, 32, 0.1));
  InsertConfig insert;
  insert.max_height_m = max_height_m;
  insert.sensor_height_m = l.level.sensor_height_m;
  insert.drop_undersides = drop_undersides;
  map.InsertScan(l.points.data(), l.points.size(), Eigen::Vector3f::Zero(), insert);
  return ComputeLayers(map, layer_config);
}

std::size_t CellsAbove(const ElevationLayers& L, double z_m) {
  std::size_t n = 0;
  for (std::size_t k = 0; k < L.state.size(); ++k)
    n += L.state[k] == CellState::kObserved && L.max_z[k] > z_m;
  return n;
}

TEST(HeightBand, CeilingCellsAreNotGround) {
  const Levelled l = LevelScan(NoddingScan());
  const double floor_z = -l.level.sensor_height_m;
  // Without band or underside rule the ceiling is the ground of every cell it covers.
  const ElevationLayers raw = MapScan(l, std::numeric_limits<double>::infinity(), false);
  ASSERT_GT(CellsAbove(raw, floor_z + 1.0), 400u);
  // The underside rule alone: the ceiling is seen from below wherever its points span a plane;
  // what is left are far cells of single scan lines, beyond the floor rays' reach (the overhang
  // rule takes the ceiling over rays to the floor).
  const ElevationLayers undersides = MapScan(l, std::numeric_limits<double>::infinity(), true);
  EXPECT_LT(CellsAbove(undersides, floor_z + 1.0), CellsAbove(raw, floor_z + 1.0));
  // With the band as well, no cell's ground is the ceiling: those seen only there stay unknown.
  const ElevationLayers banded = MapScan(l, 1.0, true);
  EXPECT_EQ(CellsAbove(banded, floor_z + 0.1), 0u);
  std::size_t floor_cells = 0;
  for (std::size_t k = 0; k < banded.state.size(); ++k)
    floor_cells += banded.state[k] == CellState::kObserved;
  EXPECT_GT(floor_cells, 3000u);
}

TEST(HeightBand, AHillRisingAheadStaysGround) {
  // A 15 % ramp from 2 m ahead rises 1.2 m by 10 m: above a flat 1 m band, within the graded one.
  std::vector<Eigen::Vector3f> scan;
  for (double x = 0.55; x < 10.0; x += 0.02)
    for (double y = -1.0; y < 1.0; y += 0.02) {
      const double ground = x < 2.0 ? 0.0 : 0.15 * (x - 2.0);
      scan.emplace_back(float(x), float(y), float(ground - kSensorHeightM));
    }
  ElevationMap map(GridGeometry::FromArea(0, -1, 10, 2, 0.1));
  InsertConfig insert;
  insert.max_height_m = 1.0;
  insert.sensor_height_m = kSensorHeightM;
  const InsertStats s = map.InsertScan(scan.data(), scan.size(), Eigen::Vector3f::Zero(), insert);
  EXPECT_EQ(s.above_band, 0u);
  EXPECT_EQ(s.underside, 0u);
  EXPECT_EQ(s.inserted, scan.size());
}

TEST(SlopeSupport, FarSparseFloorIsUnknownNotSteep) {
  const Levelled l = LevelScan(NoddingScan(0.01, 0.1 * kDeg));
  planning::PlannerConfig planner;
  // Far floor (beyond 6 m the lines lie > 0.5 m apart): without the support rule a single line's
  // noise makes slopes, with it those cells' inclination is unknown and none is too steep.
  LayerConfig unsupported;
  unsupported.max_slope_error = std::numeric_limits<double>::infinity();
  const auto steep_far = [&](const ElevationLayers& L, std::size_t* unknown_incl) {
    const planning::TraversabilityGrid T = planning::BuildTraversability(L, planner);
    std::size_t steep = 0;
    *unknown_incl = 0;
    for (std::size_t k = 0; k < L.state.size(); ++k) {
      if (L.state[k] != CellState::kObserved) continue;
      if (L.geometry.CenterOf(L.geometry.FromLinear(k)).norm() < 6.0) continue;
      steep += T.blocked[k] == planning::Blocked::kTooSteep;
      *unknown_incl += !std::isfinite(L.phi_x[k]);
    }
    return steep;
  };
  std::size_t unknown_before = 0, unknown_after = 0;
  const std::size_t steep_before =
      steep_far(MapScan(l, 1.0, true, unsupported), &unknown_before);
  const std::size_t steep_after = steep_far(MapScan(l, 1.0, true), &unknown_after);
  EXPECT_GT(steep_before, 10u) << "unknown " << unknown_before << " -> " << unknown_after;
  EXPECT_EQ(steep_after, 0u);
  EXPECT_GT(unknown_after, unknown_before);
  // Near the sensor the floor is dense: its inclination is known and level.
  const ElevationLayers L = MapScan(l, 1.0, true);
  const CellIndex near = L.geometry.IndexOf(2.05, 0.05);
  const std::size_t k = L.geometry.Linear(near);
  ASSERT_TRUE(std::isfinite(L.phi_x[k]));
  EXPECT_LT(L.Tilt(k), 2.0 * kDeg);
}

TEST(DropRim, AFlatFloorSeenByRaysHasNoDrops) {
  const ElevationLayers L = MapScan(LevelScan(NoddingScan(0.01, 0.1 * kDeg)), 1.0, true);
  std::size_t drops = 0;
  for (CellState s : L.state) drops += s == CellState::kDrop;
  EXPECT_EQ(drops, 0u);
}

TEST(DropRim, APatchOfGroundIsARimAFewPointsOfAWallAreNot) {
  // Rays along the row y in [0.2, 0.3) from 0.1 m up to the floor 2.55 m ahead pass over the cell
  // x in [1.1, 1.2) about 0.06 m up. Beside it (the row above, which no ray crosses): first two
  // points of a wall 0.4-0.6 m up, then a level patch of ground 0.4 m up.
  const GridGeometry g = GridGeometry::FromArea(0, 0, 3, 1, 0.1);
  std::vector<Eigen::Vector3f> far_floor;
  for (double y = 0.21; y < 0.3; y += 0.02) far_floor.emplace_back(2.55f, float(y), 0.0f);
  const Eigen::Vector3f sensor(0.0f, 0.25f, 0.1f);
  const std::size_t beside = g.Linear({11, 2});

  ElevationMap wall_map(g);
  const std::vector<Eigen::Vector3f> wall = {{1.15f, 0.35f, 0.40f}, {1.16f, 0.36f, 0.60f}};
  wall_map.InsertPoints(wall.data(), wall.size());
  wall_map.InsertScan(far_floor.data(), far_floor.size(), sensor);
  const ElevationLayers by_wall = ComputeLayers(wall_map);
  ASSERT_TRUE(std::isfinite(by_wall.clearance_z[beside]));
  EXPECT_LT(by_wall.clearance_z[beside], 0.4 - LayerConfig{}.drop_depth_m);
  EXPECT_EQ(by_wall.state[beside], CellState::kUnknown);

  ElevationMap rim_map(g);
  std::vector<Eigen::Vector3f> patch;
  for (double x = 0.91; x < 1.3; x += 0.02)
    for (double y = 0.31; y < 0.5; y += 0.02) patch.emplace_back(float(x), float(y), 0.4f);
  rim_map.InsertPoints(patch.data(), patch.size());
  rim_map.InsertScan(far_floor.data(), far_floor.size(), sensor);
  EXPECT_EQ(ComputeLayers(rim_map).state[beside], CellState::kDrop);
}

}  // namespace
}  // namespace pitchlab::mapping
