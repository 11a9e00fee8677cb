#pragma once

#include <cstddef>
#include <filesystem>
#include <istream>
#include <optional>
#include <string>
#include <vector>

namespace pitchlab::worlds {

/// A DEM grid as stored (an ESRI ASCII grid, or a raster read elsewhere into the same form): cell
/// values, rows north to south, in the file's own units (metres for projected or local grids,
/// degrees for geographic ones).
struct EsriGrid {
  int ncols = 0;                       ///< cells west to east
  int nrows = 0;                       ///< cells north to south
  double xll_corner = 0.0;             ///< western edge of the grid [file units]
  double yll_corner = 0.0;             ///< southern edge of the grid [file units]
  double cell_size = 0.0;              ///< west to east [file units]
  /// South to north [file units]: an ESRI grid's cells are square (cell_size); a GeoTIFF's may
  /// not be (Copernicus' 1 arc-second DEM beyond 50 deg latitude: 1.5" by 1").
  double cell_size_y = 0.0;
  std::optional<double> nodata_value;  ///< as written in the header, if any
  std::vector<double> values;          ///< row-major, row 0 northernmost; NODATA -> NaN

  /// Value of cell (row, col), row 0 northernmost; NaN for NODATA.
  double At(int row, int col) const { return values[static_cast<std::size_t>(row) * ncols + col]; }
  /// x of the centre of column `col` [file units].
  double ColumnX(double col) const { return xll_corner + (col + 0.5) * cell_size; }
  /// y of the centre of row `row` (row 0 northernmost) [file units].
  double RowY(double row) const { return yll_corner + (nrows - row - 0.5) * cell_size_y; }
};

/// A rectangle in a grid's own coordinates (metres, or longitude and latitude in degrees).
struct GridArea {
  double x_min = 0.0, y_min = 0.0, x_max = 0.0, y_max = 0.0;  ///< [file units]
};

/// The cells of `grid` whose centres lie in `area` (a DEM tile is kilometres wide, a robot's
/// world a few hundred metres). Throws std::invalid_argument naming the grid's extent when
/// fewer than 2 x 2 cells do.
EsriGrid CropToArea(const EsriGrid& grid, const GridArea& area);

/// Parses an ESRI ASCII grid: header keys in any order and case (ncols, nrows, xllcorner or
/// xllcenter, yllcorner or yllcenter, cellsize, optional NODATA_value), then nrows * ncols numbers.
/// Throws std::runtime_error naming `source_name`, the line and the problem (missing or duplicate
/// header field, bad value, non-numeric token, wrong value count).
EsriGrid ParseEsriGrid(std::istream& in, const std::string& source_name);

/// Loads an ESRI ASCII grid file; throws std::runtime_error as ParseEsriGrid, or when unreadable.
EsriGrid LoadEsriGrid(const std::filesystem::path& path);

/// True when a `.prj` beside `asc_path` (same stem) declares a geographic system (GEOGCS without
/// PROJCS), i.e. the grid is in lon/lat degrees.
bool HasGeographicPrj(const std::filesystem::path& asc_path);

}  // namespace pitchlab::worlds
