// GrazedReturns on a scan cast analytically: a pitching scanner in a corridor-like scene (floor,
// a wall along the robot's left that ends, a thin pole, a wall facing the robot), every return's
// true surface and incidence known, so which returns the footprint spreads over more than a cell
// is known exactly.

#include "pitchlab/sensors/grazing_returns.hpp"

#include <cmath>
#include <optional>
#include <random>
#include <set>
#include <utility>

#include <gtest/gtest.h>

namespace pitchlab::sensors {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDivergence = 0.25 * kPi / 180;  // the LMS200's full beam width
constexpr double kCell = 0.1;

enum class Surface { kFloor, kSideWall, kPole, kFacingWall };

struct Hit {
  double range = 0;
  Surface surface = Surface::kFloor;
  Eigen::Vector3d normal;
};

// The scene in base_link: floor z = 0; a wall y = 1 for x in [1, 7] (2.5 m high), ending there;
// a pole of radius 2.5 cm at (3, -0.6); a wall x = 12, |y| <= 4 facing the robot.
std::optional<Hit> Cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  std::optional<Hit> best;
  const auto offer = [&](double t, Surface s, const Eigen::Vector3d& n) {
    if (t > 0.05 && (!best || t < best->range)) best = Hit{t, s, n};
  };
  if (d.z() < 0) offer(-o.z() / d.z(), Surface::kFloor, Eigen::Vector3d::UnitZ());
  if (d.y() > 0) {
    const double t = (0.95 - o.y()) / d.y();
    const Eigen::Vector3d p = o + t * d;
    if (p.x() >= 1 && p.x() <= 7 && p.z() >= 0 && p.z() <= 2.5) {
      offer(t, Surface::kSideWall, -Eigen::Vector3d::UnitY());
    }
  }
  if (d.x() > 0) {
    const double t = (12 - o.x()) / d.x();
    const Eigen::Vector3d p = o + t * d;
    if (std::abs(p.y()) <= 4 && p.z() >= 0 && p.z() <= 2.5) {
      offer(t, Surface::kFacingWall, -Eigen::Vector3d::UnitX());
    }
  }
  {  // the pole: |(o + t d - c)_xy| = r
    const Eigen::Vector2d c(3, -0.6), oc = o.head<2>() - c, dd = d.head<2>();
    const double r = 0.025, a = dd.squaredNorm(), b = 2 * oc.dot(dd), k = oc.squaredNorm() - r * r;
    const double disc = b * b - 4 * a * k;
    if (disc >= 0) {
      const double t = (-b - std::sqrt(disc)) / (2 * a);
      const Eigen::Vector3d p = o + t * d;
      Eigen::Vector3d n(p.x() - c.x(), p.y() - c.y(), 0);
      offer(t, Surface::kPole, n.normalized());
    }
  }
  return best;
}

struct CastScan {
  Scan3D scan;
  std::vector<Hit> hits;  // one per point
};

// The return of beam `beam` of line `line` at `p`, `range` from the laser.
ScanPoint Return(const Eigen::Vector3d& p, double range, int line, int beam) {
  ScanPoint sp;
  sp.x = float(p.x());
  sp.y = float(p.y());
  sp.z = float(p.z());
  sp.range_m = float(range);
  sp.line = std::uint16_t(line);
  sp.beam = std::uint16_t(beam);
  return sp;
}

// The measured LMS200 model's range noise (Lms200Config{}): 2 mm + 1.5 mm/m + 0.4 of the
// footprint's depth r delta tan(incidence), tan held at its 85 deg value beyond.
double MeasuredSigma(double range, const Eigen::Vector3d& beam, const Eigen::Vector3d& normal) {
  const double c = std::abs(beam.normalized().dot(normal));
  const double tan_incidence = std::min(std::sqrt(1 - c * c) / c, std::tan(85 * kPi / 180));
  return std::sqrt(0.002 * 0.002 + std::pow(0.0015 * range, 2) +
                   std::pow(0.4 * range * kDivergence * tan_incidence, 2));
}

// 100 lines from -30 to +15 deg pitch, 361 beams over 180 deg (the LMS200's 0.5 deg); with `rng`,
// each range gets the measured model's noise.
CastScan CastAll(const MountConfig& mount, std::mt19937* rng = nullptr) {
  CastScan out;
  for (int l = 0; l < 100; ++l) {
    LaserLine line;
    line.pitch_rad = (-30.0 + 0.45 * l) * kPi / 180;
    line.angle_min_rad = -kPi / 2;
    line.angle_increment_rad = 0.5 * kPi / 180;
    const Eigen::Vector3d o = mount.BaseToLaser(line.pitch_rad).translation();
    for (int b = 0; b < 361; ++b) {
      const Eigen::Vector3d d =
          (BeamPointInBase(1.0, line.Angle(b), line.pitch_rad, mount) - o).normalized();
      const std::optional<Hit> hit = Cast(o, d);
      if (!hit || hit->range > 30) continue;
      double range = hit->range;
      if (rng) {
        range += MeasuredSigma(range, d, hit->normal) * std::normal_distribution<double>()(*rng);
      }
      out.scan.points.push_back(Return(o + range * d, range, l, b));
      out.hits.push_back(*hit);
    }
    out.scan.lines.push_back(line);
  }
  return out;
}

