// Users' DEMs (dem_io.hpp): ESRI ASCII grids and their .prj read back exactly or resampled onto
// the map frame against GeographicLib's projections, bad files refused naming file and line.

#include <gtest/gtest.h>

#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "pitchlab/mapping/dem_io.hpp"
#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab::mapping {
namespace {

namespace fs = std::filesystem;

// ESRI's .prj of UTM zone 13N on WGS84, as GIS tools write it.
constexpr char kUtm13N[] =
    "PROJCS[\"WGS_1984_UTM_Zone_13N\",GEOGCS[\"GCS_WGS_1984\",DATUM[\"D_WGS_1984\","
    "SPHEROID[\"WGS_1984\",6378137.0,298.257223563]],PRIMEM[\"Greenwich\",0.0],"
    "UNIT[\"Degree\",0.0174532925199433]],PROJECTION[\"Transverse_Mercator\"],"
    "PARAMETER[\"False_Easting\",500000.0],PARAMETER[\"False_Northing\",0.0],"
    "PARAMETER[\"Central_Meridian\",-105.0],PARAMETER[\"Scale_Factor\",0.9996],"
    "PARAMETER[\"Latitude_Of_Origin\",0.0],UNIT[\"Meter\",1.0]]";

using test_support::ScopedTempDir;

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

double HeightAt(const Dem& dem, int i, int j) {
  const double z0 = dem.map.geodetic_origin() ? dem.map.geodetic_origin()->height_m : 0.0;
  return dem.map.at(CellIndex{i, j}).mean_z + z0;
}

TEST(AsciiGrid, HandMadeGridReadsBackExactly) {
  const ScopedTempDir dir("dem_exact");
  const fs::path asc = dir / "g.asc";
  // Lower-left given as a cell centre: the corner lies half a cell (1 m) further out.
  WriteText(asc,
            "NCOLS 3\nnrows 2\nxllcenter 101\nyllcenter 51\ncellsize 2\nNODATA_value -9999\n"
            "1.25 -9999 3\n4 5.5\n-6.75\n");
  const Result<AsciiGrid> g = ReadAsciiGrid(asc.string());
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_EQ(g->ncols, 3);
  EXPECT_EQ(g->nrows, 2);
  EXPECT_EQ(g->xll_corner, 100);
  EXPECT_EQ(g->yll_corner, 50);
  EXPECT_EQ(g->At(0, 0), 1.25);
  EXPECT_TRUE(std::isnan(g->At(0, 1)));
  EXPECT_EQ(g->At(1, 2), -6.75);

  // As a DEM without a .prj: local metres, the file's own x, y, cell for cell.
  const Result<Dem> dem = LoadDem(asc.string());
  ASSERT_TRUE(dem) << dem.error().message;
  EXPECT_FALSE(dem->resampled);
  EXPECT_FALSE(dem->map.geodetic_origin());
  EXPECT_EQ(dem->nodata_cells, 1u);
  const GridGeometry& geo = dem->map.geometry();
  EXPECT_EQ(geo.x_min_m, 100);
  EXPECT_EQ(geo.y_min_m, 50);
  EXPECT_EQ(geo.cell_m, 2);
  EXPECT_EQ(HeightAt(*dem, 0, 1), 1.25);  // file row 0 is the northern map row 1
  EXPECT_EQ(HeightAt(*dem, 2, 0), -6.75);
  EXPECT_EQ(HeightAt(*dem, 1, 0), 5.5);
  EXPECT_FALSE(dem->map.at(CellIndex{1, 1}).known());
  EXPECT_EQ(dem->FileToMap({101, 51}), Eigen::Vector2d(101, 51));
}

TEST(AsciiGrid, BadFilesNameTheFileAndTheLine) {
  const ScopedTempDir dir("dem_bad");
  const struct {
    std::string text, where, what;
  } cases[] = {
      {"ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\n1 2\n",
       ":5:", "missing header field 'cellsize'"},
      {"ncols 2\nncols 2\n", ":2:", "given twice"},
      {"ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 x\n",
       ":6:", "'x' is not a finite number"},
      {"ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n3\n",
       ":7:", "the file ends after 3"},
      {"ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n", ":6:", "more values"},
      {"ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 0\n1\n", ":5:", "must be positive"},
      {"ncols 1.5\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1\n", ":1:", "whole number"},
      {"ncols 1\nnrows 1\nxllcorner 0\nxllcenter 0\nyllcorner 0\ncellsize 1\n1\n",
       ":7:", "exactly one"},
      {"ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\ndx 1\n1\n",
       ":6:", "'dx' is neither"},
      {"ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1e999\n", ":6:", "not a finite"},
      // 10^16 values asked of 71 bytes: refused before they are allocated (worldgen died of it).
      {"ncols 100000000\nnrows 100000000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n", ":6:",
       "= 10000000000000000 values, more than the file's 71 bytes can hold"},
  };
  for (const auto& c : cases) {
    const fs::path asc = dir / "bad.asc";
    WriteText(asc, c.text);
    const Result<AsciiGrid> g = ReadAsciiGrid(asc.string());
    ASSERT_FALSE(g) << c.text;
    EXPECT_NE(g.error().message.find(asc.string() + c.where), std::string::npos)
        << g.error().message;
    EXPECT_NE(g.error().message.find(c.what), std::string::npos) << g.error().message;
  }
  EXPECT_EQ(ReadAsciiGrid((dir / "missing.asc").string()).error().code, Error::Code::kNotFound);
}

TEST(Prj, ReadsTheThreeKindsAndRefusesOtherProjections) {
  const Result<DemCrs> utm = ParsePrj(kUtm13N, "u.prj");
  ASSERT_TRUE(utm) << utm.error().message;
  EXPECT_EQ(utm->kind, DemCrs::Kind::kTransverseMercator);
  EXPECT_EQ(utm->name, "WGS_1984_UTM_Zone_13N");
  EXPECT_EQ(utm->central_meridian_deg, -105.0);
  EXPECT_EQ(utm->scale_factor, 0.9996);
  EXPECT_EQ(utm->false_easting_m, 500000.0);

  std::ifstream in(fs::path(PITCHLAB_TEST_DATA_DIR) / "dem/west_bijou_escarpment_snippet.prj");
  const std::string geographic((std::istreambuf_iterator<char>(in)), {});
  const Result<DemCrs> geo = ParsePrj(geographic, "g.prj");
  ASSERT_TRUE(geo) << geo.error().message;
  EXPECT_EQ(geo->kind, DemCrs::Kind::kGeographic);

  // pitchlab's own rasters' .prj, with and without a geodetic origin.
  const Result<DemCrs> own = ParsePrj(ProjectionWkt(GeodeticOrigin{46.77, 23.6, 400}), "o.prj");
  ASSERT_TRUE(own) << own.error().message;
  EXPECT_EQ(own->kind, DemCrs::Kind::kTransverseMercator);
  EXPECT_NEAR(own->latitude_of_origin_deg, 46.77, 1e-12);
  EXPECT_NEAR(own->central_meridian_deg, 23.6, 1e-12);
  const Result<DemCrs> local = ParsePrj(ProjectionWkt(std::nullopt), "l.prj");
  ASSERT_TRUE(local) << local.error().message;
  EXPECT_EQ(local->kind, DemCrs::Kind::kLocal);

  std::string lambert = kUtm13N;
  lambert.replace(lambert.find("Transverse_Mercator"), 19, "Lambert_Conformal_Conic");
  const Result<DemCrs> refused = ParsePrj(lambert, "lcc.prj");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("lcc.prj: projection 'lambert_conformal_conic' is not "
                                         "supported"),
            std::string::npos)
      << refused.error().message;
  std::string feet = kUtm13N;
  feet.replace(feet.find("UNIT[\"Meter\",1.0]"), 17, "UNIT[\"Foot_US\",0.3048006096]");
  EXPECT_FALSE(ParsePrj(feet, "f.prj"));
  EXPECT_FALSE(ParsePrj("PROJCS[\"broken\"", "b.prj"));
}

