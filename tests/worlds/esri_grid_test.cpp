// The ESRI ASCII loader on real DEMs and on broken files, and DEM placement on the Earth.
#include <sys/wait.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "pitchlab/worlds/dem_projection.hpp"
#include "pitchlab/worlds/dem_world.hpp"
#include "pitchlab/worlds/esri_grid.hpp"
#include "test_support.hpp"

namespace pitchlab::worlds {
namespace {

const std::filesystem::path kDemDir = std::filesystem::path(PITCHLAB_TEST_DATA_DIR) / "dem";

// Independent min / max / NODATA count: skip six header lines, read numbers with >>.
struct Stats {
  double min = std::numeric_limits<double>::infinity();
  double max = -std::numeric_limits<double>::infinity();
  int nodata = 0;
  int count = 0;
};
Stats IndependentStats(const std::filesystem::path& path, double nodata) {
  std::ifstream in(path);
  std::string line;
  for (int i = 0; i < 6; ++i) std::getline(in, line);
  Stats s;
  double v = 0;
  while (in >> v) {
    ++s.count;
    if (v == nodata) {
      ++s.nodata;
      continue;
    }
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  return s;
}

Stats LoaderStats(const EsriGrid& grid) {
  Stats s;
  for (double v : grid.values) {
    ++s.count;
    if (std::isnan(v)) {
      ++s.nodata;
      continue;
    }
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  return s;
}

struct RealDem {
  const char* file;
  int ncols, nrows;
  double nodata, min_m, max_m;  // heights [m] from SOURCES.md, rounded (SRTM max: the file's)
};

void PrintTo(const RealDem& dem, std::ostream* os) { *os << dem.file; }

class RealDemFile : public ::testing::TestWithParam<RealDem> {};

TEST_P(RealDemFile, LoadsWithTheHeaderCountsAndHeightRange) {
  const RealDem& dem = GetParam();
  const EsriGrid grid = LoadEsriGrid(kDemDir / dem.file);
  EXPECT_EQ(grid.ncols, dem.ncols);
  EXPECT_EQ(grid.nrows, dem.nrows);
  ASSERT_TRUE(grid.nodata_value);
  EXPECT_EQ(*grid.nodata_value, dem.nodata);
  const Stats expected = IndependentStats(kDemDir / dem.file, dem.nodata);
  const Stats got = LoaderStats(grid);
  EXPECT_EQ(got.count, dem.ncols * dem.nrows);
  EXPECT_EQ(got.count, expected.count);
  EXPECT_EQ(got.nodata, expected.nodata);
  EXPECT_EQ(got.min, expected.min);
  EXPECT_EQ(got.max, expected.max);
  constexpr double kSourcesRounding_m = 1.0;
  EXPECT_NEAR(got.min, dem.min_m, kSourcesRounding_m);
  EXPECT_NEAR(got.max, dem.max_m, kSourcesRounding_m);
}

INSTANTIATE_TEST_SUITE_P(
    SharedData, RealDemFile,
    ::testing::Values(RealDem{"west_bijou_gully.asc", 43, 89, 0, 1680.8, 1725.4},
                      RealDem{"hugo_site.asc", 76, 55, -9999, 1660, 1711},
                      RealDem{"west_bijou_escarpment_snippet.asc", 129, 67, -32768, 1690, 1807},
                      RealDem{"SRTMGL3_boulder_240x144.asc", 240, 144, 0, 1943, 3286}),
    [](const auto& info) {
      std::string name = info.param.file;
      return name.substr(0, name.find('.'));
    });

EsriGrid Parse(const std::string& text) {
  std::istringstream in(text);
  return ParseEsriGrid(in, "test.asc");
}

// The message of the exception `text` raises, or "" when it parses.
std::string ParseError(const std::string& text) {
  try {
    Parse(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(EsriGrid, HeaderFieldsInAnyOrderAndCaseWithCellCentres) {
  const EsriGrid grid = Parse(
      "CELLSIZE 2\nNRows 2\nnodata_value -1\nyllcenter 11\nNCOLS 3\nXLLCENTER 101\n"
      "1 2 3\n4 -1 6\n");
  EXPECT_EQ(grid.ncols, 3);
  EXPECT_EQ(grid.nrows, 2);
  EXPECT_DOUBLE_EQ(grid.xll_corner, 100.0);
  EXPECT_DOUBLE_EQ(grid.yll_corner, 10.0);
  EXPECT_DOUBLE_EQ(grid.At(0, 2), 3.0);  // row 0 is the northern row
  EXPECT_TRUE(std::isnan(grid.At(1, 1)));
  EXPECT_DOUBLE_EQ(grid.RowY(0), 13.0);
  EXPECT_DOUBLE_EQ(grid.ColumnX(2), 105.0);
}

TEST(EsriGrid, NodataIsOptional) {
  const EsriGrid grid = Parse("ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5 0\n");
  EXPECT_FALSE(grid.nodata_value);
  EXPECT_EQ(grid.At(0, 1), 0.0);
}

TEST(EsriGrid, CorruptFilesRaiseErrorsNamingTheFileLineAndProblem) {
  const std::string header = "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n";
  EXPECT_NE(
      ParseError(header + "1 2\n3\n").find("expected nrows x ncols = 2 x 2 = 4 values, found 3"),
      std::string::npos);
  EXPECT_NE(ParseError(header + "1 2\n3 4 5\n").find("test.asc:7: more values"), std::string::npos);
  EXPECT_NE(ParseError(header + "1 2\n3 x4\n").find("test.asc:7: non-numeric value 'x4'"),
            std::string::npos);
  EXPECT_NE(ParseError("1 2\n3 4\n").find("missing header"), std::string::npos);
  EXPECT_NE(ParseError("ncols 2\nnrows 2\nxllcorner 0\ncellsize 1\n1 2 3 4\n")
                .find("need exactly one of 'yllcorner' and 'yllcenter'"),
            std::string::npos);
  EXPECT_NE(ParseError("ncols 2\nncols 2\n").find("test.asc:2: duplicate header field"),
            std::string::npos);
  EXPECT_NE(ParseError("ncols 2.5\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3 4\n")
                .find("test.asc:1: header field 'ncols' must be a positive integer"),
            std::string::npos);
  EXPECT_NE(ParseError("ncols 1\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize -3\n1\n")
                .find("'cellsize' must be positive"),
            std::string::npos);
  EXPECT_NE(ParseError("ncols two\n").find("test.asc:1: header field 'ncols' needs one number"),
            std::string::npos);
}

// A 10 x 8 grid of 2 m x 1 m cells, its west edge at x = 100, south edge at y = 200, each cell's
// value 100 * row + col: the crop keeps exactly the cells whose centres lie in the area, edges
// included, with their values and corner; an area that holds fewer than 2 x 2 centres is refused
// naming the grid's extent.
TEST(EsriGrid, CropKeepsTheCellsWhoseCentresLieInTheArea) {
  EsriGrid grid;
  grid.ncols = 10;
  grid.nrows = 8;
  grid.xll_corner = 100;
  grid.yll_corner = 200;
  grid.cell_size = 2;
  grid.cell_size_y = 1;
  for (int row = 0; row < 8; ++row)
    for (int col = 0; col < 10; ++col) grid.values.push_back(100.0 * row + col);
  // Column centres 101, 103, ..., 119; row centres 207.5 (row 0) down to 200.5 (row 7).
  const EsriGrid crop = CropToArea(grid, GridArea{103, 202.5, 109.5, 205});
  EXPECT_EQ(crop.ncols, 4);  // centres 103 (on the edge), 105, 107, 109
  EXPECT_EQ(crop.nrows, 3);  // centres 204.5, 203.5, 202.5 (on the edge): rows 3, 4, 5
  EXPECT_DOUBLE_EQ(crop.xll_corner, 102);
  EXPECT_DOUBLE_EQ(crop.yll_corner, 202);
  EXPECT_DOUBLE_EQ(crop.cell_size_y, 1);
  ASSERT_EQ(crop.values.size(), 12u);
  EXPECT_EQ(crop.At(0, 0), 301);
  EXPECT_EQ(crop.At(2, 3), 504);
  EXPECT_DOUBLE_EQ(crop.ColumnX(0), 103);
  EXPECT_DOUBLE_EQ(crop.RowY(2), 202.5);
  // Reaching past the grid keeps what is there.
  EXPECT_EQ(CropToArea(grid, GridArea{0, 0, 1000, 1000}).values, grid.values);
  try {
    CropToArea(grid, GridArea{104, 201, 105.5, 209});  // one column centre (105)
    FAIL() << "a one-column area was cropped";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the grid spans x 101 .. 119, y 200.5 .. 207.5"),
              std::string::npos)
        << e.what();
  }
}

TEST(EsriGrid, MissingAndBadFilesOnDiskNameThePath) {
  const test::ScopedTempDir dir("esri_bad");
  const auto bad = dir.path() / "bad.asc";
  test::WriteText(bad, "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 nan\n");
  try {
    LoadEsriGrid(bad);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad.string() + ":6: non-numeric value 'nan'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(LoadEsriGrid(dir.path() / "missing.asc"), std::runtime_error);
}

TEST(EsriGrid, PrjWithGeogcsMarksAGeographicGrid) {
  EXPECT_TRUE(HasGeographicPrj(kDemDir / "west_bijou_escarpment_snippet.asc"));
  EXPECT_FALSE(HasGeographicPrj(kDemDir / "west_bijou_gully.asc"));
}

TEST(DemProjection, LonLatGridSpansItsArcSecondsInMetres) {
  const EsriGrid dem = LoadEsriGrid(kDemDir / "west_bijou_escarpment_snippet.asc");
  const ProjectedDem projected = ProjectDem(dem, {DemCoordinates::kGeographic}, 10.0);
  // 1 arc-second at 39.5 deg N: ~30.9 m north-south, ~23.8 m east-west. The grid spans the
  // valid cell centres (no NODATA here), less up to one output cell of rounding.
  const double expected_ew_m = (dem.ncols - 1) * 23.85, expected_ns_m = (dem.nrows - 1) * 30.87;
  constexpr double kArcSecondModel = 0.005;  // relative error of the rounded per-second lengths
  const double width_m = projected.grid.XMax_m() - projected.grid.x0_m;
  const double height_m = projected.grid.YMax_m() - projected.grid.y0_m;
  EXPECT_NEAR(width_m, expected_ew_m, expected_ew_m * kArcSecondModel + 10.0);
  EXPECT_NEAR(height_m, expected_ns_m, expected_ns_m * kArcSecondModel + 10.0);
  ASSERT_TRUE(projected.geodetic_origin);
  EXPECT_NEAR(projected.geodetic_origin->latitude_deg, dem.RowY(0.5 * (dem.nrows - 1)), 1e-9);
  // Heights stay heights: the range is the DEM's.
  EXPECT_NEAR(projected.grid.MaxHeight_m() - projected.grid.MinHeight_m(), 1807 - 1690, 5.0);
}

TEST(DemProjection, UtmGullyOriginLiesEastOfDenver) {
  const EsriGrid dem = LoadEsriGrid(kDemDir / "west_bijou_gully.asc");
  const ProjectedDem projected = ProjectDem(dem, ParseUtmZone("13N"), 1.0);
  ASSERT_TRUE(projected.geodetic_origin);
  EXPECT_NEAR(projected.geodetic_origin->latitude_deg, 39.56, 0.02);
  EXPECT_NEAR(projected.geodetic_origin->longitude_deg, -104.30, 0.02);
  // NODATA (0) never reaches the surface: every height is within the valid range.
  EXPECT_GT(projected.grid.MinHeight_m() + projected.origin_height_m, 1680.0);
  EXPECT_LT(projected.grid.MaxHeight_m() + projected.origin_height_m, 1726.0);
}

TEST(DemProjection, LocalGridCropsNodataAndKeepsItsScale) {
  const EsriGrid dem = LoadEsriGrid(kDemDir / "hugo_site.asc");
  const ProjectedDem projected = ProjectDem(dem, {DemCoordinates::kLocal}, 5.0);
  EXPECT_FALSE(projected.geodetic_origin);
  EXPECT_LE(projected.grid.XMax_m() - projected.grid.x0_m, 75 * 10.0);
  EXPECT_GT(projected.grid.XMax_m() - projected.grid.x0_m, 100.0);
  constexpr double kCubicOvershoot_m = 1.0;
  EXPECT_GT(projected.grid.MinHeight_m() + projected.origin_height_m, 1660.0 - kCubicOvershoot_m);
  EXPECT_LT(projected.grid.MaxHeight_m() + projected.origin_height_m, 1711.0 + kCubicOvershoot_m);
}

TEST(DemProjection, UtmZoneTextIsValidated) {
  EXPECT_EQ(ParseUtmZone("13N").utm_zone, 13);
  EXPECT_FALSE(ParseUtmZone("33s").northern_hemisphere);
  for (const char* bad : {"61N", "0N", "13", "13X", "N13", ""}) {
    EXPECT_THROW(ParseUtmZone(bad), std::invalid_argument) << bad;
  }
}

TEST(DemWorld, SrtmWithoutPrjNeedsExplicitCoordinatesThenBuilds) {
  DemWorldConfig config;
  config.dem_path = kDemDir / "SRTMGL3_boulder_240x144.asc";
  config.cell_m = 90.0;
  try {
    BuildDemWorld(config);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("looks like degrees"), std::string::npos) << e.what();
  }
  config.placement = DemPlacement{DemCoordinates::kGeographic};
  const DemWorld world = BuildDemWorld(config);
  // 3 arc-seconds at 40.15 deg N: ~70.9 m east-west, ~92.6 m north-south.
  EXPECT_NEAR(world.grid.XMax_m() - world.grid.x0_m, 239 * 70.9, 239 * 70.9 * 0.01 + 90.0);
  EXPECT_NEAR(world.grid.YMax_m() - world.grid.y0_m, 143 * 92.6, 143 * 92.6 * 0.01 + 90.0);
  ASSERT_TRUE(world.metadata.geodetic_origin);
  EXPECT_NEAR(world.metadata.geodetic_origin->longitude_deg, -105.45, 0.05);
}

TEST(DemWorld, TooFineACellForABigDemSaysWhichCellWorks) {
  DemWorldConfig config;
  config.dem_path = kDemDir / "SRTMGL3_boulder_240x144.asc";
  config.placement = DemPlacement{DemCoordinates::kGeographic};
  config.cell_m = 0.2;
  try {
    BuildDemWorld(config);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("needs a cell of at least"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("SRTMGL3_boulder_240x144.asc"), std::string::npos);
  }
}

// Exit codes as pitchlab's: 0 done, 2 a mistake on the command line (with a pointer to --help),
// 1 a problem with what it names (a missing DEM); nothing written either way.
TEST(Worldgen, CommandLineGivesHelpAndExitsTwoOnMistakesOneOnBadInput) {
  const std::string exe = PITCHLAB_WORLDGEN_EXE;
  const test::ScopedTempDir dir("cli");
  const auto exit_code = [&](const std::string& args) {
    const int status = std::system((exe + " " + args + " > /dev/null 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(exit_code("--help"), 0);
  EXPECT_EQ(exit_code("dem --help"), 0);
  EXPECT_EQ(exit_code(""), 2);
  EXPECT_EQ(exit_code("moon"), 2);
  const std::string dem = (kDemDir / "west_bijou_escarpment_snippet.asc").string();
  const std::string out = (dir.path() / "x.xml").string();
  for (const std::string& mistake :
       {"dem --in " + dem + " --cell abc --out " + out, "dem --in " + dem,
        "dem --in " + dem + " --out " + (dir.path() / "x.txt").string(),
        "dem --in " + dem + " --bogus 1 --out " + out,
        "dem --in " + dem + " --utm-zone 61Q --out " + out,
        "dem --in " + dem + " --local --geographic --out " + out, "terrain --seed -1 --out " + out,
        "dem --in " + dem + " --out"}) {
    EXPECT_EQ(exit_code(mistake), 2) << mistake;
  }
  EXPECT_EQ(exit_code("dem --in /nonexistent.asc --out " + out), 1);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  const auto esc = dir.path() / "esc.xml";
  EXPECT_EQ(exit_code("dem --in " + dem + " --cell 20 --relief-seed 5 --out " + esc.string()), 0);
  EXPECT_TRUE(test::LoadModel(esc));
}

}  // namespace
}  // namespace pitchlab::worlds
