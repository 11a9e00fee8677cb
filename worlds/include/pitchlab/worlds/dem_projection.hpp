#pragma once

#include <optional>

#include "pitchlab/worlds/esri_grid.hpp"
#include "pitchlab/worlds/height_grid.hpp"
#include "pitchlab/worlds/world_metadata.hpp"

namespace pitchlab::worlds {

/// How a DEM's x, y are to be read.
enum class DemCoordinates {
  kLocal,       ///< metres in an arbitrary local frame (no geodetic placement)
  kUtm,         ///< UTM easting/northing [m] in `utm_zone`, `northern_hemisphere`
  kGeographic,  ///< WGS84 longitude (x) and latitude (y) [deg]
};

/// Where a DEM sits on the Earth.
struct DemPlacement {
  DemCoordinates coordinates = DemCoordinates::kLocal;  ///< how x, y are read
  int utm_zone = 0;                                     ///< 1..60, for kUtm
  bool northern_hemisphere = true;                      ///< for kUtm
};

/// A DEM resampled onto a regular metric grid in a local ENU frame (x east, y north, z up) whose
/// origin is the centre of the DEM's valid rectangle at its height.
struct ProjectedDem {
  HeightGrid grid;                               ///< heights relative to the origin's height [m]
  std::optional<GeodeticPoint> geodetic_origin;  ///< absent for kLocal
  double origin_height_m = 0.0;                  ///< DEM height at the local origin [m]
};

/// Parses "13N" / "13S" (zone 1..60 and hemisphere) into a UTM placement; throws
/// std::invalid_argument naming the text otherwise.
DemPlacement ParseUtmZone(const std::string& text);

/// Crops `dem` to its largest axis-aligned rectangle free of NODATA, projects it (UTM or lon/lat
/// through WGS84 to a LocalCartesian ENU frame) and resamples it by bicubic interpolation onto a
/// grid of `cell_m` spacing inscribed in the projected rectangle. Throws std::invalid_argument when
/// the DEM has fewer than 2 x 2 valid cells, cell_m <= 0, or the result would exceed
/// `max_vertices` (the message names the smallest workable cell).
ProjectedDem ProjectDem(const EsriGrid& dem, const DemPlacement& placement, double cell_m,
                        long max_vertices = 16'000'000);

}  // namespace pitchlab::worlds