TEST(Dem, UtmGridIsResampledOntoTheLocalEnuFrameExactlyForAPlane) {
  // A plane in UTM 13N (10 m cells, 40 x 30): bilinear resampling reproduces a plane exactly, so
  // every map cell must hold the plane's height where GeographicLib puts the cell's centre.
  const ScopedTempDir dir("dem_utm");
  const double xll = 559700, yll = 4380200, cell = 10;
  const auto plane = [&](double e, double n) { return 1700 + 0.05 * (e - xll) - 0.02 * (n - yll); };
  std::string text = "ncols 40\nnrows 30\nxllcorner 559700\nyllcorner 4380200\ncellsize 10\n";
  for (int row = 0; row < 30; ++row) {
    for (int col = 0; col < 40; ++col)
      text += std::to_string(plane(xll + (col + 0.5) * cell, yll + (30 - row - 0.5) * cell)) + " ";
    text += "\n";
  }
  WriteText(dir / "plane.asc", text);
  WriteText(dir / "plane.prj", kUtm13N);
  const Result<Dem> dem = LoadDem((dir / "plane.asc").string());
  ASSERT_TRUE(dem) << dem.error().message;
  ASSERT_TRUE(dem->resampled);
  const GeodeticOrigin o = *dem->map.geodetic_origin();
  double lat_c = 0, lon_c = 0;
  GeographicLib::UTMUPS::Reverse(13, true, xll + 200, yll + 150, lat_c, lon_c);
  EXPECT_NEAR(o.latitude_deg, lat_c, 1e-9);
  EXPECT_NEAR(o.longitude_deg, lon_c, 1e-9);
  // UTM's scale 0.9996 and the grid's 0.45 deg convergence here: cells within 0.1 % of 10 m.
  EXPECT_NEAR(dem->map.geometry().cell_m, cell / 0.9996, 0.01);
  const GeographicLib::LocalCartesian enu(o.latitude_deg, o.longitude_deg, o.height_m);
  const GridGeometry& g = dem->map.geometry();
  int checked = 0;
  for (int j = 0; j < g.size_y; ++j)
    for (int i = 0; i < g.size_x; ++i) {
      if (!dem->map.at(CellIndex{i, j}).known()) continue;
      const Eigen::Vector2d c = g.CenterOf({i, j});
      // Between the grid's outer edge and its outermost cell centres the edge value holds (no
      // data beyond to interpolate with): the plane is exact inside the centres' rectangle.
      const Eigen::Vector2d f = dem->MapToFile(c);
      if (f.x() < xll + cell / 2 || f.x() > xll + 39.5 * cell || f.y() < yll + cell / 2 ||
          f.y() > yll + 29.5 * cell)
        continue;
      double lat = 0, lon = 0, h = 0, e = 0, n = 0, gamma = 0, k = 0;
      int zone = 0;
      bool north = true;
      enu.Reverse(c.x(), c.y(), 0, lat, lon, h);
      GeographicLib::UTMUPS::Forward(lat, lon, zone, north, e, n, gamma, k, 13);
      // float32 heights relative to the origin: 1e-4 m over tens of metres of relief.
      EXPECT_NEAR(HeightAt(*dem, i, j), plane(e, n), 1e-3) << i << ", " << j;
      const Eigen::Vector2d back = dem->FileToMap(dem->MapToFile(c));
      EXPECT_NEAR((back - c).norm(), 0.0, 1e-6);
      ++checked;
    }
  // The centres' rectangle is 39 x 29 of the 40 x 30 cells.
  EXPECT_GT(checked, 0.9 * 39 * 29);
}

