#pragma once
// DEMs in the raster formats GDAL reads (GeoTIFF above all: SRTM, Copernicus, USGS 3DEP and most
// national DEMs are published as GeoTIFF), as the same AsciiGrid an ESRI grid is read into, with
// the raster's coordinate system as ESRI WKT for ParsePrj. GDAL stays inside this file's .cpp:
// nothing of it reaches a header.

#include <string>

#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping::internal {

/// A raster DEM as read: the grid (rows north to south, heights in metres, NaN where there is no
/// value) and its coordinate system.
struct RasterDem {
  AsciiGrid grid;
  /// The raster's coordinate system as ESRI WKT1 (what a `.prj` holds); empty when it has none.
  std::string esri_wkt;
  std::string driver;  ///< GDAL's name for the format ("GTiff", "AAIGrid", ...)
};

/// Reads band 1 of a single-band raster. Fails (kInvalidArgument; kNotFound when GDAL cannot open
/// it) naming `path` and what is wrong: not a raster GDAL reads, more than one band (an image, not
/// heights), no geotransform (nothing places the cells), a rotated grid (pitchlab reads north-up
/// grids), heights in a unit other than metres or feet.
[[nodiscard]] Result<RasterDem> ReadGdalRaster(const std::string& path);

}  // namespace pitchlab::mapping::internal
