// The hfield contract: what the generators say the surface is, MuJoCo's mj_ray finds there.
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>

#include "pitchlab/worlds/dem_world.hpp"
#include "pitchlab/worlds/heightfield_world.hpp"
#include "pitchlab/worlds/terrain_generator.hpp"
#include "pitchlab/worlds/world_metadata.hpp"
#include "test_support.hpp"

namespace pitchlab::worlds {
namespace {

using test::DataPtr;
using test::LoadModel;
using test::ScopedTempDir;
using test::SurfaceHeight;

constexpr double kMeshTolerance_m = 0.003;  // float32 data, 6-decimal MJCF numbers
constexpr double kPi = 3.14159265358979323846;

// Casts rays at a seeded set of points (vertices, cell interiors on both sides of the diagonal)
// and compares with the grid's own triangle-mesh height.
void ExpectRaysMatchGrid(const std::filesystem::path& xml, const HeightGrid& grid, int samples) {
  auto model = LoadModel(xml);
  ASSERT_TRUE(model);
  DataPtr data(mj_makeData(model.get()));
  mj_forward(model.get(), data.get());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(grid.x0_m, grid.XMax_m()), uy(grid.y0_m, grid.YMax_m());
  for (int k = 0; k < samples; ++k) {
    double x = ux(rng), y = uy(rng);
    if (k % 4 == 0) {  // exactly on a vertex
      x = grid.x0_m + std::round((x - grid.x0_m) / grid.cell_m) * grid.cell_m;
      y = grid.y0_m + std::round((y - grid.y0_m) / grid.cell_m) * grid.cell_m;
    }
    EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), x, y), grid.HeightOnMesh(x, y),
                kMeshTolerance_m)
        << xml.filename() << " at x " << x << ", y " << y;
  }
}

TEST(Heightfield, RowsRunSouthToNorthAndColumnsWestToEast) {
  // An asymmetric surface: rises 1 m per 10 m eastward, plus a 2 m block in the north-east corner
  // only; any flip or transpose moves the block or reverses the slope.
  HeightGrid grid(11, 7, 1.0, 100.0, -50.0);
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) {
      grid.At(ix, iy) = 5.0 + 0.1 * ix + ((ix >= 8 && iy >= 5) ? 2.0 : 0.0);
    }
  }
  const ScopedTempDir dir("orientation");
  const auto xml = dir.path() / "tilted.xml";
  WriteHeightfieldWorld(grid, WorldMetadata{}, "orientation test", xml);
  auto model = LoadModel(xml);
  ASSERT_TRUE(model);
  DataPtr data(mj_makeData(model.get()));
  mj_forward(model.get(), data.get());
  // South-west vertex, south-east vertex, north-east block, a point inside a cell.
  EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), 100.0, -50.0), 5.0, kMeshTolerance_m);
  EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), 110.0, -50.0), 6.0, kMeshTolerance_m);
  EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), 109.5, -44.5), 7.95, kMeshTolerance_m);
  EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), 100.5, -44.5), 5.05, kMeshTolerance_m);
  // Next to the block the two possible diagonals disagree by 0.4 m: MuJoCo splits each cell along
  // (ix, iy)-(ix + 1, iy + 1), giving 6.33 m here (the other split would give 5.93 m).
  EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), 107.3, -45.2), 6.33, kMeshTolerance_m);
  ExpectRaysMatchGrid(xml, grid, 200);
}

TEST(Heightfield, TerrainWorldSurfaceIsTheGeneratorsHeightsUnderMjRay) {
  const HeightGrid grid = GenerateTerrainHeights(TerrainConfig{});
  ExpectRaysMatchGrid(std::filesystem::path(PITCHLAB_WORLDS_DIR) / "terrain.xml", grid, 400);
}

