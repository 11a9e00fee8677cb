#include "geom_shapes.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace pitchlab::sensors::detail {
namespace {

// Bounds are padded so float rounding of the box never clips a surface point [m].
constexpr double kBoundsPad_m = 1.0e-3;

// Nearest accepted candidate so far; t is a distance along the ray in units of |dir|.
struct Nearest {
  double t_min;
  double t_max;
  double best = -1.0;
  void Offer(double t) {
    if (t >= t_min && t <= t_max && (best < 0.0 || t < best)) best = t;
  }
};

// Roots of a*t^2 + 2*b*t + c = 0 (MuJoCo's ray_quad form); returns how many (0 or 2).
int QuadraticRoots(double a, double b, double c, double roots[2]) {
  if (a <= 0.0) return 0;
  const double det = b * b - a * c;
  if (det < 0.0) return 0;
  const double sqrt_det = std::sqrt(det);
  roots[0] = (-b - sqrt_det) / a;
  roots[1] = (-b + sqrt_det) / a;
  return 2;
}

// Ray in the shape's own frame: lp = mat' (org - pos), lv = mat' dir (MuJoCo's ray_map).
void ToShapeFrame(const AnalyticShape& s, const double org[3], const double dir[3], double lp[3],
                  double lv[3]) {
  const double d[3] = {org[0] - s.pos[0], org[1] - s.pos[1], org[2] - s.pos[2]};
  for (int i = 0; i < 3; ++i) {
    lp[i] = s.mat[i] * d[0] + s.mat[3 + i] * d[1] + s.mat[6 + i] * d[2];
    lv[i] = s.mat[i] * dir[0] + s.mat[3 + i] * dir[1] + s.mat[6 + i] * dir[2];
  }
}

// One-sided rectangle z = 0 seen from +z (ray_plane): infinite sizes clipped, see the header.
void OfferPlane(const double size[3], const double lp[3], const double lv[3], Nearest* n) {
  if (lv[2] >= 0.0) return;
  const double t = -lp[2] / lv[2];
  const double half_x = size[0] > 0.0 ? size[0] : kInfinitePlaneHalfExtent_m;
  const double half_y = size[1] > 0.0 ? size[1] : kInfinitePlaneHalfExtent_m;
  if (std::abs(lp[0] + t * lv[0]) <= half_x && std::abs(lp[1] + t * lv[1]) <= half_y) n->Offer(t);
}

// Sphere of `radius` centred at (0, 0, z_centre); keeps roots whose z satisfies `keep`
// (z_sign > 0: z >= z_centre, < 0: z <= z_centre, 0: all).
void OfferSphere(double radius, double z_centre, int z_sign, const double lp[3], const double lv[3],
                 Nearest* n) {
  const double p[3] = {lp[0], lp[1], lp[2] - z_centre};
  double roots[2];
  const int count = QuadraticRoots(
      lv[0] * lv[0] + lv[1] * lv[1] + lv[2] * lv[2], lv[0] * p[0] + lv[1] * p[1] + lv[2] * p[2],
      p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - radius * radius, roots);
  for (int i = 0; i < count; ++i) {
    const double z = p[2] + roots[i] * lv[2];
    if (z_sign * z >= 0.0) n->Offer(roots[i]);
  }
}

// Infinite cylinder x^2 + y^2 = r^2 clipped to |z| <= half_height (round side of cylinder,
// capsule).
void OfferRoundSide(double radius, double half_height, const double lp[3], const double lv[3],
                    Nearest* n) {
  double roots[2];
  const int count = QuadraticRoots(lv[0] * lv[0] + lv[1] * lv[1], lv[0] * lp[0] + lv[1] * lp[1],
                                   lp[0] * lp[0] + lp[1] * lp[1] - radius * radius, roots);
  for (int i = 0; i < count; ++i) {
    if (std::abs(lp[2] + roots[i] * lv[2]) <= half_height) n->Offer(roots[i]);
  }
}

// Flat discs z = +-half_height of a cylinder.
void OfferDiscs(double radius, double half_height, const double lp[3], const double lv[3],
                Nearest* n) {
  if (lv[2] == 0.0) return;
  for (const double z : {-half_height, half_height}) {
    const double t = (z - lp[2]) / lv[2];
    const double x = lp[0] + t * lv[0];
    const double y = lp[1] + t * lv[1];
    if (x * x + y * y <= radius * radius) n->Offer(t);
  }
}

void OfferEllipsoid(const double size[3], const double lp[3], const double lv[3], Nearest* n) {
  // Scale the axes to a unit sphere; t is unchanged by the scaling.
  const double p[3] = {lp[0] / size[0], lp[1] / size[1], lp[2] / size[2]};
  const double v[3] = {lv[0] / size[0], lv[1] / size[1], lv[2] / size[2]};
  double roots[2];
  const int count = QuadraticRoots(v[0] * v[0] + v[1] * v[1] + v[2] * v[2],
                                   v[0] * p[0] + v[1] * p[1] + v[2] * p[2],
                                   p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - 1.0, roots);
  for (int i = 0; i < count; ++i) n->Offer(roots[i]);
}

// Half-extents of the shape's local bounding box [m].
void LocalHalfExtents(const AnalyticShape& s, double half[3]) {
  switch (s.type) {
    case mjGEOM_PLANE:
      half[0] = s.size[0] > 0.0 ? s.size[0] : kInfinitePlaneHalfExtent_m;
      half[1] = s.size[1] > 0.0 ? s.size[1] : kInfinitePlaneHalfExtent_m;
      half[2] = 0.0;
      return;
    case mjGEOM_SPHERE:
      half[0] = half[1] = half[2] = s.size[0];
      return;
    case mjGEOM_CAPSULE:
      half[0] = half[1] = s.size[0];
      half[2] = s.size[1] + s.size[0];
      return;
    case mjGEOM_CYLINDER:
      half[0] = half[1] = s.size[0];
      half[2] = s.size[1];
      return;
    default:  // ellipsoid
      half[0] = s.size[0];
      half[1] = s.size[1];
      half[2] = s.size[2];
      return;
  }
}

// Appends vertex mat * local + pos; returns its index.
unsigned AddVertex(const double pos[3], const double mat[9], double x, double y, double z,
                   TriangleSoup* soup) {
  const auto index = static_cast<unsigned>(soup->vertices.size() / 3);
  for (int i = 0; i < 3; ++i) {
    soup->vertices.push_back(
        static_cast<float>(pos[i] + mat[3 * i] * x + mat[3 * i + 1] * y + mat[3 * i + 2] * z));
  }
  return index;
}

void AddTriangle(unsigned a, unsigned b, unsigned c, int geom, TriangleSoup* soup) {
  soup->indices.insert(soup->indices.end(), {a, b, c});
  soup->geom_of_triangle.push_back(geom);
}

void AppendBox(const mjModel* m, int g, const double pos[3], const double mat[9],
               TriangleSoup* soup) {
  const mjtNum* s = m->geom_size + 3 * g;
  unsigned v[8];  // corner i has sign bits (x: bit 0, y: bit 1, z: bit 2)
  for (int i = 0; i < 8; ++i) {
    v[i] = AddVertex(pos, mat, (i & 1) ? s[0] : -s[0], (i & 2) ? s[1] : -s[1],
                     (i & 4) ? s[2] : -s[2], soup);
  }
  constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
  for (const auto& f : kFaces) {
    AddTriangle(v[f[0]], v[f[1]], v[f[2]], g, soup);
    AddTriangle(v[f[0]], v[f[2]], v[f[3]], g, soup);
  }
}

// MuJoCo 2.2.2 compiles mesh vertices into the geom frame (re-centred, re-oriented): mj_rayMesh
// uses mesh_vert as is, so do we.
void AppendMesh(const mjModel* m, int g, const double pos[3], const double mat[9],
                TriangleSoup* soup) {
  const int mesh = m->geom_dataid[g];
  const float* vert = m->mesh_vert + 3 * m->mesh_vertadr[mesh];
  const int* face = m->mesh_face + 3 * m->mesh_faceadr[mesh];
  const auto first = static_cast<unsigned>(soup->vertices.size() / 3);
  for (int i = 0; i < m->mesh_vertnum[mesh]; ++i) {
    AddVertex(pos, mat, vert[3 * i], vert[3 * i + 1], vert[3 * i + 2], soup);
  }
  for (int f = 0; f < m->mesh_facenum[mesh]; ++f) {
    AddTriangle(first + face[3 * f], first + face[3 * f + 1], first + face[3 * f + 2], g, soup);
  }
}

// mj_rayHfield: vertex (r, c) at (c dx - sx, r dy - sy, data[r ncol + c] sz), data normalised to
// [0, 1] by the compiler; cell (r, c) split along (r, c)-(r+1, c+1). The solid below reaches down
// to -size[3] (the base box), its sides follow the edge profile.
void AppendHfield(const mjModel* m, int g, const double pos[3], const double mat[9],
                  TriangleSoup* soup) {
  const int h = m->geom_dataid[g];
  const int nrow = m->hfield_nrow[h];
  const int ncol = m->hfield_ncol[h];
  const mjtNum* size = m->hfield_size + 4 * h;
  const float* data = m->hfield_data + m->hfield_adr[h];
  const double dx = 2.0 * size[0] / (ncol - 1);
  const double dy = 2.0 * size[1] / (nrow - 1);
  const double base_z = -size[3];
  auto x_of = [&](int c) { return dx * c - size[0]; };
  auto y_of = [&](int r) { return dy * r - size[1]; };
  const auto first = static_cast<unsigned>(soup->vertices.size() / 3);
  for (int r = 0; r < nrow; ++r) {
    for (int c = 0; c < ncol; ++c)
      AddVertex(pos, mat, x_of(c), y_of(r), data[r * ncol + c] * size[2], soup);
  }
  auto top = [&](int r, int c) { return first + static_cast<unsigned>(r * ncol + c); };
  for (int r = 0; r + 1 < nrow; ++r) {
    for (int c = 0; c + 1 < ncol; ++c) {
      AddTriangle(top(r, c), top(r + 1, c + 1), top(r, c + 1), g, soup);
      AddTriangle(top(r, c), top(r + 1, c + 1), top(r + 1, c), g, soup);
    }
  }
  // Side walls: one quad per border segment, from the base up to the edge profile.
  auto wall = [&](int r0, int c0, int r1, int c1) {
    const unsigned b0 = AddVertex(pos, mat, x_of(c0), y_of(r0), base_z, soup);
    const unsigned b1 = AddVertex(pos, mat, x_of(c1), y_of(r1), base_z, soup);
    AddTriangle(top(r0, c0), top(r1, c1), b1, g, soup);
    AddTriangle(top(r0, c0), b1, b0, g, soup);
  };
  for (int c = 0; c + 1 < ncol; ++c) {
    wall(0, c, 0, c + 1);
    wall(nrow - 1, c, nrow - 1, c + 1);
  }
  for (int r = 0; r + 1 < nrow; ++r) {
    wall(r, 0, r + 1, 0);
    wall(r, ncol - 1, r + 1, ncol - 1);
  }
  const unsigned q0 = AddVertex(pos, mat, -size[0], -size[1], base_z, soup);
  const unsigned q1 = AddVertex(pos, mat, size[0], -size[1], base_z, soup);
  const unsigned q2 = AddVertex(pos, mat, size[0], size[1], base_z, soup);
  const unsigned q3 = AddVertex(pos, mat, -size[0], size[1], base_z, soup);
  AddTriangle(q0, q1, q2, g, soup);
  AddTriangle(q0, q2, q3, g, soup);
}

}  // namespace

