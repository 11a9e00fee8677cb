#include "dem_input.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "pitchlab/mapping/dem_io.hpp"

namespace pitchlab::worldgen {
namespace {

using Kind = mapping::DemCrs::Kind;

// The UTM zone a Transverse Mercator is, if it is one: scale 0.9996, false easting 500 km, false
// northing 0 (north) or 10000 km (south), latitude of origin 0 and a zone's central meridian
// (6 deg zones from -180, meridians at -177 + 6 (zone - 1)). Exact comparisons with a tolerance
// far below any difference between real projections (the next scale in use is 0.9999).
std::optional<worlds::DemPlacement> UtmZoneOf(const mapping::DemCrs& crs) {
  const auto near = [](double a, double b, double tol) { return std::abs(a - b) <= tol; };
  if (!near(crs.scale_factor, 0.9996, 1e-9) || !near(crs.false_easting_m, 500000.0, 1e-3) ||
      !near(crs.latitude_of_origin_deg, 0.0, 1e-9)) {
    return std::nullopt;
  }
  const bool north = near(crs.false_northing_m, 0.0, 1e-3);
  if (!north && !near(crs.false_northing_m, 10000000.0, 1e-3)) return std::nullopt;
  const double zone = (crs.central_meridian_deg + 183.0) / 6.0;
  if (!near(zone, std::round(zone), 1e-9) || zone < 1 || zone > 60) return std::nullopt;
  return worlds::DemPlacement{worlds::DemCoordinates::kUtm, static_cast<int>(std::round(zone)),
                              north};
}

std::optional<worlds::DemPlacement> PlacementOf(const mapping::DemCrs& crs,
                                                const std::filesystem::path& path) {
  switch (crs.kind) {
    case Kind::kGeographic:
      return worlds::DemPlacement{worlds::DemCoordinates::kGeographic, 0, true};
    case Kind::kLocal:  // "no .prj" / "no coordinate system": the worlds library's guess decides
      if (crs.name == "no .prj" || crs.name == "no coordinate system") return std::nullopt;
      return worlds::DemPlacement{worlds::DemCoordinates::kLocal, 0, true};
    case Kind::kTransverseMercator:
      break;
  }
  if (const auto utm = UtmZoneOf(crs)) return utm;
  // pitchlab's own maps (elevation.asc + .prj): a tangent plane at the map's origin, metres.
  if (crs.scale_factor == 1.0 && crs.false_easting_m == 0.0 && crs.false_northing_m == 0.0) {
    return worlds::DemPlacement{worlds::DemCoordinates::kLocal, 0, true};
  }
  throw std::invalid_argument(
      path.string() + ": its coordinate system '" + crs.name +
      "' is a Transverse Mercator but not UTM; a world is placed from UTM, longitude/latitude or "
      "local metres: reproject the DEM to UTM (gdalwarp -t_srs EPSG:326NN, 327NN south) or give "
      "--local to read x, y as metres");
}

}  // namespace

DemInput ReadDemInput(const std::filesystem::path& path, bool placement_given) {
  Result<mapping::DemGrid> read = mapping::ReadDemGrid(path.string());
  if (!read) throw std::runtime_error(read.error().message);
  DemInput input;
  if (!placement_given) {
    Result<mapping::DemCrs> crs = mapping::CrsOf(*read);
    if (!crs)
      throw std::invalid_argument(crs.error().message +
                                  " (or give --utm-zone, --geographic or --local)");
    input.placement = PlacementOf(*crs, path);
  }
  mapping::AsciiGrid& g = read->grid;
  worlds::EsriGrid& grid = input.grid;
  grid.ncols = g.ncols;
  grid.nrows = g.nrows;
  grid.xll_corner = g.xll_corner;
  grid.yll_corner = g.yll_corner;
  grid.cell_size = g.cell_size;
  grid.cell_size_y = g.cell_size_y;
  grid.nodata_value = g.nodata_value;
  grid.values = std::move(g.values);
  return input;
}

}  // namespace pitchlab::worldgen