TEST(Dem, GeographicRealDemGetsSquareCellsAtItsFinerSpacing) {
  const Result<Dem> dem =
      LoadDem(std::string(PITCHLAB_TEST_DATA_DIR) + "/dem/west_bijou_escarpment_snippet.asc");
  ASSERT_TRUE(dem) << dem.error().message;
  ASSERT_TRUE(dem->resampled);
  const GeodeticOrigin o = *dem->map.geodetic_origin();
  // The centre of 129 x 67 cells of 1 arc-second from (-104.341806, 39.505972).
  EXPECT_NEAR(o.longitude_deg, -104.341805555546 + 64.5 * 0.000277777778, 1e-9);
  EXPECT_NEAR(o.latitude_deg, 39.505972222219 + 33.5 * 0.000277777778, 1e-9);
  // Along the parallel one arc-second is N cos(lat) dlon (N the prime vertical radius).
  const double a = 6378137.0, e2 = 0.00669437999014, phi = o.latitude_deg * M_PI / 180;
  const double N = a / std::sqrt(1 - e2 * std::sin(phi) * std::sin(phi));
  EXPECT_NEAR(dem->map.geometry().cell_m, N * std::cos(phi) * 0.000277777778 * M_PI / 180, 0.01);
  // Heights are the file's, blended: within its range (1690-1807 m, SOURCES.md).
  const ElevationLayers L = ComputeLayers(dem->map);
  for (std::size_t k = 0; k < L.mean_z.size(); ++k) {
    if (L.state[k] != CellState::kObserved) continue;
    EXPECT_GE(L.mean_z[k] + o.height_m, 1690 - 1e-3);
    EXPECT_LE(L.mean_z[k] + o.height_m, 1807 + 1e-3);
  }
}