TEST(Heightfield, TerrainHasSlopesBeyondAP3AndFlatStartAndGoalPads) {
  const HeightGrid grid = GenerateTerrainHeights(TerrainConfig{});
  constexpr double kP3SlopeLimit_rad = 30.0 * kPi / 180.0;
  constexpr double kFlat_rad = 1.0 * kPi / 180.0;
  int steep = 0;
  for (int iy = 0; iy < grid.ny; ++iy) {
    for (int ix = 0; ix < grid.nx; ++ix) steep += grid.Slope_rad(ix, iy) > kP3SlopeLimit_rad;
  }
  EXPECT_GT(steep, 1000) << "vertices steeper than 30 deg";
  EXPECT_GE(grid.XMax_m() - grid.x0_m, 60.0);
  EXPECT_NEAR(grid.cell_m, 0.1, 1e-12);
  for (double x = -1.5; x <= 1.5; x += 0.5) {
    for (double y = -1.5; y <= 1.5; y += 0.5) {
      const int ix = static_cast<int>(std::lround((x - grid.x0_m) / grid.cell_m));
      const int iy = static_cast<int>(std::lround((y - grid.y0_m) / grid.cell_m));
      EXPECT_LT(grid.Slope_rad(ix, iy), kFlat_rad) << "start pad at " << x << ", " << y;
    }
  }
  const TerrainConfig c;
  for (double x = -1.0; x <= 1.0; x += 0.5) {
    for (double y = -1.0; y <= 1.0; y += 0.5) {
      const int ix = static_cast<int>(std::lround((c.goal_x_m + x - grid.x0_m) / grid.cell_m));
      const int iy = static_cast<int>(std::lround((c.goal_y_m + y - grid.y0_m) / grid.cell_m));
      EXPECT_LT(grid.Slope_rad(ix, iy), kFlat_rad) << "goal pad at " << x << ", " << y;
    }
  }
  // The pads sit at the level of their surroundings, not on a mesa (the old start pad took the
  // height of a hilltop and stood 3 m proud behind 30 deg rims): the pad's height is the mean of
  // the ring where its rim ends, up to what rocks on that ring add.
  constexpr double kLevel_m = 0.1;
  for (const auto& [cx, cy, ring] : {std::tuple{0.0, 0.0, c.start_pad_radius_m + 8.0},
                                     {c.goal_x_m, c.goal_y_m, c.goal_pad_radius_m + 3.0}}) {
    double sum = 0;
    constexpr int kSamples = 64;
    for (int k = 0; k < kSamples; ++k) {
      const double a = 2.0 * kPi * k / kSamples;
      sum += grid.HeightBilinear(cx + ring * std::cos(a), cy + ring * std::sin(a));
    }
    EXPECT_NEAR(grid.HeightBilinear(cx, cy), sum / kSamples, kLevel_m)
        << "pad at " << cx << ", " << cy;
  }
}