bool IsAnalytic(int geom_type) {
  return geom_type == mjGEOM_PLANE || geom_type == mjGEOM_SPHERE || geom_type == mjGEOM_CAPSULE ||
         geom_type == mjGEOM_ELLIPSOID || geom_type == mjGEOM_CYLINDER;
}

double IntersectShape(const AnalyticShape& shape, const double org[3], const double dir[3],
                      double t_min, double t_max) {
  double lp[3], lv[3];
  ToShapeFrame(shape, org, dir, lp, lv);
  Nearest n{t_min, t_max};
  const double* s = shape.size;
  switch (shape.type) {
    case mjGEOM_PLANE:
      OfferPlane(s, lp, lv, &n);
      break;
    case mjGEOM_SPHERE:
      OfferSphere(s[0], 0.0, 0, lp, lv, &n);
      break;
    case mjGEOM_CAPSULE:  // round side, then the two hemispherical caps beyond it
      OfferRoundSide(s[0], s[1], lp, lv, &n);
      OfferSphere(s[0], s[1], 1, lp, lv, &n);
      OfferSphere(s[0], -s[1], -1, lp, lv, &n);
      break;
    case mjGEOM_CYLINDER:
      OfferRoundSide(s[0], s[1], lp, lv, &n);
      OfferDiscs(s[0], s[1], lp, lv, &n);
      break;
    case mjGEOM_ELLIPSOID:
      OfferEllipsoid(s, lp, lv, &n);
      break;
    default:
      break;
  }
  return n.best;
}