TEST(Dem, PitchlabsOwnRasterReadsBackCellForCellInTheSameFrame) {
  // map -> elevation.asc + .prj -> LoadDem: the same grid, heights and geodetic origin.
  const GeodeticOrigin origin{46.77, 23.6, 400};
  ElevationMap map(GridGeometry::FromArea(-2, -1, 4, 2, 0.5), origin);
  std::vector<Eigen::Vector3f> pts;
  for (double y = -0.75; y < 1; y += 0.5)
    for (double x = -1.75; x < 2; x += 0.5) pts.emplace_back(x, y, 0.25 * x - 0.5 * y);
  (void)map.InsertPoints(pts.data(), pts.size());
  const ScopedTempDir dir("dem_own");
  const fs::path asc = dir / "elevation.asc";
  ASSERT_TRUE(WriteEsriAsciiGrid(ComputeLayers(map), origin, asc.string()));
  const Result<Dem> dem = LoadDem(asc.string());
  ASSERT_TRUE(dem) << dem.error().message;
  EXPECT_FALSE(dem->resampled);
  EXPECT_TRUE(dem->map.geometry().SameAs(map.geometry()));
  EXPECT_NEAR(dem->map.geodetic_origin()->latitude_deg, 46.77, 1e-12);
  EXPECT_NEAR(dem->map.geodetic_origin()->longitude_deg, 23.6, 1e-12);
  for (std::size_t k = 0; k < map.cells().size(); ++k)  // the raster keeps 4 decimals
    EXPECT_NEAR(HeightAt(*dem, k % 8, k / 8), map.at(k).mean_z + 400.0, 5e-5) << k;
}

TEST(Dem, DegreesWithoutAPrjAreRefused) {
  const ScopedTempDir dir("dem_degrees");
  std::ifstream in(std::string(PITCHLAB_TEST_DATA_DIR) + "/dem/SRTMGL3_boulder_240x144.asc");
  WriteText(dir / "srtm.asc", std::string((std::istreambuf_iterator<char>(in)), {}));
  const Result<Dem> dem = LoadDem((dir / "srtm.asc").string());
  ASSERT_FALSE(dem);
  EXPECT_NE(dem.error().message.find("looks like degrees, but no .prj says so"), std::string::npos)
      << dem.error().message;
  WriteText(dir / "srtm.prj", "PROJCS[\"x\",PROJECTION[\"Albers\"],UNIT[\"Meter\",1.0]]");
  const Result<Dem> albers = LoadDem((dir / "srtm.asc").string());
  ASSERT_FALSE(albers);
  EXPECT_NE(albers.error().message.find((dir / "srtm.prj").string() + ": projection 'albers'"),
            std::string::npos)
      << albers.error().message;
}

}  // namespace
}  // namespace pitchlab::mapping