TEST(Heightfield, GullySurfaceMatchesTheRawDemAtItsCellCentres) {
  // Independent of the resampler: DEM cell centres placed by GeographicLib here, heights by
  // mj_ray in a relief-free gully world.
  GullyConfig gully;
  gully.dem_path = std::filesystem::path(PITCHLAB_WORLDS_SOURCE_DIR) / "data/west_bijou_gully.asc";
  gully.cell_m = 0.5;
  DemWorldConfig config = GullyDemConfig(gully);
  config.relief_seed.reset();
  const ScopedTempDir dir("gully_raw");
  const auto xml = dir.path() / "gully_smooth.xml";
  GenerateDemWorld(config, xml);
  auto model = LoadModel(xml);
  ASSERT_TRUE(model);
  DataPtr data(mj_makeData(model.get()));
  mj_forward(model.get(), data.get());
  const WorldMetadata meta = ReadWorldMetadata(model.get());
  ASSERT_TRUE(meta.geodetic_origin);
  const GeographicLib::LocalCartesian enu(meta.geodetic_origin->latitude_deg,
                                          meta.geodetic_origin->longitude_deg, 0.0);
  const EsriGrid dem = LoadEsriGrid(gully.dem_path);
  constexpr double kResampleTolerance_m = 0.05;  // piecewise-linear mesh over a bicubic surface
  int checked = 0;
  for (int row = 0; row < dem.nrows; ++row) {
    for (int col = 0; col < dem.ncols; ++col) {
      if (std::isnan(dem.At(row, col))) continue;
      double lat = 0, lon = 0, e = 0, n = 0, u = 0;
      GeographicLib::UTMUPS::Reverse(13, true, dem.ColumnX(col), dem.RowY(row), lat, lon);
      enu.Forward(lat, lon, 0.0, e, n, u);
      const auto& b = meta.bounds;
      if (e < b.x_min_m || e > b.x_max_m || n < b.y_min_m || n > b.y_max_m) continue;
      EXPECT_NEAR(SurfaceHeight(model.get(), data.get(), e, n),
                  dem.At(row, col) - meta.geodetic_origin->height_m, kResampleTolerance_m)
          << "DEM row " << row << ", col " << col;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(Heightfield, GeneratedWorldsAreTheSameBytesFromTheSameSeed) {
  TerrainConfig small;
  small.size_m = 12.0;
  small.cell_m = 0.2;
  small.goal_x_m = -4.0, small.goal_y_m = 4.0;
  const ScopedTempDir a("seed_a"), b("seed_b"), c("seed_c");
  GenerateTerrainWorld(small, a.path());
  GenerateTerrainWorld(small, b.path());
  small.seed += 1;
  GenerateTerrainWorld(small, c.path());
  for (const char* file : {"terrain.xml", "terrain_hfield.bin"}) {
    EXPECT_EQ(test::ReadBytes(a.path() / file), test::ReadBytes(b.path() / file)) << file;
  }
  EXPECT_NE(test::ReadBytes(a.path() / "terrain_hfield.bin"),
            test::ReadBytes(c.path() / "terrain_hfield.bin"));
}

TEST(Heightfield, ADefaultGoalOffTheWorldIsRefusedNamingItAndNothingIsWritten) {
  const ScopedTempDir dir("gully_goal");
  GullyConfig gully;
  gully.dem_path = std::filesystem::path(PITCHLAB_WORLDS_SOURCE_DIR) / "data/west_bijou_gully.asc";
  gully.cell_m = 0.5;                // coarse: the check does not depend on the resolution
  gully.default_goal = {0.0, 70.0};  // the world spans y -66.4 .. 66.4 m
  try {
    GenerateGullyWorld(gully, dir.path());
    FAIL() << "a goal off the world was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("default goal (0.000, 70.000) lies outside the world's "
                                         "bounds"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "gully.xml"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "gully_hfield.bin"));
}

TEST(Heightfield, BuiltWorldsEqualAFreshRunOfTheDefaultGenerators) {
  const ScopedTempDir dir("defaults");
  GenerateTerrainWorld(TerrainConfig{}, dir.path());
  GullyConfig gully;
  gully.dem_path = std::filesystem::path(PITCHLAB_WORLDS_SOURCE_DIR) / "data/west_bijou_gully.asc";
  GenerateGullyWorld(gully, dir.path());
  GullyConfig other = gully;
  other.relief_seed += 1;
  const ScopedTempDir other_dir("gully_other");
  GenerateGullyWorld(other, other_dir.path());
  const std::filesystem::path built(PITCHLAB_WORLDS_DIR);
  for (const char* file : {"terrain.xml", "terrain_hfield.bin", "gully.xml", "gully_hfield.bin"}) {
    EXPECT_EQ(test::ReadBytes(dir.path() / file), test::ReadBytes(built / file)) << file;
  }
  EXPECT_NE(test::ReadBytes(dir.path() / "gully_hfield.bin"),
            test::ReadBytes(other_dir.path() / "gully_hfield.bin"));
}

}  // namespace
}  // namespace pitchlab::worlds