void ShapeBounds(const AnalyticShape& shape, float lower[3], float upper[3]) {
  double half[3];
  LocalHalfExtents(shape, half);
  for (int i = 0; i < 3; ++i) {
    // Extent of the rotated box along parent axis i: sum_j |mat_ij| half_j.
    const double extent = std::abs(shape.mat[3 * i]) * half[0] +
                          std::abs(shape.mat[3 * i + 1]) * half[1] +
                          std::abs(shape.mat[3 * i + 2]) * half[2];
    const double pad = kBoundsPad_m + 1.0e-6 * (std::abs(shape.pos[i]) + extent);
    lower[i] = static_cast<float>(shape.pos[i] - extent - pad);
    upper[i] = static_cast<float>(shape.pos[i] + extent + pad);
  }
}

void AppendTriangles(const mjModel* model, int geom, const double pos[3], const double mat[9],
                     TriangleSoup* soup) {
  switch (model->geom_type[geom]) {
    case mjGEOM_BOX:
      AppendBox(model, geom, pos, mat, soup);
      return;
    case mjGEOM_MESH:
      AppendMesh(model, geom, pos, mat, soup);
      return;
    case mjGEOM_HFIELD:
      AppendHfield(model, geom, pos, mat, soup);
      return;
    default:
      throw std::runtime_error("Embree ray caster: geom " + std::to_string(geom) + " has type " +
                               std::to_string(model->geom_type[geom]) +
                               ", which has no triangle form");
  }
}

}  // namespace pitchlab::sensors::detail
