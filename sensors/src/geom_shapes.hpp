#pragma once
// Private geometry of MuJoCo geoms for the Embree caster: exact ray tests for the quadrics (and the
// one-sided plane), triangles for boxes, meshes and heightfields. Matches MuJoCo 2.2.2's
// engine_ray.c surface by surface, so Embree and mj_ray agree to float precision.

#include <mujoco/mujoco.h>

#include <vector>

namespace pitchlab::sensors::detail {

/// Infinite MuJoCo planes (size x or y <= 0) are clipped to this half-extent [m]: a ray from within
/// (kInfinitePlaneHalfExtent_m - max range) of the plane's origin sees the same as mj_ray.
inline constexpr double kInfinitePlaneHalfExtent_m = 1.0e4;

/// A geom traced analytically (plane, sphere, capsule, ellipsoid, cylinder), posed in its parent
/// frame: the world for static geoms, the geom frame itself (identity) inside an instance.
struct AnalyticShape {
  int type = mjGEOM_SPHERE;                     ///< mjtGeom
  int geom = -1;                                ///< MuJoCo geom id
  double size[3] = {0, 0, 0};                   ///< MuJoCo geom_size [m]
  double pos[3] = {0, 0, 0};                    ///< geom origin in the parent frame [m]
  double mat[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major rotation parent <- geom
};

/// True for the types AnalyticShape handles.
bool IsAnalytic(int geom_type);

/// Distance along `dir` (units of |dir|) to the nearest surface point in [t_min, t_max], or a
/// negative value when there is none. Same surfaces as mj_ray: the plane is seen from its +z side
/// only, a ray starting inside a solid hits its inside.
double IntersectShape(const AnalyticShape& shape, const double org[3], const double dir[3],
                      double t_min, double t_max);

/// Axis-aligned bounds of the shape in its parent frame [m], slightly padded (conservative).
void ShapeBounds(const AnalyticShape& shape, float lower[3], float upper[3]);

/// Triangles of several geoms in one frame; `geom_of_triangle[i]` is triangle i's MuJoCo geom.
struct TriangleSoup {
  std::vector<float> vertices;        ///< x y z per vertex [m]
  std::vector<unsigned> indices;      ///< 3 vertex indices per triangle
  std::vector<int> geom_of_triangle;  ///< MuJoCo geom id per triangle
};

/// Appends the box, mesh or heightfield geom `geom`, posed by (pos, row-major mat) into the soup's
/// frame. Heightfields follow mj_rayHfield: the same diagonal per cell, side walls following the
/// edge profile and a bottom at -size[3]. Throws std::runtime_error for any other type.
void AppendTriangles(const mjModel* model, int geom, const double pos[3], const double mat[9],
                     TriangleSoup* soup);

}  // namespace pitchlab::sensors::detail
