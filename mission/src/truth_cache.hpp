#pragma once
// The true surface of a simulated world, kept between runs: every run of a sweep over seeds of
// one world computes the same ground truth (the world as placed, ray cast from above on the map's
// grid: 0.5-0.8 s of CPU on urban and terrain), so the first run leaves it in a folder and the
// others read it back. A file is named by what the truth depends on, so it is never stale.

#include <filesystem>
#include <optional>
#include <string>

#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/sensors/ray_caster.hpp"
#include "pitchlab/sensors/result.hpp"

struct mjModel_;
struct mjData_;

namespace pitchlab::mission {

/// The cache file in `dir` for the ground truth that a caster made with `caster` casts in `model`
/// as `data` places it, over `area`, as this executable computes it: "truth-<16 hex digits>.plem",
/// the digits an FNV-1a 64 hash of the geoms the caster sees (sensors::VisibleGeoms: type, size,
/// mesh or heightfield, pose as placed), the grid, and this executable's size and modification
/// time (another build may compute the truth otherwise). The robot is not among those geoms (its
/// mount error is drawn per seed), so runs of one world with different seeds share the file.
std::filesystem::path TruthCacheFile(const std::filesystem::path& dir, const mjModel_* model,
                                     const mjData_* data, const sensors::RayCasterOptions& caster,
                                     const mapping::GridGeometry& area);

/// The map cached in `file`, when there is one on `area`'s grid; nothing when the file is absent.
/// A file that does not read back whole (a bad hash, another grid) is an error naming it.
Result<std::optional<mapping::ElevationMap>> LoadCachedTruth(const std::filesystem::path& file,
                                                             const mapping::GridGeometry& area);

/// Writes `map` to `file`, creating its folder; a run of the same world writing it at the same
/// time is harmless (each writes a file of its own, then renames it over `file`).
Result<void> StoreCachedTruth(const mapping::ElevationMap& map, const std::filesystem::path& file);

}  // namespace pitchlab::mission
