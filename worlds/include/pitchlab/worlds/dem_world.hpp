#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "pitchlab/worlds/dem_projection.hpp"

namespace pitchlab::worlds {

/// A heightfield world built from a user's DEM (ESRI ASCII grid, or a grid read by the caller).
struct DemWorldConfig {
  std::filesystem::path dem_path;            ///< the .asc file; with `grid`, only its name
  /// The DEM already read (a GeoTIFF, through mapping's ReadDemGrid in pitchlab_worldgen);
  /// absent: dem_path is read as an ESRI ASCII grid.
  std::optional<EsriGrid> grid;
  /// The part of the DEM the world is built of, in the DEM's own coordinates (CropToArea);
  /// absent: all of it.
  std::optional<GridArea> area;
  std::optional<DemPlacement> placement;     ///< absent: lon/lat if a .prj says GEOGCS, else local
  double cell_m = 0.2;                       ///< output vertex spacing [m]
  std::optional<std::uint64_t> relief_seed;  ///< add seeded rocks and cracks when given
  std::string description;                   ///< empty: derived from the file name
  /// The default run's goal in the world frame [m]; must lie within the world's bounds. Absent:
  /// the world names none (`pitchlab run` then needs --goal).
  std::optional<GoalPoint> default_goal;
};

/// A DEM world before it is written: the surface, its metadata and how the DEM was placed.
struct DemWorld {
  HeightGrid grid;         ///< surface heights in the local ENU frame [m]
  WorldMetadata metadata;  ///< description, geodetic origin, bounds, flattest start
  DemPlacement placement;  ///< the coordinates used (given or detected)
  std::string comment;     ///< provenance line for the MJCF (file, placement, cell, seed)
};

/// Loads, places, resamples and (optionally) roughens the DEM. Throws std::runtime_error /
/// std::invalid_argument naming the DEM file and the problem; asks for explicit coordinates when a
/// grid without .prj has a cell size that looks like degrees.
DemWorld BuildDemWorld(const DemWorldConfig& config);

/// BuildDemWorld, then writes `out_xml` and its `<stem>_hfield.bin`; returns the placement used.
DemPlacement GenerateDemWorld(const DemWorldConfig& config, const std::filesystem::path& out_xml);

/// The `gully` world: west_bijou_gully.asc (3 m, UTM 13N) upsampled to `cell_m` with relief.
struct GullyConfig {
  std::filesystem::path dem_path;    ///< west_bijou_gully.asc
  double cell_m = 0.15;              ///< [m]
  std::uint64_t relief_seed = 3980;  ///< the default world's seed
  /// The default run's goal [m]: 10.8 m downhill from the start (-0.075, 45.825), 1.0 m lower,
  /// at the head of the gully. The floor beyond it is out of a P3-AT's reach: on the true map
  /// (0.1 m cells, the run's 19.3 deg slip limit and 8.9 cm step) nothing south of y = 34 m
  /// connects to the start but a strip against the east bound, since the head scarp between
  /// y = 28 and 36 m slopes 16-23 deg; this spot lies 1 m inside the connected ground on every
  /// side. Valid for the default cell_m and relief_seed only.
  GoalPoint default_goal{3.0, 35.5};
};

/// The DemWorldConfig of the gully world (UTM 13N, relief on).
DemWorldConfig GullyDemConfig(const GullyConfig& config);

/// Writes gully.xml and gully_hfield.bin into `out_dir`; returns the XML's path.
std::filesystem::path GenerateGullyWorld(const GullyConfig& config,
                                         const std::filesystem::path& out_dir);

}  // namespace pitchlab::worlds
