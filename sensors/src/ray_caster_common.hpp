#pragma once
// Private helpers shared by the Embree and the mj_ray casters: which geoms a ray may hit.

#include <mujoco/mujoco.h>

#include <vector>

#include "pitchlab/sensors/ray_caster.hpp"

namespace pitchlab::sensors::detail {

/// Per geom, 1 when it lies in the subtree of `options.exclude_subtree_of_body` (0 otherwise; all 0
/// when that body is empty or absent from the model).
std::vector<char> ExcludedGeoms(const mjModel* model, const RayCasterOptions& options);

/// True when mj_ray (MuJoCo 2.2.2 `ray_eliminate`, geomgroup NULL, flg_static 1) never reports the
/// geom: its rgba alpha is 0 (no material) or its material's alpha is 0.
bool MjRaySkips(const mjModel* model, int geom);

/// True when the geom moves with the simulation: its body is not welded to the world (has a joint
/// on the path to the world) or is (welded to) a mocap body.
bool GeomMoves(const mjModel* model, int geom);

}  // namespace pitchlab::sensors::detail
