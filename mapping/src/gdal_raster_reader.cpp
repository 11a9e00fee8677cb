// Raster DEMs through GDAL (gdal_raster_reader.hpp).

#include "gdal_raster_reader.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping::internal {
namespace {

// GDAL reports errors to a handler that prints them by default; here they are kept quiet for the
// scope and the last one becomes part of our own message.
class QuietGdalErrors {
 public:
  QuietGdalErrors() {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
  }
  ~QuietGdalErrors() { CPLPopErrorHandler(); }
  QuietGdalErrors(const QuietGdalErrors&) = delete;
  QuietGdalErrors& operator=(const QuietGdalErrors&) = delete;
  // GDAL's last message, from ": ", without the file's name (ours leads the message already).
  static std::string Last(const std::string& path) {
    const char* m = CPLGetLastErrorMsg();
    std::string text = m ? m : "";
    for (const std::string& prefix : {path + ": ", path + ":"}) {
      while (text.rfind(prefix, 0) == 0) text.erase(0, prefix.size());
    }
    return text.empty() ? text : ": " + text;
  }
};

struct DatasetCloser {
  void operator()(void* d) const { GDALClose(static_cast<GDALDatasetH>(d)); }
};
using Dataset = std::unique_ptr<void, DatasetCloser>;

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Metres per unit of the band's heights, or 0 for a unit this reader does not know. GDAL leaves the
// unit empty when the file does not say (most DEMs: heights in metres).
double MetresPerHeightUnit(const std::string& unit) {
  const std::string u = Lower(unit);
  if (u.empty() || u == "m" || u == "metre" || u == "meter" || u == "metres" || u == "meters")
    return 1.0;
  if (u == "ft" || u == "foot" || u == "feet" || u == "international foot") return 0.3048;
  if (u == "us survey foot" || u == "ftus" || u == "us-ft") return 1200.0 / 3937.0;
  return 0.0;
}

// The dataset's coordinate system as ESRI WKT1, empty when it has none.
Result<std::string> EsriWkt(GDALDatasetH ds, const std::string& path) {
  OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
  if (srs == nullptr) return std::string();
  // Clone: morphing for ESRI must not change the dataset's own.
  std::unique_ptr<void, void (*)(OGRSpatialReferenceH)> copy(OSRClone(srs),
                                                             OSRDestroySpatialReference);
  char* wkt = nullptr;
  const char* const options[] = {"FORMAT=WKT1_ESRI", nullptr};
  if (OSRExportToWktEx(static_cast<OGRSpatialReferenceH>(copy.get()), &wkt, options) !=
          OGRERR_NONE ||
      wkt == nullptr) {
    CPLFree(wkt);
    return Fail(
        Error::Code::kInvalidArgument,
        path + ": its coordinate system has no ESRI WKT form" + QuietGdalErrors::Last(path));
  }
  std::string text(wkt);
  CPLFree(wkt);
  return text;
}

// Band 1's heights, rows north to south (flipped when the raster is stored south-up), in metres,
// NaN where the band has no value.
Result<std::vector<double>> Heights(GDALRasterBandH band, int nx, int ny, bool south_up,
                                    const std::string& path) {
  std::vector<double> v(static_cast<std::size_t>(nx) * ny);
  if (GDALRasterIO(band, GF_Read, 0, 0, nx, ny, v.data(), nx, ny, GDT_Float64, 0, 0) != CE_None) {
    return Fail(Error::Code::kInvalidArgument,
                path + ": its heights cannot be read" + QuietGdalErrors::Last(path));
  }
  int has_nodata = 0, has_scale = 0, has_offset = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  double scale = GDALGetRasterScale(band, &has_scale);
  double offset = GDALGetRasterOffset(band, &has_offset);
  if (!has_scale) scale = 1.0;
  if (!has_offset) offset = 0.0;
  const std::string unit = GDALGetRasterUnitType(band);
  const double metres = MetresPerHeightUnit(unit);
  if (metres == 0.0) {
    return Fail(Error::Code::kInvalidArgument,
                path + ": heights in '" + unit + "', not metres or feet");
  }
  for (double& h : v) {
    // GDAL compares no-data as the file stores it: a float band's -3.4e38 read as double matches.
    if ((has_nodata && (h == nodata || (std::isnan(nodata) && std::isnan(h)))) || !std::isfinite(h))
      h = std::nan("");
    else
      h = (h * scale + offset) * metres;
  }
  if (south_up) {
    for (int r = 0; r < ny / 2; ++r) {
      std::swap_ranges(v.begin() + static_cast<std::ptrdiff_t>(r) * nx,
                       v.begin() + static_cast<std::ptrdiff_t>(r + 1) * nx,
                       v.begin() + static_cast<std::ptrdiff_t>(ny - 1 - r) * nx);
    }
  }
  return v;
}

}  // namespace

Result<RasterDem> ReadGdalRaster(const std::string& path) {
  static std::once_flag registered;
  std::call_once(registered, [] { GDALAllRegister(); });
  const QuietGdalErrors quiet;
  const auto bad = [&](const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, path + ": " + why);
  };
  if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    std::fclose(f);
  } else {  // GDAL would only say that no driver recognised it
    return Fail(Error::Code::kNotFound, path + ": cannot be read: " + std::strerror(errno));
  }
  const Dataset ds(GDALOpenEx(path.c_str(),
                              GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR, nullptr,
                              nullptr, nullptr));
  if (!ds) {
    return Fail(Error::Code::kNotFound,
                path + ": cannot be read as a raster" + QuietGdalErrors::Last(path));
  }
  const GDALDatasetH d = static_cast<GDALDatasetH>(ds.get());
  RasterDem out;
  out.driver = GDALGetDriverShortName(GDALGetDatasetDriver(d));
  const int bands = GDALGetRasterCount(d);
  if (bands != 1) {
    return bad("holds " + std::to_string(bands) +
               " bands: a DEM holds one, the heights (is it an image?)");
  }
  double gt[6] = {0, 1, 0, 0, 0, 1};
  if (GDALGetGeoTransform(d, gt) != CE_None) {
    return bad(
        "has no geotransform: nothing gives its cells' size and place "
        "(a GeoTIFF, or an ESRI grid with its .prj, does)");
  }
  if (gt[2] != 0.0 || gt[4] != 0.0)
    return bad("its grid is rotated; pitchlab reads north-up grids");
  const double dx = gt[1], dy = std::abs(gt[5]);
  if (!(dx > 0) || !(dy > 0)) {
    return bad("its cells are " + NumberText(dx) + " by " + NumberText(gt[5]) + ": not a grid");
  }
  const int nx = GDALGetRasterXSize(d), ny = GDALGetRasterYSize(d);
  Result<std::vector<double>> heights = Heights(GDALGetRasterBand(d, 1), nx, ny, gt[5] > 0, path);
  if (!heights) return tl::make_unexpected(heights.error());
  Result<std::string> wkt = EsriWkt(d, path);
  if (!wkt) return tl::make_unexpected(wkt.error());
  AsciiGrid& g = out.grid;
  g.ncols = nx;
  g.nrows = ny;
  g.cell_size = dx;
  // Square to a millionth is square: a cell size in decimal degrees is rounded there.
  g.cell_size_y = std::abs(dx - dy) <= 1e-6 * dx ? dx : dy;
  g.xll_corner = gt[0];
  g.yll_corner = gt[5] < 0 ? gt[3] + ny * gt[5] : gt[3];
  g.values = std::move(*heights);
  out.esri_wkt = std::move(*wkt);
  return out;
}

}  // namespace pitchlab::mapping::internal