// The true footprint spread of a return along its beam, r delta tan(incidence) [m].
double TrueSpread(const ScanPoint& p, const Hit& hit, const Eigen::Vector3d& laser) {
  const Eigen::Vector3d beam = (Eigen::Vector3d(p.x, p.y, p.z) - laser).normalized();
  const double c = std::abs(beam.dot(hit.normal));
  return p.range_m * kDivergence * std::sqrt(1 - c * c) / c;
}

TEST(GrazedReturns, AWallGrazedBeyondACellIsFlaggedAndTheFloorPoleAndFacingWallAreNot) {
  const MountConfig mount;
  const CastScan cast = CastAll(mount);
  GrazingConfig config;
  config.beam_divergence_rad = kDivergence;
  config.max_spread_m = kCell;
  const std::vector<bool> grazed = GrazedReturns(cast.scan, mount, config);
  ASSERT_EQ(grazed.size(), cast.scan.points.size());

  int wall_far = 0, wall_far_flagged = 0, wall_near = 0, floor = 0, pole = 0, facing = 0;
  for (std::size_t i = 0; i < grazed.size(); ++i) {
    const ScanPoint& p = cast.scan.points[i];
    const Hit& hit = cast.hits[i];
    switch (hit.surface) {
      case Surface::kFloor:
        ++floor;
        EXPECT_FALSE(grazed[i]) << "floor point at " << p.x << ", " << p.y;
        break;
      case Surface::kPole:
        ++pole;
        EXPECT_FALSE(grazed[i]) << "pole point at range " << p.range_m;
        break;
      case Surface::kFacingWall:
        ++facing;
        EXPECT_FALSE(grazed[i]) << "facing wall point at " << p.x << ", " << p.y;
        break;
      case Surface::kSideWall: {
        const double spread =
            TrueSpread(p, hit, mount.BaseToLaser(cast.scan.lines[p.line].pitch_rad).translation());
        // Away from the wall's ends and edges (where the neighbours lie on other surfaces) and
        // 20 % away from the threshold, the flag is the true spread's verdict.
        if (p.x < 1.5 || p.x > 6.5 || p.z < 0.2 || p.z > 2.3) break;
        if (spread > 1.2 * kCell) {
          ++wall_far;
          wall_far_flagged += grazed[i];
        } else if (spread < 0.8 * kCell) {
          ++wall_near;
          EXPECT_FALSE(grazed[i]) << "wall point with spread " << spread;
        }
        break;
      }
    }
  }
  // The scene has each case (a test of nothing cannot fail).
  EXPECT_GT(floor, 1000);
  EXPECT_GT(pole, 10);
  EXPECT_GT(facing, 1000);
  EXPECT_GT(wall_near, 100);
  EXPECT_GT(wall_far, 100);
  // The estimated normal comes from neighbours a beam or a line away on the same plane: exact
  // up to float rounding, so every far grazed wall point is flagged.
  EXPECT_EQ(wall_far_flagged, wall_far);
}

// Lines of a scan that look at a wall 3 m ahead (x = 3) through a 1 m gap, with a wall 7 m ahead
// behind the gap; the beam that straddles each edge returns the mean of the two ranges, as the
// LMS200 model's mixed pixels (and a real LMS) do: a point in the air between the walls.
TEST(GrazedReturns, AMixedPixelAtADepthEdgeIsFlaggedAndTheWallsBesideItAreNot) {
  const MountConfig mount;
  Scan3D scan;
  int mixed = 0, wall = 0;
  for (int l = 0; l < 3; ++l) {
    LaserLine line;
    line.pitch_rad = (-2.0 + 2.0 * l) * kPi / 180;
    line.angle_min_rad = -kPi / 4;
    line.angle_increment_rad = 0.5 * kPi / 180;
    scan.lines.push_back(line);
    const Eigen::Vector3d o = mount.BaseToLaser(line.pitch_rad).translation();
    double last_far = -1;  // whether the previous beam met the far wall
    for (int b = 0; b <= 180; ++b) {
      const Eigen::Vector3d d =
          (BeamPointInBase(1.0, line.Angle(b), line.pitch_rad, mount) - o).normalized();
      const double t_near = (3 - o.x()) / d.x(), t_far = (7 - o.x()) / d.x();
      const bool far = std::abs((o + t_near * d).y()) < 0.5;  // through the gap
      double range = far ? t_far : t_near;
      const bool edge = last_far >= 0 && far != (last_far > 0);
      last_far = far ? 1 : 0;
      if (edge) range = 0.5 * (t_near + t_far);
      scan.points.push_back(Return(o + range * d, range, l, b));
      (edge ? mixed : wall) += 1;
    }
  }
  const std::vector<bool> grazed = GrazedReturns(scan, mount);
  int mixed_flagged = 0, wall_flagged = 0;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const ScanPoint& p = scan.points[i];
    const double t_near = 3.0, t_far = 7.0;
    const bool on_wall = std::abs(p.x - t_near) < 0.05 || std::abs(p.x - t_far) < 0.05;
    (on_wall ? wall_flagged : mixed_flagged) += grazed[i];
  }
  EXPECT_EQ(mixed, 6);  // two edges in each of three lines
  EXPECT_EQ(mixed_flagged, mixed);
  EXPECT_EQ(wall_flagged, 0) << "of " << wall << " wall returns";
}

