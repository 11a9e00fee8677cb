// Reference caster: one mj_ray per ray, so its answers are MuJoCo's by construction.

#include <mujoco/mujoco.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pitchlab/sensors/ray_caster.hpp"
#include "ray_caster_common.hpp"

namespace pitchlab::sensors {
namespace {

struct ModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

// A private copy of the model in which every excluded geom is invisible (alpha 0, no material).
// mj_ray's own `ray_eliminate` then skips exactly those geoms: exact, unlike re-casting from just
// past an excluded hit (which needs an epsilon and can step over a touching geom), and one mj_ray
// per ray, unlike `bodyexclude`, which names a single body, not a subtree.
ModelPtr CopyWithExcludedGeomsInvisible(const mjModel* model, const RayCasterOptions& options) {
  ModelPtr copy(mj_copyModel(nullptr, model));
  if (!copy) throw std::runtime_error("MakeMujocoRayCaster: mj_copyModel failed");
  const std::vector<char> excluded = detail::ExcludedGeoms(model, options);
  for (int g = 0; g < copy->ngeom; ++g) {
    if (!excluded[g]) continue;
    copy->geom_matid[g] = -1;
    copy->geom_rgba[4 * g + 3] = 0.0f;
  }
  return copy;
}

class MujocoRayCaster final : public RayCaster {
 public:
  MujocoRayCaster(const mjModel* model, const mjData* data, const RayCasterOptions& options)
      : model_(CopyWithExcludedGeomsInvisible(model, options)), data_(data) {}

  void Cast(const float* origins, const float* directions, std::size_t n, float max_range_m,
            float* range_m, int* geom_id) const override {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const mjtNum pnt[3] = {origins[3 * i], origins[3 * i + 1], origins[3 * i + 2]};
      const mjtNum vec[3] = {directions[3 * i], directions[3 * i + 1], directions[3 * i + 2]};
      const mjtNum norm = mju_norm3(vec);
      int hit_geom = -1;
      // mj_ray calls mju_error on a null vector; a degenerate direction is reported as a miss.
      const mjtNum x =
          norm < mjMINVAL ? -1.0 : mj_ray(model_.get(), data_, pnt, vec, nullptr, 1, -1, &hit_geom);
      const mjtNum distance = x * norm;  // mj_ray's x is in units of |vec|
      const bool hit = x >= 0.0 && distance <= max_range_m;
      range_m[i] = hit ? static_cast<float>(distance) : kInf;
      if (geom_id != nullptr) geom_id[i] = hit ? hit_geom : -1;
    }
  }

  // mj_ray reads the poses from mjData at every call: nothing to refresh.
  void Refresh() override {}

 private:
  ModelPtr model_;
  const mjData* data_;
};

// MuJoCo 2.2.2's mj_rayHfield reads the profile of a heightfield's side walls normal to x at
// data[row * nrow + col] instead of data[row * ncol + col] (engine_ray.c, "check viable sides of
// top box"): with more rows than columns that reads past the field, by up to (nrow - 1)(nrow -
// ncol) heights (the gully's 900 x 134: 2.7 MB), for every ray that meets such a wall. Those rays
// read garbage, and where the read leaves the mapped heap the process dies (a test's scan of the
// gully crashed inside mj_rayHfield). A field that mj_ray would read past is refused, naming it.
void CheckHeightfieldsMjRayCanRead(const mjModel* model, const RayCasterOptions& options) {
  const std::vector<char> excluded = detail::ExcludedGeoms(model, options);
  for (int g = 0; g < model->ngeom; ++g) {
    if (excluded[g] || model->geom_type[g] != mjGEOM_HFIELD) continue;
    const int h = model->geom_dataid[g];
    const int nrow = model->hfield_nrow[h], ncol = model->hfield_ncol[h];
    if (nrow <= ncol) continue;
    const char* name = model->names + model->name_hfieldadr[h];
    throw std::runtime_error(
        "the MuJoCo ray caster cannot cast on heightfield '" + std::string(name) + "' (" +
        std::to_string(nrow) + " rows x " + std::to_string(ncol) +
        " columns): MuJoCo 2.2.2's mj_ray reads past a heightfield with more rows than columns; "
        "use the Embree caster (the default)");
  }
}

}  // namespace

std::unique_ptr<RayCaster> MakeMujocoRayCaster(const mjModel_* model, const mjData_* data,
                                               const RayCasterOptions& options) {
  if (model == nullptr || data == nullptr) {
    throw std::runtime_error("MakeMujocoRayCaster: model and data must not be null");
  }
  CheckHeightfieldsMjRayCanRead(model, options);
  return std::make_unique<MujocoRayCaster>(model, data, options);
}

}  // namespace pitchlab::sensors
