// The inclination and roughness rasters `pitchlab map` writes beside the elevation: known planes
// and a known spread, read back from the ESRI ASCII grid.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mapping {
namespace {

// The raster's 4 decimals [deg] or [m].
constexpr double kRasterTol = 5e-5;

TEST(Rasters, InclinationIsTheTiltInDegreesAndRoughnessTheSpread) {
  // z = 0.2 x + 0.1 y on 1 m cells, four points a cell at +-0.25 m from its centre, those of
  // column 2 raised and lowered by 0.05 m in a saddle (+ - - +: no linear part, so the planes
  // fitted keep the tilt atan(sqrt(0.05)) = 12.6 deg). Eq. 3's roughness is the heights' own
  // spread: the plane's +-0.075 and +-0.025 m (std dev sqrt(0.003125) = 0.0559 m); in column 2
  // -0.025, -0.025, -0.075, +0.125 m (0.075 m).
  ElevationMap map(GridGeometry::FromArea(0, 0, 5, 4, 1.0));
  std::vector<Eigen::Vector3f> pts;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 5; ++i)
      for (int k = 0; k < 4; ++k) {
        const double x = i + 0.25 + 0.5 * (k % 2), y = j + 0.25 + 0.5 * (k / 2);
        const double bump = i == 2 ? ((k == 0 || k == 3) ? 0.05 : -0.05) : 0.0;
        pts.emplace_back(x, y, 0.2 * x + 0.1 * y + bump);
      }
  (void)map.InsertPoints(pts.data(), pts.size());
  const ElevationLayers L = ComputeLayers(map);
  const test_support::ScopedTempDir dir("rasters");
  ASSERT_TRUE(WriteEsriAsciiGrid(L, std::nullopt, (dir / "inclination.asc").string(),
                                 RasterLayer::kInclination));
  ASSERT_TRUE(WriteEsriAsciiGrid(L, std::nullopt, (dir / "roughness.asc").string(),
                                 RasterLayer::kRoughness));
  EXPECT_TRUE(std::filesystem::exists(dir / "inclination.prj"));
  const Result<AsciiGrid> incl = ReadAsciiGrid((dir / "inclination.asc").string());
  const Result<AsciiGrid> rough = ReadAsciiGrid((dir / "roughness.asc").string());
  ASSERT_TRUE(incl && rough);
  const double tilt_deg = std::atan(std::sqrt(0.2 * 0.2 + 0.1 * 0.1)) * 180 / M_PI;
  for (int row = 0; row < 4; ++row) {
    EXPECT_NEAR(incl->At(row, 0), tilt_deg, kRasterTol) << row;  // column 0: plane only
    EXPECT_NEAR(incl->At(row, 2), tilt_deg, kRasterTol) << row;
    EXPECT_NEAR(rough->At(row, 0), std::sqrt(0.003125), kRasterTol);
    EXPECT_NEAR(rough->At(row, 2), 0.075, kRasterTol);
  }
}

}  // namespace
}  // namespace pitchlab::mapping
