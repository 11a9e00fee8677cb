#include "truth_cache.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <system_error>
#include <vector>

#include <mujoco/mujoco.h>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/sim/robot_model.hpp"

namespace pitchlab::mission {
namespace {

// FNV-1a, 64 bit: a cache name, not a defence against someone forging a file.
struct Fnv64 {
  std::uint64_t h = 14695981039346656037ull;
  void Add(const void* bytes, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(bytes);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  template <typename T>
  void Add(const T& value) {
    Add(&value, sizeof value);
  }
};

}  // namespace

std::filesystem::path TruthCacheFile(const std::filesystem::path& dir, const mjModel* m,
                                     const mjData* d, const mapping::GridGeometry& area) {
  Fnv64 hash;
  // What the truth's ray caster sees: every geom outside the robot's subtree, posed as placed (the
  // robot itself, its mount error drawn per seed included, is not part of the truth).
  const int robot = mj_name2id(m, mjOBJ_BODY, sim::kRobotBody);
  for (int g = 0; g < m->ngeom; ++g) {
    bool on_robot = false;
    for (int b = m->geom_bodyid[g]; b > 0 && !on_robot; b = m->body_parentid[b]) {
      on_robot = b == robot;
    }
    if (on_robot) continue;
    hash.Add(g);
    hash.Add(m->geom_type[g]);
    hash.Add(m->geom_dataid[g]);
    hash.Add(m->geom_matid[g]);
    hash.Add(m->geom_rgba + 4 * g, 4 * sizeof(float));
    hash.Add(m->geom_size + 3 * g, 3 * sizeof(mjtNum));
    hash.Add(d->geom_xpos + 3 * g, 3 * sizeof(mjtNum));
    hash.Add(d->geom_xmat + 9 * g, 9 * sizeof(mjtNum));
  }
  hash.Add(m->mat_rgba, 4 * sizeof(float) * static_cast<std::size_t>(m->nmat));
  hash.Add(m->hfield_size, 4 * sizeof(mjtNum) * static_cast<std::size_t>(m->nhfield));
  hash.Add(m->hfield_nrow, sizeof(int) * static_cast<std::size_t>(m->nhfield));
  hash.Add(m->hfield_ncol, sizeof(int) * static_cast<std::size_t>(m->nhfield));
  hash.Add(m->hfield_data, sizeof(float) * static_cast<std::size_t>(m->nhfielddata));
  hash.Add(m->mesh_vertadr, sizeof(int) * static_cast<std::size_t>(m->nmesh));
  hash.Add(m->mesh_faceadr, sizeof(int) * static_cast<std::size_t>(m->nmesh));
  hash.Add(m->mesh_vert, 3 * sizeof(float) * static_cast<std::size_t>(m->nmeshvert));
  hash.Add(m->mesh_face, 3 * sizeof(int) * static_cast<std::size_t>(m->nmeshface));
  hash.Add(area.x_min_m);
  hash.Add(area.y_min_m);
  hash.Add(area.cell_m);
  hash.Add(area.size_x);
  hash.Add(area.size_y);
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto size = ec ? 0 : std::filesystem::file_size(exe, ec);
  const auto time = ec ? 0 : std::filesystem::last_write_time(exe, ec).time_since_epoch().count();
  hash.Add(size);
  hash.Add(time);
  char name[40];
  std::snprintf(name, sizeof name, "truth-%016llx.plem", static_cast<unsigned long long>(hash.h));
  return dir / name;
}

Result<std::optional<mapping::ElevationMap>> LoadCachedTruth(const std::filesystem::path& file,
                                                             const mapping::GridGeometry& area) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) return std::optional<mapping::ElevationMap>();
  Result<mapping::ElevationMap> map = mapping::LoadElevationMap(file.string());
  if (!map) return tl::make_unexpected(map.error());
  if (!map->geometry().SameAs(area)) {
    return Fail(Error::Code::kInvalidArgument,
                file.string() + ": a cached ground truth on another grid than the run's");
  }
  return std::optional<mapping::ElevationMap>(std::move(*map));
}

Result<void> StoreCachedTruth(const mapping::ElevationMap& map, const std::filesystem::path& file) {
  std::error_code ec;
  std::filesystem::create_directories(file.parent_path(), ec);
  if (ec) {
    return Fail(Error::Code::kFailed,
                file.parent_path().string() + ": cannot create the folder: " + ec.message());
  }
  const std::filesystem::path mine = file.string() + "." + std::to_string(::getpid()) + ".partial";
  if (Result<void> saved = mapping::SaveElevationMap(map, mine.string()); !saved) return saved;
  std::filesystem::rename(mine, file, ec);
  if (ec) {
    std::filesystem::remove(mine, ec);
    return Fail(Error::Code::kFailed, file.string() + ": cannot rename into place");
  }
  return {};
}

}  // namespace pitchlab::mission
