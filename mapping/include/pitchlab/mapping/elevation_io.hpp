#pragma once
// Elevation map files: a lossless binary (the running statistics, so insertion can continue after
// loading), an ESRI ASCII grid with its .prj for GIS tools, and a PNG picture.
//
// Lossless format (`.plem`, all little-endian):
//   bytes 0-7    magic "PLELEV03"
//   float64 x3   x_min_m, y_min_m, cell_m       (GridGeometry)
//   int32 x2     size_x, size_y
//   uint32       has_geodetic_origin (0 or 1)
//   float64 x3   latitude_deg, longitude_deg, height_m (zeros when absent)
//   uint32       bytes per cell record (60)
//   runs         until all size_x * size_y cells (index j * size_x + i) are covered:
//                uint32 unseen, uint32 seen, then `seen` records. The `unseen` cells are
//                CellStats' defaults (no point, no ray); a record's fields in declaration order:
//                uint32 count, float32 mean_x mean_y mean_z c_xx c_xy c_xz c_yy c_yz c_zz
//                min_z max_z clearance_z next_min_z next_max_z (infinities as IEEE infinities)
//   uint64       FNV-1a 64 hash of every byte before it
// Files of earlier pitchlab are read too: "PLELEV02" (runs of 52-byte records, without the
// second extremes, whose cells' extremes then stand for them) and "PLELEV01" (every 52-byte
// record in order, no runs).
// Files are written to a temporary name and renamed: a failure leaves no partial file.

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/sensors/result.hpp"

namespace pitchlab::mapping {

/// Writes the map losslessly (format above). Errors name the path and the reason.
[[nodiscard]] Result<void> SaveElevationMap(const ElevationMap& map, const std::string& path);
/// Reads a map written by SaveElevationMap; fails (kInvalidArgument) on a bad magic, size or hash.
[[nodiscard]] Result<ElevationMap> LoadElevationMap(const std::string& path);

/// Which layer a raster holds.
enum class RasterLayer {
  kMean,         ///< Eq. 2 cell elevation [m]
  kMin,          ///< lowest point [m]
  kMax,          ///< highest point [m]
  kRoughness,    ///< Eq. 3 T [m]
  kInclination,  ///< the cell plane's tilt, ElevationLayers::Tilt [deg] (GIS slope rasters' unit)
};

/// Writes `layer` as an ESRI ASCII grid (rows north to south, NODATA -9999 for unknown and drop
/// cells and for an inclination the scan does not support, xll/yll the grid's outer corner) and a
/// `.prj` beside it (same stem). With a geodetic origin the frame is a Transverse Mercator
/// centred on it (WGS84, scale 1, false easting and northing 0: it matches the map's local ENU
/// frame to well under a millimetre over kilometres) and heights are offset by the origin's
/// height; without one a LOCAL_CS in metres.
[[nodiscard]] Result<void> WriteEsriAsciiGrid(const ElevationLayers& layers,
                                              const std::optional<GeodeticOrigin>& origin,
                                              const std::string& asc_path,
                                              RasterLayer layer = RasterLayer::kMean);
/// The .prj text WriteEsriAsciiGrid writes (ESRI WKT1).
std::string ProjectionWkt(const std::optional<GeodeticOrigin>& origin);

/// An 8-bit RGB picture, row 0 at the top (north up).
struct RgbImage {
  int width = 0, height = 0;
  int pixels_per_cell = 1;        ///< [px/cell]
  std::vector<std::uint8_t> rgb;  ///< width * height * 3
  void Set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b);
};

/// How the map picture looks.
struct ImageOptions {
  int pixels_per_cell = 0;       ///< 0: the largest that keeps the longer side <= max_side_px
  int max_side_px = 2048;        ///< [px]
  double sun_azimuth_deg = 315;  ///< hillshade light from the north-west [deg]
  double sun_altitude_deg = 45;  ///< [deg]
  double z_exaggeration = 1.0;   ///< hillshade vertical exaggeration [1]
};

/// RenderElevationImage's colour [0-255] of relative height t (0 low, 1 high, clamped) before
/// hillshade: deep blue, green, yellow-brown, white. Exposed for colour bars.
std::array<double, 3> ElevationRamp(double t);
/// The heights [m] RenderElevationImage maps to the ramp's ends: the 2nd and 98th percentile of
/// the observed cells' mean heights (0 and 1 for an empty map; hi > lo always).
std::pair<double, double> ElevationRampRange(const ElevationLayers& layers);
/// Colour by mean height (2nd-98th percentile, blue-green-brown-white ramp) times a hillshade;
/// unknown cells a grey checkerboard, drops magenta.
RgbImage RenderElevationImage(const ElevationLayers& layers, const ImageOptions& options = {});
/// Pixel (column, row) of the map point (x, y) [m] in an image rendered from `geometry`.
Eigen::Vector2d MapToPixel(const GridGeometry& geometry, const RgbImage& image, double x_m,
                           double y_m);
/// Writes the picture as an 8-bit RGB PNG (libpng), atomically.
[[nodiscard]] Result<void> WritePng(const RgbImage& image, const std::string& path);

}  // namespace pitchlab::mapping
