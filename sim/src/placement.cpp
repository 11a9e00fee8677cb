// Simulation::PlaceRobot: find the ground under the footprint, check it is free, drop and settle.

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "pitchlab/sim/simulation.hpp"
#include "simulation_impl.hpp"

namespace pitchlab::sim {
namespace {

std::string Xy(double x, double y) {
  std::ostringstream os;
  os.precision(3);
  os << std::fixed << "(" << x << ", " << y << ")";
  return os.str();
}

// Footprint sample points in the world: a 3 x 3 grid over the robot's length and width.
std::vector<Eigen::Vector2d> FootprintSamples(const P3Params& p, double x, double y, double yaw) {
  std::vector<Eigen::Vector2d> out;
  const Eigen::Rotation2Dd R(yaw);
  for (double fx : {-0.5, 0.0, 0.5}) {
    for (double fy : {-0.5, 0.0, 0.5}) {
      const Eigen::Vector2d local(p.footprint_x_m + fx * (p.length_m - 0.04),
                                  fy * (p.width_m - 0.04));
      out.push_back(Eigen::Vector2d(x, y) + R * local);
    }
  }
  return out;
}

// The top of heightfield geom `g` at world (x, y) [m], on the triangles MuJoCo collides with
// (vertex (r, c) at (c dx - sx, r dy - sy, data[r ncol + c] sz), cell (r, c) split along
// (r, c)-(r+1, c+1)); -inf off the field. Not mj_rayHfield alone: MuJoCo 2.2.2's lets a
// vertical ray that runs exactly along a grid line fall through the surface onto the base's top
// (measured: of the vertical rays through the vertices and edge midpoints of a DEM world at
// 0.3 m, 38 k of 4.2 M; none of a million at random positions), and a start at round
// coordinates puts the footprint's samples on grid lines: "a step of 24 m" under a flat
// footprint. A field tilted off world z (never written by pitchlab) is left to mj_rayHfield.
double HfieldTop(const mjModel* m, const mjData* d, int g, const Eigen::Vector2d& xy,
                 const mjtNum pnt[3], const mjtNum down[3]) {
  const double dist = mj_rayHfield(m, d, g, pnt, down);
  const double ray_top = dist >= 0 ? pnt[2] - dist : -std::numeric_limits<double>::infinity();
  const mjtNum* R = d->geom_xmat + 9 * g;  // row-major: world = R local + pos
  if (R[8] < 1.0 - 1e-9) return ray_top;
  const mjtNum* pos = d->geom_xpos + 3 * g;
  const double wx = xy.x() - pos[0], wy = xy.y() - pos[1];
  const double lx = R[0] * wx + R[3] * wy, ly = R[1] * wx + R[4] * wy;  // R^T (p - pos)
  const int h = m->geom_dataid[g];
  const int nrow = m->hfield_nrow[h], ncol = m->hfield_ncol[h];
  const mjtNum* size = m->hfield_size + 4 * h;
  const float* data = m->hfield_data + m->hfield_adr[h];
  const double col = (lx + size[0]) * (ncol - 1) / (2.0 * size[0]);
  const double row = (ly + size[1]) * (nrow - 1) / (2.0 * size[1]);
  if (!(col >= 0 && col <= ncol - 1 && row >= 0 && row <= nrow - 1)) return ray_top;
  const int c = std::min(static_cast<int>(col), ncol - 2),
            r = std::min(static_cast<int>(row), nrow - 2);
  const double fx = col - c, fy = row - r;
  const auto z = [&](int rr, int cc) { return static_cast<double>(data[rr * ncol + cc]); };
  const double top =
      fx >= fy ? z(r, c) + fx * (z(r, c + 1) - z(r, c)) + fy * (z(r + 1, c + 1) - z(r, c + 1))
               : z(r, c) + fy * (z(r + 1, c) - z(r, c)) + fx * (z(r + 1, c + 1) - z(r + 1, c));
  const double surface = pos[2] + top * size[2];
  // Where MuJoCo's ray found the surface (the two agree to 1e-13 m there, measured at 10^6 random
  // points of terrain, gully and a DEM world), its hit is kept to the bit: a start's height a
  // few 1e-14 m off sends the whole run elsewhere (the default run: 21 stops instead of 19).
  constexpr double kSameSurface_m = 1e-6;
  return std::abs(ray_top - surface) <= kSameSurface_m ? ray_top : surface;
}

// Highest terrain (plane / heightfield) surface under (x, y) [m], or NaN. `from_z` is above all.
double TerrainHeight(const mjModel* m, const mjData* d, const Eigen::Vector2d& xy, double from_z,
                     bool any_terrain, const mjtByte* groups) {
  const mjtNum pnt[3] = {xy.x(), xy.y(), from_z};
  const mjtNum down[3] = {0, 0, -1};
  double top = -std::numeric_limits<double>::infinity();
  if (!any_terrain) {  // worlds without planes or heightfields: the first static surface is ground
    int geom = -1;
    const double dist = mj_ray(m, d, pnt, down, groups, 1, -1, &geom);
    return dist >= 0 ? from_z - dist : std::nan("");
  }
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] == mjGEOM_PLANE) {
      const double dist = mju_rayGeom(d->geom_xpos + 3 * g, d->geom_xmat + 9 * g,
                                      m->geom_size + 3 * g, pnt, down, mjGEOM_PLANE);
      if (dist >= 0) top = std::max(top, from_z - dist);
    } else if (m->geom_type[g] == mjGEOM_HFIELD) {
      top = std::max(top, HfieldTop(m, d, g, xy, pnt, down));
    }
  }
  return std::isfinite(top) ? top : std::nan("");
}

