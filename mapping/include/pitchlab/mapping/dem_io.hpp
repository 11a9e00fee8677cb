#pragma once
// Users' terrain: a digital elevation model (DEM), an ESRI ASCII grid with its `.prj` or a raster
// GDAL reads (a GeoTIFF, with the coordinate system it carries), read into an ElevationMap the
// planner takes like one built from scans.
//
// Frames. A grid without a `.prj`, or whose `.prj` is a LOCAL_CS, is metres in a local frame: the
// map frame is the file's own x, y, every cell read exactly as written. A georeferenced grid
// (`.prj` GEOGCS: longitude, latitude in degrees; PROJCS Transverse_Mercator, which UTM is) is
// resampled (bilinear) onto square cells of a local east-north-up frame at the grid's centre, the
// map's geodetic origin, at the finer of the grid's two cell spacings in metres; a Transverse
// Mercator with scale 1 and no false easting or northing (the `.prj` pitchlab's own maps carry)
// already is such a frame, centred on its own origin, and is read exactly. Heights keep their
// values: the geodetic origin's height is the mean of the valid cells, map z is the height above
// it (the ENU frame is a tangent plane: a point 50 m above it and 1.5 km away is 1 cm off its
// vertical). The datum is taken as WGS84 with the `.prj`'s ellipsoid (NAD83 and ETRS89 lie
// within 1-2 m of it, finer than any DEM cell).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// A DEM grid as stored: rows north to south, x, y and cells in the file's units.
struct AsciiGrid {
  int ncols = 0;                       ///< cells west to east [1]
  int nrows = 0;                       ///< cells north to south [1]
  double xll_corner = 0;               ///< western edge [file units]
  double yll_corner = 0;               ///< southern edge [file units]
  double cell_size = 0;                ///< west to east [file units]
  /// South to north [file units]: an ESRI grid's cells are square (cell_size); a raster's may not
  /// be (Copernicus' 1 arc-second DEM beyond 50 deg latitude: 1.5" by 1").
  double cell_size_y = 0;
  std::optional<double> nodata_value;  ///< as the header gives it
  std::vector<double> values;          ///< row-major, row 0 northernmost; NODATA -> NaN

  /// Value of (row, col), row 0 northernmost; NaN for NODATA.
  double At(int row, int col) const { return values[static_cast<std::size_t>(row) * ncols + col]; }
};

/// Reads an ESRI ASCII grid: header lines `key value` (ncols, nrows, xllcorner or xllcenter,
/// yllcorner or yllcenter, cellsize, optional NODATA_value; any order and case), then
/// nrows x ncols numbers. Fails (kInvalidArgument, kNotFound when unreadable) with
/// "FILE:LINE: what is wrong" (a missing, repeated or unknown header field, a non-positive size,
/// a token that is no finite number, too few or too many values).
[[nodiscard]] Result<AsciiGrid> ReadAsciiGrid(const std::string& path);

/// The coordinate system a `.prj` (ESRI WKT1) declares.
struct DemCrs {
  enum class Kind {
    kLocal,               ///< metres in a local frame (no `.prj`, or LOCAL_CS)
    kGeographic,          ///< GEOGCS: x longitude, y latitude [deg]
    kTransverseMercator,  ///< PROJCS with Transverse_Mercator (UTM among them) [m]
  };
  Kind kind = Kind::kLocal;
  std::string name;                           ///< the WKT's name, or "local" / "no .prj"
  double semi_major_m = 6378137.0;            ///< ellipsoid a [m] (WGS84's unless the .prj says)
  double inverse_flattening = 298.257223563;  ///< ellipsoid 1/f [1]
  double central_meridian_deg = 0;            ///< [deg]
  double latitude_of_origin_deg = 0;          ///< [deg]
  double scale_factor = 1;                    ///< [1]
  double false_easting_m = 0;                 ///< [m]
  double false_northing_m = 0;                ///< [m]
};

/// Parses `.prj` text. Fails (kInvalidArgument) naming `source` on WKT that is none of the kinds
/// above (another projection, a unit other than metre or degree), with the projection's name and
/// how to reproject.
[[nodiscard]] Result<DemCrs> ParsePrj(const std::string& wkt, const std::string& source);

/// A DEM file as stored, before it is placed: its grid and the coordinate system text that came
/// with it (what LoadDem reads, for users who place the grid themselves, such as a simulated
/// world built from it).
struct DemGrid {
  AsciiGrid grid;
  /// ESRI WKT1 (what a `.prj` holds): the `.prj` beside an `.asc`, or a raster's own coordinate
  /// system; empty when there is none.
  std::string wkt;
  std::string wkt_source;  ///< the `.prj`'s path or the raster's: where `wkt` came from
  bool esri_ascii = false;  ///< an `.asc` (its coordinate system is a `.prj`), not a GDAL raster
};

/// Reads a DEM's grid and coordinate system text as LoadDem does (an `.asc` and the `.prj` beside
/// it; any other file through GDAL), without parsing the text or placing the grid. Fails as
/// ReadAsciiGrid and on a raster GDAL cannot read or pitchlab cannot take (see LoadDem).
[[nodiscard]] Result<DemGrid> ReadDemGrid(const std::string& path);

/// The coordinate system of `dem`: ParsePrj of its text; without one kLocal, named "no .prj" for
/// an `.asc` and "no coordinate system" for a raster. Fails as ParsePrj.
[[nodiscard]] Result<DemCrs> CrsOf(const DemGrid& dem);

/// A DEM read as an elevation map (one point per cell at the cell's centre and height).
struct Dem {
  ElevationMap map;              ///< geodetic origin set when the grid is georeferenced
  DemCrs crs;                    ///< from the `.prj`, kLocal without one
  AsciiGrid grid;                ///< the file as read
  bool resampled = false;        ///< false: every cell is the file's cell, value for value
  std::size_t nodata_cells = 0;  ///< file cells without a value (unknown in the map) [1]

  /// The map-frame point [m] of a point in the file's coordinates (x, y [m] or lon, lat [deg]).
  Eigen::Vector2d FileToMap(const Eigen::Vector2d& file) const;
  /// The inverse of FileToMap.
  Eigen::Vector2d MapToFile(const Eigen::Vector2d& map_m) const;
};

/// Reads a DEM into a Dem (see the top of this file for frames): an `.asc` with the `.prj` beside
/// it (same stem), if any; any other file as a raster through GDAL (GeoTIFF, SRTM .hgt, .img,
/// .vrt, ...: band 1 of a single-band, north-up raster of square cells, heights in metres or
/// feet), with the coordinate system it carries (none: local metres). Fails (kInvalidArgument;
/// kNotFound for a file that cannot be opened) as ReadAsciiGrid and ParsePrj, on a raster GDAL
/// cannot read or pitchlab cannot take (several bands, no geotransform, rotated or non-square
/// cells, another height unit), on a grid without a coordinate system whose cell size looks like
/// degrees (below 0.01 with corners within lon/lat range), on a grid with no valid cell, or one
/// too large for a map (more than 2^31 cells).
[[nodiscard]] Result<Dem> LoadDem(const std::string& path);

}  // namespace pitchlab::mapping
