// Raster DEMs through GDAL (LoadDem on a GeoTIFF, mapping/src/gdal_raster_reader.cpp): GDAL is
// the peer. It reads our ESRI test grids itself (value for value what our reader reads) and writes
// them as GeoTIFFs, which must load as the very map their .asc and .prj give; rasters pitchlab
// cannot take are refused naming the file and why.

#include <gtest/gtest.h>

#include <gdal.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "gdal_peer.hpp"
#include "gdal_raster_reader.hpp"
#include "pitchlab/mapping/dem_io.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mapping {
namespace {

namespace fs = std::filesystem;
using ::test_support::CopyAsGeoTiff;
using ::test_support::EpsgWkt;
using test_support::ScopedTempDir;

const std::string kDemDir = std::string(PITCHLAB_TEST_DATA_DIR) + "/dem/";

// A new float32 GeoTIFF of `bands` bands, `nx` x `ny`, every band filled by `height(col, row)`
// (row 0 first in the file); geotransform and unit as given (no geotransform when `gt` is null).
void WriteGeoTiff(const fs::path& out, int nx, int ny, int bands, const double* gt,
                  const std::function<double(int, int)>& height,
                  const char* epsg_wkt_from = nullptr, const char* unit = nullptr,
                  std::optional<double> nodata = std::nullopt) {
  GDALAllRegister();
  GDALDatasetH d = GDALCreate(GDALGetDriverByName("GTiff"), out.string().c_str(), nx, ny, bands,
                              GDT_Float32, nullptr);
  ASSERT_NE(d, nullptr);
  if (gt) {
    double copy[6];
    std::copy(gt, gt + 6, copy);
    GDALSetGeoTransform(d, copy);
  }
  if (epsg_wkt_from) GDALSetProjection(d, epsg_wkt_from);
  std::vector<float> values(static_cast<std::size_t>(nx) * ny);
  for (int row = 0; row < ny; ++row)
    for (int col = 0; col < nx; ++col)
      values[row * nx + col] = static_cast<float>(height(col, row));
  for (int b = 1; b <= bands; ++b) {
    GDALRasterBandH band = GDALGetRasterBand(d, b);
    if (unit) GDALSetRasterUnitType(band, unit);
    if (nodata) GDALSetRasterNoDataValue(band, *nodata);
    ASSERT_EQ(GDALRasterIO(band, GF_Write, 0, 0, nx, ny, values.data(), nx, ny, GDT_Float32, 0, 0),
              CE_None);
  }
  GDALClose(d);
}

void ExpectSameMap(const Dem& a, const Dem& b) {
  const GridGeometry& ga = a.map.geometry();
  const GridGeometry& gb = b.map.geometry();
  ASSERT_EQ(ga.size_x, gb.size_x);
  ASSERT_EQ(ga.size_y, gb.size_y);
  EXPECT_DOUBLE_EQ(ga.cell_m, gb.cell_m);
  EXPECT_DOUBLE_EQ(ga.x_min_m, gb.x_min_m);
  EXPECT_DOUBLE_EQ(ga.y_min_m, gb.y_min_m);
  ASSERT_EQ(a.map.geodetic_origin().has_value(), b.map.geodetic_origin().has_value());
  if (a.map.geodetic_origin()) {
    EXPECT_NEAR(a.map.geodetic_origin()->latitude_deg, b.map.geodetic_origin()->latitude_deg,
                1e-12);
    EXPECT_NEAR(a.map.geodetic_origin()->longitude_deg, b.map.geodetic_origin()->longitude_deg,
                1e-12);
    EXPECT_NEAR(a.map.geodetic_origin()->height_m, b.map.geodetic_origin()->height_m, 1e-3);
  }
  EXPECT_EQ(a.nodata_cells, b.nodata_cells);
  for (int j = 0; j < ga.size_y; ++j)
    for (int i = 0; i < ga.size_x; ++i) {
      const CellStats& ca = a.map.at(CellIndex{i, j});
      const CellStats& cb = b.map.at(CellIndex{i, j});
      ASSERT_EQ(ca.known(), cb.known()) << i << ", " << j;
      // The GeoTIFF holds float32 heights: 1 mm at ~2000 m.
      if (ca.known()) ASSERT_NEAR(ca.mean_z, cb.mean_z, 2e-3) << i << ", " << j;
    }
}

TEST(RasterDem, GdalReadsOurEsriGridsValueForValueAsOurReaderDoes) {
  for (const char* name : {"west_bijou_escarpment_snippet.asc", "hugo_site.asc"}) {
    const Result<AsciiGrid> ours = ReadAsciiGrid(kDemDir + name);
    const Result<internal::RasterDem> gdal = internal::ReadGdalRaster(kDemDir + name);
    ASSERT_TRUE(ours) << ours.error().message;
    ASSERT_TRUE(gdal) << gdal.error().message;
    EXPECT_EQ(gdal->driver, "AAIGrid");
    EXPECT_EQ(gdal->grid.ncols, ours->ncols);
    EXPECT_EQ(gdal->grid.nrows, ours->nrows);
    EXPECT_NEAR(gdal->grid.xll_corner, ours->xll_corner, 1e-9);
    EXPECT_NEAR(gdal->grid.yll_corner, ours->yll_corner, 1e-9);
    EXPECT_NEAR(gdal->grid.cell_size, ours->cell_size, 1e-12);
    ASSERT_EQ(gdal->grid.values.size(), ours->values.size());
    for (std::size_t k = 0; k < ours->values.size(); ++k) {
      if (std::isnan(ours->values[k])) {
        ASSERT_TRUE(std::isnan(gdal->grid.values[k])) << name << " value " << k;
      } else {
        ASSERT_NEAR(gdal->grid.values[k], ours->values[k], 1e-9) << name << " value " << k;
      }
    }
  }
}

// A real geographic DEM (1 arc-second SRTM, longitude/latitude): its GeoTIFF, georeferenced by the
// keys GDAL wrote from the .prj, is resampled onto the same east-north-up map.
TEST(RasterDem, AGeoTiffOfAGeographicGridLoadsAsItsAscAndPrjDo) {
  const ScopedTempDir dir("raster_dem");
  const std::string asc = kDemDir + "west_bijou_escarpment_snippet.asc";
  CopyAsGeoTiff(asc, dir / "bijou.tif");
  const Result<Dem> from_asc = LoadDem(asc);
  const Result<Dem> from_tif = LoadDem((dir / "bijou.tif").string());
  ASSERT_TRUE(from_asc) << from_asc.error().message;
  ASSERT_TRUE(from_tif) << from_tif.error().message;
  EXPECT_EQ(from_tif->crs.kind, DemCrs::Kind::kGeographic);
  EXPECT_TRUE(from_tif->resampled);
  ExpectSameMap(*from_asc, *from_tif);
}

// A UTM grid (projected metres) as GeoTIFF: the projection's parameters survive GDAL's keys and
// its ESRI WKT, and the map is the one the .asc and .prj give.
TEST(RasterDem, AGeoTiffOfAUtmGridLoadsAsItsAscAndPrjDo) {
  const ScopedTempDir dir("raster_dem");
  std::string text = "ncols 40\nnrows 30\nxllcorner 559700\nyllcorner 4380200\ncellsize 10\n";
  for (int row = 0; row < 30; ++row) {
    for (int col = 0; col < 40; ++col) text += std::to_string(1700 + 0.5 * col - 0.2 * row) + " ";
    text += "\n";
  }
  std::ofstream(dir / "plane.asc") << text;
  std::ofstream(dir / "plane.prj")
      << "PROJCS[\"WGS_1984_UTM_Zone_13N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\","
         "SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],"
         "UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],"
         "PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],"
         "PARAMETER[\"Central_Meridian\",-105.0],PARAMETER[\"Scale_Factor\",0.9996],"
         "PARAMETER[\"Latitude_Of_Origin\",0.0],UNIT[\"Meter\",1.0]]";
  CopyAsGeoTiff((dir / "plane.asc").string(), dir / "plane.tif");
  const Result<Dem> from_asc = LoadDem((dir / "plane.asc").string());
  const Result<Dem> from_tif = LoadDem((dir / "plane.tif").string());
  ASSERT_TRUE(from_asc) << from_asc.error().message;
  ASSERT_TRUE(from_tif) << from_tif.error().message;
  EXPECT_EQ(from_tif->crs.kind, DemCrs::Kind::kTransverseMercator);
  EXPECT_DOUBLE_EQ(from_tif->crs.central_meridian_deg, -105.0);
  EXPECT_DOUBLE_EQ(from_tif->crs.scale_factor, 0.9996);
  EXPECT_DOUBLE_EQ(from_tif->crs.false_easting_m, 500000.0);
  ExpectSameMap(*from_asc, *from_tif);
}

// Heights in feet become metres; no-data cells stay unknown; a raster stored south-up (positive
// y pixel size) is the same map as the same heights stored north-up.
TEST(RasterDem, FeetNoDataAndSouthUpRastersAreReadAsTheyMean) {
  const ScopedTempDir dir("raster_dem");
  const auto h = [](int col, int row) { return row == 1 && col == 2 ? -9999.0 : 100.0 + col; };
  const double north_up[6] = {1000, 2, 0, 2000, 0, -2};  // local metres, 2 m cells
  WriteGeoTiff(dir / "feet.tif", 5, 4, 1, north_up, h, nullptr, "ft", -9999.0);
  const Result<Dem> feet = LoadDem((dir / "feet.tif").string());
  ASSERT_TRUE(feet) << feet.error().message;
  EXPECT_EQ(feet->crs.kind, DemCrs::Kind::kLocal);
  EXPECT_FALSE(feet->resampled);
  EXPECT_EQ(feet->nodata_cells, 1u);
  // Map row j = 3 - file row; (col 4, file row 0) holds 104 ft.
  EXPECT_NEAR(feet->map.at(CellIndex{4, 3}).mean_z, 104 * 0.3048, 1e-4);
  EXPECT_FALSE(feet->map.at(CellIndex{2, 2}).known());  // file row 1, col 2: no data

  const double south_up[6] = {1000, 2, 0, 1992, 0, 2};  // row 0 is the southernmost
  WriteGeoTiff(
      dir / "south.tif", 5, 4, 1, south_up, [&](int col, int row) { return h(col, 3 - row); },
      nullptr, "ft", -9999.0);
  const Result<Dem> south = LoadDem((dir / "south.tif").string());
  ASSERT_TRUE(south) << south.error().message;
  ExpectSameMap(*feet, *south);
}

// Cells 1.5" by 1" (Copernicus' DEM beyond 50 deg latitude), heights linear in longitude and
// latitude: bilinear sampling gives them back exactly wherever a map cell's centre falls, on
// square map cells of the finer spacing (1" of latitude, 30.9 m).
TEST(RasterDem, AGeographicRasterOfOblongCellsIsResampledExactlyForAPlane) {
  const ScopedTempDir dir("raster_dem");
  const double lon0 = 10.0, lat0 = 51.01, dlon = 1.5 / 3600, dlat = 1.0 / 3600;
  const int nx = 30, ny = 40;
  const auto plane = [&](double lon, double lat) {
    return 300 + 2000 * (lon - lon0) - 5000 * (lat - lat0);
  };
  const double gt[6] = {lon0, dlon, 0, lat0, 0, -dlat};
  WriteGeoTiff(
      dir / "oblong.tif", nx, ny, 1, gt,
      [&](int col, int row) { return plane(lon0 + (col + 0.5) * dlon, lat0 - (row + 0.5) * dlat); },
      EpsgWkt(4326).c_str());
  const Result<Dem> dem = LoadDem((dir / "oblong.tif").string());
  ASSERT_TRUE(dem) << dem.error().message;
  EXPECT_DOUBLE_EQ(dem->grid.cell_size, dlon);
  EXPECT_DOUBLE_EQ(dem->grid.cell_size_y, dlat);
  // 1" of latitude is 30.9 m; 1.5" of longitude at 51 deg is 29.2 m: the finer wins.
  EXPECT_NEAR(dem->map.geometry().cell_m, 1.5 * 30.92 * std::cos(51.0 * M_PI / 180), 0.2);
  const double z0 = dem->map.geodetic_origin()->height_m;
  const GridGeometry& g = dem->map.geometry();
  int checked = 0;
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      if (!dem->map.at(CellIndex{i, j}).known()) continue;
      const Eigen::Vector2d f = dem->MapToFile(g.CenterOf({i, j}));
      // Inside the rectangle of the file's cell centres, where nothing is clamped.
      if (f.x() < lon0 + dlon / 2 || f.x() > lon0 + (nx - 0.5) * dlon || f.y() > lat0 - dlat / 2 ||
          f.y() < lat0 - (ny - 0.5) * dlat)
        continue;
      // float32 heights in the file: 1e-4 m near 300 m.
      EXPECT_NEAR(dem->map.at(CellIndex{i, j}).mean_z + z0, plane(f.x(), f.y()), 1e-3);
      ++checked;
    }
  EXPECT_GT(checked, 800);  // of ~ (29 x 1.5 / 0.95) x 39 map cells inside
}

