// Raster DEMs through GDAL (gdal_raster_reader.hpp).

#include "gdal_raster_reader.hpp"

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_vsi.h>
#include <dlfcn.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "pitchlab/mapping/physical_memory.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping::internal {
namespace {

// GDAL's C API, loaded the first time a raster is read. Linked, libgdal and the ~100 libraries
// it needs load with every pitchlab process (measured: `pitchlab --help` 0.12 -> 0.23 s, 47 ->
// 146 shared libraries; each run of a sweep is a process), while few processes read a raster.
// The headers give the types; the library is the one the build found (PITCHLAB_GDAL_SONAME).
struct GdalApi {
  decltype(&::GDALAllRegister) AllRegister = nullptr;
  decltype(&::GDALOpenEx) OpenEx = nullptr;
  decltype(&::GDALClose) Close = nullptr;
  decltype(&::GDALGetDatasetDriver) GetDatasetDriver = nullptr;
  decltype(&::GDALGetDriverShortName) GetDriverShortName = nullptr;
  decltype(&::GDALGetRasterCount) GetRasterCount = nullptr;
  decltype(&::GDALGetGeoTransform) GetGeoTransform = nullptr;
  decltype(&::GDALGetRasterXSize) GetRasterXSize = nullptr;
  decltype(&::GDALGetRasterYSize) GetRasterYSize = nullptr;
  decltype(&::GDALGetRasterBand) GetRasterBand = nullptr;
  decltype(&::GDALRasterIO) RasterIO = nullptr;
  decltype(&::GDALGetRasterNoDataValue) GetRasterNoDataValue = nullptr;
  decltype(&::GDALGetRasterScale) GetRasterScale = nullptr;
  decltype(&::GDALGetRasterOffset) GetRasterOffset = nullptr;
  decltype(&::GDALGetRasterUnitType) GetRasterUnitType = nullptr;
  decltype(&::GDALGetSpatialRef) GetSpatialRef = nullptr;
  decltype(&::OSRClone) SrsClone = nullptr;
  decltype(&::OSRDestroySpatialReference) SrsDestroy = nullptr;
  decltype(&::OSRExportToWktEx) SrsExportToWktEx = nullptr;
  decltype(&::VSIFree) Free = nullptr;
  decltype(&::CPLPushErrorHandler) PushErrorHandler = nullptr;
  decltype(&::CPLPopErrorHandler) PopErrorHandler = nullptr;
  decltype(&::CPLQuietErrorHandler) QuietErrorHandler = nullptr;
  decltype(&::CPLErrorReset) ErrorReset = nullptr;
  decltype(&::CPLGetLastErrorMsg) GetLastErrorMsg = nullptr;
  std::string missing;  ///< why GDAL could not be loaded; empty when it was
};

GdalApi LoadGdal() {
  GdalApi api;
  void* lib = ::dlopen(PITCHLAB_GDAL_SONAME, RTLD_NOW | RTLD_LOCAL);  // kept for the process
  if (lib == nullptr) {
    api.missing = std::string("GDAL is not installed (") + ::dlerror() + ")";
    return api;
  }
  const auto bind = [&](auto& f, const char* name) {
    f = reinterpret_cast<std::remove_reference_t<decltype(f)>>(::dlsym(lib, name));
    if (f == nullptr && api.missing.empty()) api.missing = std::string("GDAL has no ") + name;
  };
  bind(api.AllRegister, "GDALAllRegister");
  bind(api.OpenEx, "GDALOpenEx");
  bind(api.Close, "GDALClose");
  bind(api.GetDatasetDriver, "GDALGetDatasetDriver");
  bind(api.GetDriverShortName, "GDALGetDriverShortName");
  bind(api.GetRasterCount, "GDALGetRasterCount");
  bind(api.GetGeoTransform, "GDALGetGeoTransform");
  bind(api.GetRasterXSize, "GDALGetRasterXSize");
  bind(api.GetRasterYSize, "GDALGetRasterYSize");
  bind(api.GetRasterBand, "GDALGetRasterBand");
  bind(api.RasterIO, "GDALRasterIO");
  bind(api.GetRasterNoDataValue, "GDALGetRasterNoDataValue");
  bind(api.GetRasterScale, "GDALGetRasterScale");
  bind(api.GetRasterOffset, "GDALGetRasterOffset");
  bind(api.GetRasterUnitType, "GDALGetRasterUnitType");
  bind(api.GetSpatialRef, "GDALGetSpatialRef");
  bind(api.SrsClone, "OSRClone");
  bind(api.SrsDestroy, "OSRDestroySpatialReference");
  bind(api.SrsExportToWktEx, "OSRExportToWktEx");
  bind(api.Free, "VSIFree");
  bind(api.PushErrorHandler, "CPLPushErrorHandler");
  bind(api.PopErrorHandler, "CPLPopErrorHandler");
  bind(api.QuietErrorHandler, "CPLQuietErrorHandler");
  bind(api.ErrorReset, "CPLErrorReset");
  bind(api.GetLastErrorMsg, "CPLGetLastErrorMsg");
  if (api.missing.empty()) api.AllRegister();
  return api;
}

// Loaded and its drivers registered once, on first use.
const GdalApi& Gdal() {
  static const GdalApi api = LoadGdal();
  return api;
}

// GDAL reports errors to a handler that prints them by default; here they are kept quiet for the
// scope and the last one becomes part of our own message.
class QuietGdalErrors {
 public:
  QuietGdalErrors() {
    Gdal().PushErrorHandler(Gdal().QuietErrorHandler);
    Gdal().ErrorReset();
  }
  ~QuietGdalErrors() { Gdal().PopErrorHandler(); }
  QuietGdalErrors(const QuietGdalErrors&) = delete;
  QuietGdalErrors& operator=(const QuietGdalErrors&) = delete;
  // GDAL's last message, from ": ", without the file's name (ours leads the message already).
  static std::string Last(const std::string& path) {
    const char* m = Gdal().GetLastErrorMsg();
    std::string text = m ? m : "";
    for (const std::string& prefix : {path + ": ", path + ":"}) {
      while (text.rfind(prefix, 0) == 0) text.erase(0, prefix.size());
    }
    return text.empty() ? text : ": " + text;
  }
};

struct DatasetCloser {
  void operator()(void* d) const { Gdal().Close(static_cast<GDALDatasetH>(d)); }
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
  OGRSpatialReferenceH srs = Gdal().GetSpatialRef(ds);
  if (srs == nullptr) return std::string();
  // Clone: morphing for ESRI must not change the dataset's own.
  const auto destroy = [](void* srs) { Gdal().SrsDestroy(static_cast<OGRSpatialReferenceH>(srs)); };
  const std::unique_ptr<void, decltype(destroy)> copy(Gdal().SrsClone(srs), destroy);
  char* wkt = nullptr;
  const char* const options[] = {"FORMAT=WKT1_ESRI", nullptr};
  if (Gdal().SrsExportToWktEx(static_cast<OGRSpatialReferenceH>(copy.get()), &wkt, options) !=
          OGRERR_NONE ||
      wkt == nullptr) {
    Gdal().Free(wkt);
    return Fail(
        Error::Code::kInvalidArgument,
        path + ": its coordinate system has no ESRI WKT form" + QuietGdalErrors::Last(path));
  }
  std::string text(wkt);
  Gdal().Free(wkt);
  return text;
}

// Band 1's heights, rows north to south (flipped when the raster is stored south-up), in metres,
// NaN where the band has no value.
Result<std::vector<double>> Heights(GDALRasterBandH band, int nx, int ny, bool south_up,
                                    const std::string& path) {
  std::vector<double> v(static_cast<std::size_t>(nx) * ny);
  if (Gdal().RasterIO(band, GF_Read, 0, 0, nx, ny, v.data(), nx, ny, GDT_Float64, 0, 0) !=
      CE_None) {
    return Fail(Error::Code::kInvalidArgument,
                path + ": its heights cannot be read" + QuietGdalErrors::Last(path));
  }
  int has_nodata = 0, has_scale = 0, has_offset = 0;
  const double nodata = Gdal().GetRasterNoDataValue(band, &has_nodata);
  double scale = Gdal().GetRasterScale(band, &has_scale);
  double offset = Gdal().GetRasterOffset(band, &has_offset);
  if (!has_scale) scale = 1.0;
  if (!has_offset) offset = 0.0;
  const std::string unit = Gdal().GetRasterUnitType(band);
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
  if (!Gdal().missing.empty()) {
    return Fail(Error::Code::kFailed, path + ": cannot read a raster DEM: " + Gdal().missing);
  }
  const QuietGdalErrors quiet;
  const auto bad = [&](const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, path + ": " + why);
  };
  if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    std::fclose(f);
  } else {  // GDAL would only say that no driver recognised it
    return Fail(Error::Code::kNotFound, path + ": cannot be read: " + std::strerror(errno));
  }
  const Dataset ds(Gdal().OpenEx(path.c_str(),
                                 GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR, nullptr,
                                 nullptr, nullptr));
  if (!ds) {
    return Fail(Error::Code::kNotFound,
                path + ": cannot be read as a raster" + QuietGdalErrors::Last(path));
  }
  const GDALDatasetH d = static_cast<GDALDatasetH>(ds.get());
  RasterDem out;
  out.driver = Gdal().GetDriverShortName(Gdal().GetDatasetDriver(d));
  const int bands = Gdal().GetRasterCount(d);
  if (bands != 1) {
    return bad("holds " + std::to_string(bands) +
               " bands: a DEM holds one, the heights (is it an image?)");
  }
  double gt[6] = {0, 1, 0, 0, 0, 1};
  if (Gdal().GetGeoTransform(d, gt) != CE_None) {
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
  const int nx = Gdal().GetRasterXSize(d), ny = Gdal().GetRasterYSize(d);
  // A tiled, compressed or sparse raster describes its size in a few bytes: one no memory holds
  // is refused before its heights are read (a 5 MB GeoTIFF of sparse tiles says 200000 x 200000).
  const double height_bytes = static_cast<double>(nx) * ny * sizeof(double);
  const double memory_bytes = PhysicalMemoryBytes();
  if (height_bytes > memory_bytes) {
    return bad("its " + std::to_string(nx) + " x " + std::to_string(ny) + " cells (" +
               NumberText(height_bytes / 1e9) + " GB of heights) are more than this machine's " +
               NumberText(memory_bytes / 1e9) +
               " GB of memory: cut the part you need (gdal_translate -projwin)");
  }
  Result<std::vector<double>> heights =
      Heights(Gdal().GetRasterBand(d, 1), nx, ny, gt[5] > 0, path);
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
