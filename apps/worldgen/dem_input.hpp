#pragma once
// pitchlab_worldgen's DEM input: any DEM pitchlab reads (an ESRI grid with its .prj, a GeoTIFF or
// another raster GDAL reads), as the worlds library's grid and the placement its coordinate
// system gives. It reads through mapping's DEM reader, which `pitchlab plan` uses: a world and a
// plan built from one file read it alike. An app may use every module; the worlds library may not.

#include <filesystem>
#include <optional>

#include "pitchlab/worlds/dem_projection.hpp"
#include "pitchlab/worlds/esri_grid.hpp"

namespace pitchlab::worldgen {

/// A DEM read for a world.
struct DemInput {
  worlds::EsriGrid grid;
  /// From the file's coordinate system: longitude/latitude, UTM (a Transverse Mercator with
  /// UTM's scale, false easting and northing and a zone's meridian), local metres (LOCAL_CS, or
  /// pitchlab's own maps' tangent Transverse Mercator). Absent when the file has none.
  std::optional<worlds::DemPlacement> placement;
};

/// Reads `path`. Throws std::runtime_error naming the file and the problem (as `pitchlab plan`
/// says it), and std::invalid_argument for a coordinate system a world cannot be placed in (a
/// Transverse Mercator that is not UTM, a projection pitchlab does not take) unless
/// `placement_given` (the command line says how to read x, y; the file's own system is not read).
DemInput ReadDemInput(const std::filesystem::path& path, bool placement_given);

}  // namespace pitchlab::worldgen
