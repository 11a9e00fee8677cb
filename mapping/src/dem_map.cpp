// A DEM (ESRI ASCII grid + .prj, or a raster GDAL reads) as an ElevationMap (dem_io.hpp): placed
// exactly when its frame is local metres, else resampled onto a local east-north-up grid at its
// centre.

#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/TransverseMercator.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "gdal_raster_reader.hpp"
#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {
namespace {

using Kind = DemCrs::Kind;

// A DEM sample as a cell of one point at the cell's centre.
CellStats SampleCell(double z) {
  CellStats c;
  c.count = 1;
  c.mean_z = c.min_z = c.max_z = static_cast<float>(z);  // one point: no second extremes
  return c;
}

// Pitchlab's own georeferenced rasters (ProjectionWkt): a Transverse Mercator of scale 1 without
// false easting or northing, centred on the map's geodetic origin, which matches the map's ENU
// frame to well under a millimetre over kilometres. Its x, y are the map frame already.
bool IsLocalTransverseMercator(const DemCrs& crs) {
  return crs.kind == Kind::kTransverseMercator && crs.scale_factor == 1.0 &&
         crs.false_easting_m == 0.0 && crs.false_northing_m == 0.0;
}

// The file's coordinates <-> WGS84 latitude, longitude [deg].
class FileProjection {
 public:
  explicit FileProjection(const DemCrs& crs)
      : crs_(crs), tm_(crs.semi_major_m, 1.0 / crs.inverse_flattening, crs.scale_factor) {
    double x0 = 0;
    tm_.Forward(crs.central_meridian_deg, crs.latitude_of_origin_deg, crs.central_meridian_deg, x0,
                y_origin_);
  }
  void ToGeodetic(double x, double y, double* lat, double* lon) const {
    if (crs_.kind == Kind::kGeographic) {
      *lat = y, *lon = x;
      return;
    }
    tm_.Reverse(crs_.central_meridian_deg, x - crs_.false_easting_m,
                y - crs_.false_northing_m + y_origin_, *lat, *lon);
  }
  void FromGeodetic(double lat, double lon, double* x, double* y) const {
    if (crs_.kind == Kind::kGeographic) {
      *x = lon, *y = lat;
      return;
    }
    tm_.Forward(crs_.central_meridian_deg, lat, lon, *x, *y);
    *x += crs_.false_easting_m;
    *y += crs_.false_northing_m - y_origin_;
  }

 private:
  DemCrs crs_;
  GeographicLib::TransverseMercator tm_;
  double y_origin_ = 0;  // the projection's northing of its latitude of origin [m]
};

// Bilinear height at file coordinates (x, y): NaN outside the grid or next to a NODATA cell.
double SampleBilinear(const AsciiGrid& g, double x, double y) {
  const double col = (x - g.xll_corner) / g.cell_size - 0.5;
  const double row_south = (y - g.yll_corner) / g.cell_size_y - 0.5;  // 0 at the southern centres
  if (!(col >= -0.5 && col <= g.ncols - 0.5 && row_south >= -0.5 && row_south <= g.nrows - 0.5))
    return std::nan("");
  // Between the outer edge and the first centre the edge cell's value holds (clamped).
  const double c = std::clamp(col, 0.0, g.ncols - 1.0),
               r = std::clamp(row_south, 0.0, g.nrows - 1.0);
  const int c0 = static_cast<int>(std::floor(c)), r0 = static_cast<int>(std::floor(r));
  const int c1 = std::min(c0 + 1, g.ncols - 1), r1 = std::min(r0 + 1, g.nrows - 1);
  const double tc = c - c0, tr = r - r0;
  const auto at = [&](int rs, int cc) { return g.At(g.nrows - 1 - rs, cc); };  // rs from south
  double sum = 0;
  const int rows[2] = {r0, r1}, cols[2] = {c0, c1};
  const double wr[2] = {1 - tr, tr}, wc[2] = {1 - tc, tc};
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b) {
      const double w = wr[a] * wc[b];
      if (w == 0) continue;
      const double v = at(rows[a], cols[b]);
      if (std::isnan(v)) return v;
      sum += w * v;
    }
  return sum;
}

// Mean of the valid values, and how many there are.
std::pair<double, std::size_t> MeanOfValid(const AsciiGrid& g) {
  double sum = 0;
  std::size_t n = 0;
  for (double v : g.values)
    if (!std::isnan(v)) sum += v, ++n;
  return {n ? sum / n : 0.0, n};
}

