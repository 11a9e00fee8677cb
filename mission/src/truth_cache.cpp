#include "truth_cache.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <system_error>
#include <vector>

#include <mujoco/mujoco.h>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/sensors/fnv1a.hpp"

namespace pitchlab::mission {

std::filesystem::path TruthCacheFile(const std::filesystem::path& dir, const mjModel* m,
                                     const mjData* d, const sensors::RayCasterOptions& caster,
                                     const mapping::GridGeometry& area) {
  sensors::Fnv1a64 hash;
  // What the truth's ray caster sees, posed as placed: not the robot (its mount error is drawn
  // per seed), nor what mj_ray skips as invisible.
  for (const int g : sensors::VisibleGeoms(m, caster)) {
    hash.AddValue(g);
    hash.AddValue(m->geom_type[g]);
    hash.AddValue(m->geom_dataid[g]);
    hash.Add(m->geom_size + 3 * g, 3 * sizeof(mjtNum));
    hash.Add(d->geom_xpos + 3 * g, 3 * sizeof(mjtNum));
    hash.Add(d->geom_xmat + 9 * g, 9 * sizeof(mjtNum));
  }
  hash.Add(m->hfield_size, 4 * sizeof(mjtNum) * static_cast<std::size_t>(m->nhfield));
  hash.Add(m->hfield_nrow, sizeof(int) * static_cast<std::size_t>(m->nhfield));
  hash.Add(m->hfield_ncol, sizeof(int) * static_cast<std::size_t>(m->nhfield));
  hash.Add(m->hfield_data, sizeof(float) * static_cast<std::size_t>(m->nhfielddata));
  hash.Add(m->mesh_vertadr, sizeof(int) * static_cast<std::size_t>(m->nmesh));
  hash.Add(m->mesh_faceadr, sizeof(int) * static_cast<std::size_t>(m->nmesh));
  hash.Add(m->mesh_vert, 3 * sizeof(float) * static_cast<std::size_t>(m->nmeshvert));
  hash.Add(m->mesh_face, 3 * sizeof(int) * static_cast<std::size_t>(m->nmeshface));
  hash.AddValue(area.x_min_m);
  hash.AddValue(area.y_min_m);
  hash.AddValue(area.cell_m);
  hash.AddValue(area.size_x);
  hash.AddValue(area.size_y);
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const auto size = ec ? 0 : std::filesystem::file_size(exe, ec);
  const auto time = ec ? 0 : std::filesystem::last_write_time(exe, ec).time_since_epoch().count();
  hash.AddValue(size);
  hash.AddValue(time);
  char name[40];
  std::snprintf(name, sizeof name, "truth-%016llx.plem",
                static_cast<unsigned long long>(hash.value()));
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