// In a world without terrain geoms the first static surface from above is taken as ground. It is
// not, when it is the top of an object with more of the world under it (a roof on its pavement, a
// desk over the floor, a car on the road): the height from that top down to the next surface
// below the geom's bottom [m], or NaN when nothing lies under the geom (it is the ground itself).
double HeightAboveSurfaceBelow(const mjModel* m, const mjData* d, const Eigen::Vector2d& xy,
                               double from_z, const mjtByte* groups) {
  constexpr double kInside = 1e-6;  // [m] start just inside the geom, then just below it
  const mjtNum down[3] = {0, 0, -1};
  const mjtNum above[3] = {xy.x(), xy.y(), from_z};
  int geom = -1;
  const double to_top = mj_ray(m, d, above, down, groups, 1, -1, &geom);
  if (to_top < 0 || geom < 0) return std::nan("");
  const double top = from_z - to_top;
  // From inside its top, a ray leaves the geom through its bottom.
  const mjtNum inside[3] = {xy.x(), xy.y(), top - kInside};
  const double to_bottom = mju_rayGeom(d->geom_xpos + 3 * geom, d->geom_xmat + 9 * geom,
                                       m->geom_size + 3 * geom, inside, down, m->geom_type[geom]);
  if (to_bottom < 0) return std::nan("");  // one-sided or open: nothing to look under
  const mjtNum below[3] = {xy.x(), xy.y(), top - kInside - to_bottom - kInside};
  int under = -1;
  const double to_under = mj_ray(m, d, below, down, groups, 1, -1, &under);
  if (to_under < 0) return std::nan("");
  return top - (below[2] - to_under);
}

// Least-squares plane z = a + b (x - x0) + c (y - y0) through the ground samples, and the largest
// deviation of a sample from it [m].
struct GroundPlane {
  Eigen::Vector3d coeffs;  ///< a [m], b, c [1]
  double max_residual_m;
};
GroundPlane FitGroundPlane(const Eigen::Vector2d& origin, const std::vector<Eigen::Vector2d>& xy,
                           const std::vector<double>& z) {
  Eigen::MatrixXd A(xy.size(), 3);
  Eigen::VectorXd b(xy.size());
  for (std::size_t i = 0; i < xy.size(); ++i) {
    A.row(i) << 1.0, xy[i].x() - origin.x(), xy[i].y() - origin.y();
    b[i] = z[i];
  }
  const Eigen::Vector3d plane = A.colPivHouseholderQr().solve(b);
  return {plane, (A * plane - b).cwiseAbs().maxCoeff()};
}