// The grid cell for cell: x, y as in the file (local metres, or pitchlab's local TM).
ElevationMap PlaceExactly(const AsciiGrid& g, const std::optional<GeodeticOrigin>& origin) {
  const GridGeometry geometry{g.xll_corner, g.yll_corner, g.cell_size, g.ncols, g.nrows};
  ElevationMap map(geometry, origin);
  std::vector<CellStats> cells(geometry.cell_count());
  const double z0 = origin ? origin->height_m : 0.0;
  for (int row = 0; row < g.nrows; ++row)
    for (int col = 0; col < g.ncols; ++col) {
      const double v = g.At(row, col);
      if (!std::isnan(v)) cells[geometry.Linear({col, g.nrows - 1 - row})] = SampleCell(v - z0);
    }
  map.SetCells(std::move(cells));
  return map;
}

// The grid resampled onto a local ENU grid at its centre (see dem_io.hpp).
ElevationMap Resample(const AsciiGrid& g, const DemCrs& crs, double mean_height_m) {
  const FileProjection projection(crs);
  const double xc = g.xll_corner + 0.5 * g.ncols * g.cell_size;
  const double yc = g.yll_corner + 0.5 * g.nrows * g.cell_size_y;
  GeodeticOrigin origin;
  projection.ToGeodetic(xc, yc, &origin.latitude_deg, &origin.longitude_deg);
  origin.height_m = mean_height_m;
  const GeographicLib::LocalCartesian enu(origin.latitude_deg, origin.longitude_deg, mean_height_m);
  const auto to_enu = [&](double x, double y) {
    double lat = 0, lon = 0, e = 0, n = 0, u = 0;
    projection.ToGeodetic(x, y, &lat, &lon);
    enu.Forward(lat, lon, mean_height_m, e, n, u);
    return Eigen::Vector2d(e, n);
  };
  // Cell: the finer of the grid's two spacings at its centre, so no detail is lost either way.
  const double hx = 0.5 * g.cell_size, hy = 0.5 * g.cell_size_y;
  const double cell_m = std::min((to_enu(xc + hx, yc) - to_enu(xc - hx, yc)).norm(),
                                 (to_enu(xc, yc + hy) - to_enu(xc, yc - hy)).norm());
  // Extent: the grid's outline, 64 points an edge (a geographic grid's parallels curve in ENU).
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  const double w = g.ncols * g.cell_size, t = g.nrows * g.cell_size_y;
  for (int k = 0; k <= 64; ++k) {
    const double f = k / 64.0;
    for (const Eigen::Vector2d& p : {to_enu(g.xll_corner + f * w, g.yll_corner),
                                     to_enu(g.xll_corner + f * w, g.yll_corner + t),
                                     to_enu(g.xll_corner, g.yll_corner + f * t),
                                     to_enu(g.xll_corner + w, g.yll_corner + f * t)})
      lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  }
  const double nx = std::ceil((hi.x() - lo.x()) / cell_m),
               ny = std::ceil((hi.y() - lo.y()) / cell_m);
  const GridGeometry geometry =
      GridGeometry::FromArea(lo.x(), lo.y(), nx * cell_m, ny * cell_m, cell_m);  // throws >2^31
  ElevationMap map(geometry, origin);
  std::vector<CellStats> cells(geometry.cell_count());
  for (int j = 0; j < geometry.size_y; ++j)
    for (int i = 0; i < geometry.size_x; ++i) {
      const Eigen::Vector2d c = geometry.CenterOf({i, j});
      double lat = 0, lon = 0, up = 0, x = 0, y = 0;
      enu.Reverse(c.x(), c.y(), 0.0, lat, lon, up);
      projection.FromGeodetic(lat, lon, &x, &y);
      const double v = SampleBilinear(g, x, y);
      if (!std::isnan(v)) cells[geometry.Linear({i, j})] = SampleCell(v - mean_height_m);
    }
  map.SetCells(std::move(cells));
  return map;
}

bool IsEsriAsciiGrid(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".asc";
}

}  // namespace

// The grid and its coordinate system text: an ESRI grid by our own reader and its `.prj`, any
// other raster through GDAL with the coordinate system it carries.
Result<DemGrid> ReadDemGrid(const std::string& path) {
  DemGrid dem;
  if (IsEsriAsciiGrid(path)) {
    Result<AsciiGrid> grid = ReadAsciiGrid(path);
    if (!grid) return tl::make_unexpected(grid.error());
    dem.grid = std::move(*grid);
    dem.esri_ascii = true;
    dem.wkt_source = std::filesystem::path(path).replace_extension(".prj").string();
    if (std::ifstream in(dem.wkt_source); in) {
      std::stringstream text;
      text << in.rdbuf();
      dem.wkt = text.str();
    }
    return dem;
  }
  Result<internal::RasterDem> raster = internal::ReadGdalRaster(path);
  if (!raster) return tl::make_unexpected(raster.error());
  dem.grid = std::move(raster->grid);
  dem.wkt = std::move(raster->esri_wkt);
  dem.wkt_source = path;
  return dem;
}

