// Reference caster: one mj_ray per ray, so its answers are MuJoCo's by construction.

#include <mujoco/mujoco.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
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

}  // namespace

std::unique_ptr<RayCaster> MakeMujocoRayCaster(const mjModel_* model, const mjData_* data,
                                               const RayCasterOptions& options) {
  if (model == nullptr || data == nullptr) {
    throw std::runtime_error("MakeMujocoRayCaster: model and data must not be null");
  }
  return std::make_unique<MujocoRayCaster>(model, data, options);
}

}  // namespace pitchlab::sensors