// Orientation that puts base_link's z on the plane normal and its x along `yaw_rad` in the plane.
Eigen::Quaterniond OnPlane(const Eigen::Vector3d& coeffs, double yaw_rad) {
  const Eigen::Vector3d n = Eigen::Vector3d(-coeffs[1], -coeffs[2], 1.0).normalized();
  const Eigen::Vector3d heading(std::cos(yaw_rad), std::sin(yaw_rad), 0.0);
  const Eigen::Vector3d x = (heading - heading.dot(n) * n).normalized();
  Eigen::Matrix3d R;
  R << x, n.cross(x), n;
  return Eigen::Quaterniond(R);
}

}  // namespace

Result<Eigen::Isometry3d> Simulation::PlaceRobot(double x_m, double y_m, double yaw_rad,
                                                 const PlacementConfig& config) {
  Release();  // a placed robot settles under full physics
  Impl& s = *impl_;
  const P3Params& p = params();
  if (world_.bounds) {
    const Eigen::Vector4d& b = *world_.bounds;
    if (x_m < b[0] || x_m > b[2] || y_m < b[1] || y_m > b[3]) {
      std::ostringstream os;
      os << "start " << Xy(x_m, y_m) << " is outside the world's pitchlab:bounds [" << b[0] << ", "
         << b[1] << ", " << b[2] << ", " << b[3] << "] of " << world_.path;
      return Fail(Error::Code::kInvalidArgument, os.str());
    }
  }

  // 1. Ground under every footprint sample, ignoring the robot's own geoms.
  mjtByte groups[mjNGROUP];
  for (int i = 0; i < mjNGROUP; ++i) groups[i] = i == kRobotGeomGroup ? 0 : 1;
  bool any_terrain = false;
  for (int g = 0; g < s.m->ngeom; ++g)
    any_terrain |= !s.InRobot(s.m->geom_bodyid[g]) && s.IsTerrain(g);
  const double from_z = s.m->stat.center[2] + 2.0 * s.m->stat.extent + 100.0;
  const std::vector<Eigen::Vector2d> samples = FootprintSamples(p, x_m, y_m, yaw_rad);
  std::vector<double> ground(samples.size());
  double ground_max = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < samples.size(); ++i) {
    ground[i] = TerrainHeight(s.m, s.d, samples[i], from_z, any_terrain, groups);
    if (std::isnan(ground[i])) {
      return Fail(Error::Code::kInvalidArgument,
                  "start " + Xy(x_m, y_m) + " is off the world: no ground under the footprint at " +
                      Xy(samples[i].x(), samples[i].y()) + " in " + world_.path);
    }
    ground_max = std::max(ground_max, ground[i]);
  }

  // 1b. The footprint must rest on one surface: samples may deviate from their best-fit plane by
  // at most a step (a slope is fine, the top of a wall or a curb edge is not).
  const GroundPlane plane = FitGroundPlane(Eigen::Vector2d(x_m, y_m), samples, ground);
  if (const double step = plane.max_residual_m; step > config.max_step_m) {
    return Fail(Error::Code::kInvalidArgument,
                "start " + Xy(x_m, y_m) + " is not on drivable ground: the surface under the " +
                    "footprint has a step of " + std::to_string(step) + " m (limit " +
                    std::to_string(config.max_step_m) + " m), e.g. on an obstacle or an edge");
  }

  // 2. Nothing may stand in the robot's volume above the ground (upward rays from step height).
  const double envelope_m =
      robot_.mount.t_base_mount_m.z() + robot_.mount.t_mount_laser_m.norm() + 0.1;
  // 2a. Without terrain geoms, the first surface from above may be an object's top: one higher
  // above the ground under it than the robot is tall (a roof, a table, a car) is no start; a
  // lower one (a ramp, a platform) the robot could have driven onto.
  for (std::size_t i = 0; i < samples.size() && !any_terrain; ++i) {
    if (const double height = HeightAboveSurfaceBelow(s.m, s.d, samples[i], from_z, groups);
        height > envelope_m) {
      return Fail(Error::Code::kInvalidArgument,
                  "start " + Xy(x_m, y_m) + " is on top of an obstacle, not on the ground: at " +
                      Xy(samples[i].x(), samples[i].y()) + " the surface is " +
                      std::to_string(height) + " m above the ground under it (a roof, a table)");
    }
  }
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const mjtNum pnt[3] = {samples[i].x(), samples[i].y(), ground[i] + config.max_step_m};
    const mjtNum up[3] = {0, 0, 1};
    int geom = -1;
    const double dist = mj_ray(s.m, s.d, pnt, up, groups, 1, -1, &geom);
    if (dist >= 0 && dist < envelope_m) {
      return Fail(Error::Code::kInvalidArgument,
                  "start " + Xy(x_m, y_m) + " is inside or under an obstacle: geom " +
                      s.GeomName(geom) + " is " + std::to_string(dist + config.max_step_m) +
                      " m above the ground at " + Xy(samples[i].x(), samples[i].y()));
    }
  }

  // 3. Put the robot just above the highest ground sample, at rest, and check for overlaps.
  mjtNum* q = s.d->qpos + s.root_qpos;
  // Lying on the fitted plane, so a slope start does not drop the robot onto one edge.
  const Eigen::Quaterniond attitude = OnPlane(plane.coeffs, yaw_rad);
  q[0] = x_m, q[1] = y_m;
  q[2] = plane.coeffs[0] + plane.max_residual_m + config.drop_height_m;
  q[3] = attitude.w(), q[4] = attitude.x(), q[5] = attitude.y(), q[6] = attitude.z();
  for (int j = 0; j < s.m->njnt; ++j) {
    if (!s.InRobot(s.m->jnt_bodyid[j])) continue;
    const int dofs = s.m->jnt_type[j] == mjJNT_FREE ? 6 : s.m->jnt_type[j] == mjJNT_BALL ? 3 : 1;
    for (int k = 0; k < dofs; ++k) s.d->qvel[s.m->jnt_dofadr[j] + k] = 0;
  }
  SetWheelSpeeds(0, 0);
  mj_forward(s.m, s.d);
  for (int c = 0; c < s.d->ncon; ++c) {
    const mjContact& con = s.d->contact[c];
    const bool r1 = s.InRobot(s.m->geom_bodyid[con.geom1]),
               r2 = s.InRobot(s.m->geom_bodyid[con.geom2]);
    if (r1 == r2) continue;
    const int other = r1 ? con.geom2 : con.geom1;
    if (!s.IsTerrain(other) && con.dist < -config.max_penetration_m) {
      return Fail(Error::Code::kInvalidArgument,
                  "start " + Xy(x_m, y_m) + " overlaps obstacle geom " + s.GeomName(other) +
                      " (penetration " + std::to_string(-con.dist) + " m)");
    }
  }

  // 4. Let it settle: speeds below the thresholds for settle_hold_s.
  const double t0 = time_s();
  double still_since = t0;
  while (true) {
    Step(1);
    const Eigen::Vector2d speeds = BaseSpeeds();
    if (speeds[0] > config.settle_speed_mps || speeds[1] > config.settle_rate_rps)
      still_since = time_s();
    if (time_s() - still_since >= config.settle_hold_s) break;
    if (time_s() - t0 > config.max_settle_s) {
      return Fail(Error::Code::kFailed, "robot placed at " + Xy(x_m, y_m) +
                                            " did not settle within " +
                                            std::to_string(config.max_settle_s) + " s");
    }
  }

  // 5. Upright enough to drive and scan?
  const Eigen::Isometry3d T = T_world_base();
  const double tilt_deg = std::acos(std::clamp(T.linear()(2, 2), -1.0, 1.0)) * 180.0 / M_PI;
  if (tilt_deg > config.max_tilt_deg) {
    return Fail(Error::Code::kFailed, "robot placed at " + Xy(x_m, y_m) + " settled tilted " +
                                          std::to_string(tilt_deg) + " deg (limit " +
                                          std::to_string(config.max_tilt_deg) + " deg)");
  }
  return T;
}

}  // namespace pitchlab::sim
