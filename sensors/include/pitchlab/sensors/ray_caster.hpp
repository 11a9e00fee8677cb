#pragma once
// Ray casting against a MuJoCo model's geoms: the virtual laser's physics. Two implementations:
// Embree (fast, the default) and MuJoCo's own mj_ray (the reference the tests compare against).

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

struct mjModel_;
struct mjData_;

namespace pitchlab::sensors {

/// Which geoms a caster sees.
struct RayCasterOptions {
  /// Every geom of this body and its descendants is invisible to the rays (the robot itself).
  /// Empty or absent from the model: nothing is excluded.
  std::string exclude_subtree_of_body = "robot";
  /// Embree only: trace consecutive rays as coherent 8/16-ray packets (fastest when consecutive
  /// rays are neighbouring beams of a line); false traces one rtcIntersect1 per ray (the
  /// benchmark's baseline). Same answers either way; ignored by the mj_ray caster.
  bool coherent_packets = true;
};

/// Casts batches of rays in the world frame against the model's geoms.
class RayCaster {
 public:
  virtual ~RayCaster() = default;
  /// Casts `n` rays; `origins` and unit `directions` hold 3 floats per ray (world frame [m]).
  /// Writes the distance to the first hit [m] (+inf when nothing within `max_range_m`) and the
  /// MuJoCo geom id hit (-1 on a miss); `geom_id` may be null.
  virtual void Cast(const float* origins, const float* directions, std::size_t n,
                    float max_range_m, float* range_m, int* geom_id) const = 0;
  /// Re-reads the poses of geoms on moving bodies from the mjData given at construction.
  virtual void Refresh() = 0;
  /// True when Cast reads nothing a stepping simulation writes and Refresh changes nothing (no
  /// visible geom moves): rays may then be cast on another thread while the physics steps.
  virtual bool Static() const { return false; }
};

/// Embree scene built from the model's planes, boxes, spheres, capsules, cylinders, ellipsoids,
/// meshes and heightfields. `data` must outlive the caster and hold a forward pass (mj_forward):
/// static geoms are posed from it once, here. Throws std::runtime_error on failure (Embree's
/// message included).
std::unique_ptr<RayCaster> MakeEmbreeRayCaster(const mjModel_* model, const mjData_* data,
                                               const RayCasterOptions& options = {});

/// Reference caster: one mj_ray call per ray. Same contract as the Embree caster; also throws
/// std::runtime_error naming a visible heightfield with more rows than columns, which MuJoCo
/// 2.2.2's mj_ray reads past (the gully's).
std::unique_ptr<RayCaster> MakeMujocoRayCaster(const mjModel_* model, const mjData_* data,
                                               const RayCasterOptions& options = {});

/// The geoms a caster made with `options` can hit, ascending: those outside the excluded subtree
/// that mj_ray does not skip as invisible. What a cache of a caster's answers must be keyed on.
std::vector<int> VisibleGeoms(const mjModel_* model, const RayCasterOptions& options = {});

}  // namespace pitchlab::sensors