Result<DemCrs> CrsOf(const DemGrid& dem) {
  if (dem.wkt.empty()) {
    DemCrs local;
    local.name = dem.esri_ascii ? "no .prj" : "no coordinate system";
    return local;
  }
  return ParsePrj(dem.wkt, dem.wkt_source);
}

Result<Dem> LoadDem(const std::string& path) {
  Result<DemGrid> read = ReadDemGrid(path);
  if (!read) return tl::make_unexpected(read.error());
  Result<DemCrs> crs = CrsOf(*read);
  if (!crs) return tl::make_unexpected(crs.error());
  Dem dem;
  dem.grid = std::move(read->grid);
  dem.crs = *crs;
  const AsciiGrid& g = dem.grid;
  const auto bad = [&](const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, path + ": " + why);
  };
  // A hundredth of a unit is a 1 cm cell in metres, 1.1 km in degrees: a grid that fine with
  // corners within longitude/latitude range is in degrees, whatever the missing .prj would say.
  const bool no_crs = dem.crs.name == "no .prj" || dem.crs.name == "no coordinate system";
  if (no_crs && g.cell_size < 0.01 && std::abs(g.xll_corner) <= 360 &&
      std::abs(g.yll_corner) <= 90) {
    return bad("cell size " + NumberText(g.cell_size) + " looks like degrees, but " +
               (dem.crs.name == "no .prj"
                    ? "no .prj says so: put the grid's .prj beside it (GEOGCS for "
                      "longitude/latitude)"
                    : "the file gives no coordinate system: set one (`gdal_edit.py -a_srs "
                      "EPSG:4326` for longitude/latitude)"));
  }
  if (dem.crs.kind == Kind::kGeographic &&
      !(std::abs(g.yll_corner) <= 90 && std::abs(g.yll_corner + g.nrows * g.cell_size_y) <= 90 &&
        std::abs(g.xll_corner) <= 360 && std::abs(g.xll_corner + g.ncols * g.cell_size) <= 360))
    return bad(
        "its .prj says longitude/latitude, but the grid reaches beyond +-90 deg latitude "
        "or +-360 deg longitude");
  const auto [mean, valid] = MeanOfValid(g);
  dem.nodata_cells = g.values.size() - valid;
  if (valid == 0) return bad("every cell is NODATA");
  try {
    const bool square = std::abs(g.cell_size - g.cell_size_y) <= 1e-6 * g.cell_size;
    if (!square && (dem.crs.kind == Kind::kLocal || IsLocalTransverseMercator(dem.crs))) {
      // Placed cell for cell, a grid takes the map's square cells; a georeferenced one is
      // resampled onto them, whatever its own.
      return bad("its cells are " + NumberText(g.cell_size) + " by " + NumberText(g.cell_size_y) +
                 " in a local frame: pitchlab places such a grid cell for cell on square cells");
    }
    if (dem.crs.kind == Kind::kLocal) {
      dem.map = PlaceExactly(g, std::nullopt);
    } else if (IsLocalTransverseMercator(dem.crs)) {
      dem.map = PlaceExactly(
          g, GeodeticOrigin{dem.crs.latitude_of_origin_deg, dem.crs.central_meridian_deg, mean});
    } else {
      dem.map = Resample(g, dem.crs, mean);
      dem.resampled = true;
    }
  } catch (const std::invalid_argument& e) {  // more cells than a map holds
    return bad(std::string("too large for a map: ") + e.what());
  }
  return dem;
}

Eigen::Vector2d Dem::FileToMap(const Eigen::Vector2d& file) const {
  if (!resampled) return file;
  const GeodeticOrigin& o = *map.geodetic_origin();
  const FileProjection projection(crs);
  const GeographicLib::LocalCartesian enu(o.latitude_deg, o.longitude_deg, o.height_m);
  double lat = 0, lon = 0, e = 0, n = 0, u = 0;
  projection.ToGeodetic(file.x(), file.y(), &lat, &lon);
  enu.Forward(lat, lon, o.height_m, e, n, u);
  return {e, n};
}

Eigen::Vector2d Dem::MapToFile(const Eigen::Vector2d& map_m) const {
  if (!resampled) return map_m;
  const GeodeticOrigin& o = *map.geodetic_origin();
  const FileProjection projection(crs);
  const GeographicLib::LocalCartesian enu(o.latitude_deg, o.longitude_deg, o.height_m);
  double lat = 0, lon = 0, up = 0, x = 0, y = 0;
  enu.Reverse(map_m.x(), map_m.y(), 0.0, lat, lon, up);
  projection.FromGeodetic(lat, lon, &x, &y);
  return {x, y};
}

}  // namespace pitchlab::mapping