TEST(RasterDem, RastersPitchlabCannotTakeAreRefusedSayingWhy) {
  const ScopedTempDir dir("raster_dem");
  const auto flat = [](int, int) { return 10.0; };
  const double gt[6] = {0, 1, 0, 0, 0, -1};
  const auto refused = [&](const fs::path& file, const std::string& why) {
    const Result<Dem> dem = LoadDem(file.string());
    ASSERT_FALSE(dem) << file;
    EXPECT_EQ(dem.error().message.rfind(file.string() + ": ", 0), 0u) << dem.error().message;
    EXPECT_NE(dem.error().message.find(why), std::string::npos) << dem.error().message;
  };
  WriteGeoTiff(dir / "rgb.tif", 4, 4, 3, gt, flat);
  refused(dir / "rgb.tif", "holds 3 bands");
  WriteGeoTiff(dir / "bare.tif", 4, 4, 1, nullptr, flat);
  refused(dir / "bare.tif", "has no geotransform");
  const double rotated[6] = {0, 1, 0.1, 0, 0.1, -1};
  WriteGeoTiff(dir / "rotated.tif", 4, 4, 1, rotated, flat);
  refused(dir / "rotated.tif", "rotated");
  const double oblong[6] = {0, 1, 0, 0, 0, -2};
  WriteGeoTiff(dir / "oblong.tif", 4, 4, 1, oblong, flat);
  refused(dir / "oblong.tif", "its cells are 1 by 2 in a local frame");
  WriteGeoTiff(dir / "furlong.tif", 4, 4, 1, gt, flat, nullptr, "furlong");
  refused(dir / "furlong.tif", "heights in 'furlong', not metres or feet");
  const double degrees[6] = {-104.3, 0.0003, 0, 39.5, 0, -0.0003};
  WriteGeoTiff(dir / "nocrs.tif", 4, 4, 1, degrees, flat);
  refused(dir / "nocrs.tif", "looks like degrees, but the file gives no coordinate system");
  std::ofstream(dir / "text.tif") << "not a raster\n";
  refused(dir / "text.tif", "cannot be read as a raster");
  {  // 200000 x 200000 cells in 5 MB (sparse tiles: their index only): 320 GB of heights, refused
    GDALAllRegister();
    const char* options[] = {"TILED=YES", "SPARSE_OK=TRUE", "COMPRESS=DEFLATE", nullptr};
    GDALDatasetH d = GDALCreate(GDALGetDriverByName("GTiff"), (dir / "vast.tif").string().c_str(),
                                200000, 200000, 1, GDT_Float32, const_cast<char**>(options));
    ASSERT_NE(d, nullptr);
    double vast_gt[6] = {0, 1, 0, 0, 0, -1};
    GDALSetGeoTransform(d, vast_gt);
    GDALClose(d);
  }
  ASSERT_LT(fs::file_size(dir / "vast.tif"), 10'000'000u);
  refused(dir / "vast.tif", "its 200000 x 200000 cells (320 GB of heights) are more than this");
  refused(dir / "missing.tif", "cannot be read: No such file or directory");
  // And one it can: the same 0.0003 deg cells with EPSG:4326 set.
  WriteGeoTiff(dir / "wgs84.tif", 4, 4, 1, degrees, flat, EpsgWkt(4326).c_str());
  const Result<Dem> wgs84 = LoadDem((dir / "wgs84.tif").string());
  ASSERT_TRUE(wgs84) << wgs84.error().message;
  EXPECT_EQ(wgs84->crs.kind, DemCrs::Kind::kGeographic);
}

}  // namespace
}  // namespace pitchlab::mapping
