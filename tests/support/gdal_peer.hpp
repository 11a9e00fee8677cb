#pragma once
// GDAL as the peer of pitchlab's raster DEM readers: the tests write GeoTIFFs with it (from our
// ESRI test grids or from heights of their own) and compare what pitchlab reads with what the
// grid holds. Link the test with GDAL::GDAL.

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace test_support {

/// The WKT of EPSG `code` as GDAL writes it into a GeoTIFF (4326: longitude, latitude).
inline std::string EpsgWkt(int code) {
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  EXPECT_EQ(OSRImportFromEPSG(srs, code), OGRERR_NONE) << code;
  char* wkt = nullptr;
  OSRExportToWkt(srs, &wkt);
  std::string text(wkt ? wkt : "");
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  return text;
}

/// A GeoTIFF copy of `source` (any raster GDAL reads: our .asc with its .prj, if any) at `out`;
/// its coordinate system replaced by EPSG `epsg` unless 0.
inline void CopyAsGeoTiff(const std::filesystem::path& source, const std::filesystem::path& out,
                          int epsg = 0) {
  GDALAllRegister();
  GDALDatasetH in = GDALOpen(source.string().c_str(), GA_ReadOnly);
  ASSERT_NE(in, nullptr) << source;
  GDALDatasetH copy = GDALCreateCopy(GDALGetDriverByName("GTiff"), out.string().c_str(), in, FALSE,
                                     nullptr, nullptr, nullptr);
  ASSERT_NE(copy, nullptr) << out;
  if (epsg != 0) EXPECT_EQ(GDALSetProjection(copy, EpsgWkt(epsg).c_str()), CE_None) << epsg;
  GDALClose(copy);
  GDALClose(in);
}

}  // namespace test_support