// With the measured model's noise a return on the side wall, met at grazing incidence (82 deg at
// its end), moves along its beam by decimetres: near the wall's end (x = 7) the noise puts
// returns past it, in the air where the robot would drive, as a door's jamb put wall-high points
// into an office doorway. Each return of the wall's last half metre with returns beside it in
// its line is flagged, whichever way its noise went; the floor, the pole and the facing wall
// keep their returns.
TEST(GrazedReturns, NoisyReturnsPastAGrazedWallsEndAreFlagged) {
  const MountConfig mount;
  std::mt19937 rng(16);
  const CastScan cast = CastAll(mount, &rng);
  const std::vector<bool> grazed = GrazedReturns(cast.scan, mount);
  std::set<std::pair<int, int>> returned;  // (line, beam)
  for (const ScanPoint& p : cast.scan.points) returned.insert({p.line, p.beam});
  int near_end = 0, near_end_flagged = 0, kept_surfaces = 0, kept_flagged = 0;
  for (std::size_t i = 0; i < grazed.size(); ++i) {
    const ScanPoint& p = cast.scan.points[i];
    const Surface s = cast.hits[i].surface;
    if (s == Surface::kSideWall && p.x > 6.5 && returned.count({p.line, p.beam - 1}) &&
        returned.count({p.line, p.beam + 1})) {
      ++near_end;
      near_end_flagged += grazed[i];
    } else if (s == Surface::kFloor || s == Surface::kPole || s == Surface::kFacingWall) {
      ++kept_surfaces;
      kept_flagged += grazed[i];
    }
  }
  EXPECT_GT(near_end, 20);
  EXPECT_EQ(near_end_flagged, near_end);
  // Noise makes a few facing or floor returns look grazed (a pole's edge, the wall's foot).
  EXPECT_LT(kept_flagged, kept_surfaces / 200) << kept_flagged << " of " << kept_surfaces;
}

// The beam past a grazed wall's end that gave no return (a dropout, or a doorway into the open)
// counts as beyond the wall's last return, which is flagged as if the room behind had answered.
TEST(GrazedReturns, AGrazedWallsLastReturnIsFlaggedWhenTheBeamPastTheEndDroppedOut) {
  const MountConfig mount;
  std::mt19937 rng(16);
  CastScan cast = CastAll(mount, &rng);
  // Each line's return next to the wall's last one, past the end (the facing wall), drops out.
  std::set<std::pair<int, int>> wall_end, dropped;  // (line, beam)
  std::set<std::pair<int, int>> on_wall;
  for (std::size_t i = 0; i < cast.scan.points.size(); ++i) {
    if (cast.hits[i].surface == Surface::kSideWall) {
      on_wall.insert({cast.scan.points[i].line, cast.scan.points[i].beam});
    }
  }
  for (std::size_t i = 0; i < cast.scan.points.size(); ++i) {
    const ScanPoint& p = cast.scan.points[i];
    if (cast.hits[i].surface != Surface::kFacingWall) continue;
    for (const int side : {-1, 1}) {
      if (on_wall.count({p.line, p.beam + side}) && !on_wall.count({p.line, p.beam - side})) {
        wall_end.insert({p.line, p.beam + side});
        dropped.insert({p.line, p.beam});
      }
    }
  }
  Scan3D scan;
  scan.lines = cast.scan.lines;
  for (const ScanPoint& p : cast.scan.points) {
    if (!dropped.count({p.line, p.beam})) scan.points.push_back(p);
  }
  const std::vector<bool> grazed = GrazedReturns(scan, mount);
  int last = 0, last_flagged = 0;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (!wall_end.count({scan.points[i].line, scan.points[i].beam})) continue;
    ++last;
    last_flagged += grazed[i];
  }
  EXPECT_GT(last, 20);
  EXPECT_EQ(last_flagged, last);
}

TEST(GrazedReturns, ReturnsWithoutNeighboursOnBothSidesAreKept) {
  Scan3D scan;
  scan.lines.resize(2);
  // A wall along x seen at grazing incidence, but each return alone in its line.
  for (int l = 0; l < 2; ++l) {
    ScanPoint p;
    p.x = 6.0f + float(l);
    p.y = 1.0f;
    p.z = 0.5f;
    p.range_m = p.x;
    p.line = std::uint16_t(l);
    p.beam = 100;
    scan.points.push_back(p);
  }
  const std::vector<bool> grazed = GrazedReturns(scan, MountConfig{});
  EXPECT_EQ(grazed, std::vector<bool>(2, false));
  EXPECT_TRUE(GrazedReturns(Scan3D{}, MountConfig{}).empty());
}

}  // namespace
}  // namespace pitchlab::sensors
