#include "ray_caster_common.hpp"

namespace pitchlab::sensors::detail {

std::vector<char> ExcludedGeoms(const mjModel* model, const RayCasterOptions& options) {
  std::vector<char> excluded(static_cast<std::size_t>(model->ngeom), 0);
  if (options.exclude_subtree_of_body.empty()) return excluded;
  const int root = mj_name2id(model, mjOBJ_BODY, options.exclude_subtree_of_body.c_str());
  if (root < 0) return excluded;
  // body_parentid[b] < b for every body but the world (MuJoCo orders bodies depth first), so one
  // forward pass marks every descendant of `root`.
  std::vector<char> in_subtree(static_cast<std::size_t>(model->nbody), 0);
  in_subtree[root] = 1;
  for (int b = root + 1; b < model->nbody; ++b) {
    in_subtree[b] = in_subtree[model->body_parentid[b]];
  }
  for (int g = 0; g < model->ngeom; ++g) excluded[g] = in_subtree[model->geom_bodyid[g]];
  return excluded;
}

bool MjRaySkips(const mjModel* model, int geom) {
  // MuJoCo 2.2.2 engine_ray.c ray_eliminate: invisible geoms (and invisible materials) are skipped.
  const int material = model->geom_matid[geom];
  if (material < 0) return model->geom_rgba[4 * geom + 3] == 0;
  return model->mat_rgba[4 * material + 3] == 0;
}

bool GeomMoves(const mjModel* model, int geom) {
  const int body = model->geom_bodyid[geom];
  if (model->body_weldid[body] != 0) return true;
  // A mocap body has no joint, so it may be welded to the world yet moved through mocap_pos.
  for (int b = body; b > 0; b = model->body_parentid[b]) {
    if (model->body_mocapid[b] >= 0) return true;
  }
  return false;
}

}  // namespace pitchlab::sensors::detail

namespace pitchlab::sensors {

std::vector<int> VisibleGeoms(const mjModel* model, const RayCasterOptions& options) {
  const std::vector<char> excluded = detail::ExcludedGeoms(model, options);
  std::vector<int> visible;
  for (int g = 0; g < model->ngeom; ++g) {
    if (!excluded[g] && !detail::MjRaySkips(model, g)) visible.push_back(g);
  }
  return visible;
}

}  // namespace pitchlab::sensors
