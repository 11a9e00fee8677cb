// `pitchlab plan` on users' maps through the binary: real DEMs (georeferenced from their .prj, or
// local metres without one), a map_server occupancy grid, bad files refused, --help's defaults.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gdal.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;
using test_support::ScopedTempDir;

const std::string kDemDir = std::string(PITCHLAB_TEST_DATA_DIR) + "/dem/";

TEST(UserMapsCli, PlansOnARealGeographicDemAndWritesWgs84GeoJson) {
  const ScopedTempDir dir("user_maps");
  // 1.7 km east across the West Bijou escarpment, 1 arc-second (~24 x 31 m) SRTM cells.
  const double start_lon = -104.3380, start_lat = 39.5110, goal_lon = -104.3180, goal_lat = 39.5110;
  const CliResult r = cli_test::RunPitchlab(
      "plan " + kDemDir +
          "west_bijou_escarpment_snippet.asc --start -104.3380,39.5110 --goal "
          "-104.3180,39.5110 --json --out " +
          (dir / "p").string(),
      dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["found"].get<bool>());
  EXPECT_TRUE(j["input"]["resampled"].get<bool>());
  EXPECT_EQ(j["input"]["coordinates"], "longitude/latitude [deg]");
  // 24 m cells are coarser than the robot: said on stderr and in plan.json.
  EXPECT_NE(r.err.find("warning: the map's"), std::string::npos) << r.err;
  EXPECT_NE(j["warnings"][0].get<std::string>().find("read as a slope"), std::string::npos);
  // Straight east: at least the 1.72 km between the points (N cos(lat) x 0.02 deg).
  EXPECT_GT(j["length_m"].get<double>(), 1700);
  const nlohmann::json geo = nlohmann::json::parse(Slurp(dir / "p" / "path.geojson"));
  const auto& coords = geo["features"][0]["geometry"]["coordinates"];
  ASSERT_GE(coords.size(), 2u);
  // The path runs between the centres of the cells holding start and goal: within a cell's half
  // diagonal (17 m: 0.0002 deg of longitude, 0.00015 of latitude here) of the points given.
  EXPECT_NEAR(coords.front()[0].get<double>(), start_lon, 2e-4);
  EXPECT_NEAR(coords.front()[1].get<double>(), start_lat, 1.5e-4);
  EXPECT_NEAR(coords.back()[0].get<double>(), goal_lon, 2e-4);
  EXPECT_NEAR(coords.back()[1].get<double>(), goal_lat, 1.5e-4);
  for (const auto& c : coords) {  // heights are the DEM's (1690-1807 m, SOURCES.md)
    EXPECT_GE(c[2].get<double>(), 1690 - 1e-3);
    EXPECT_LE(c[2].get<double>(), 1807 + 1e-3);
  }
}

// The same DEM as a GeoTIFF (GDAL's copy of the .asc and its .prj): the same plan, in the same
// longitude/latitude, the input said to be a raster GDAL read.
TEST(UserMapsCli, PlansOnAGeoTiffAsOnTheSameGridAsAsc) {
  const ScopedTempDir dir("user_maps");
  GDALAllRegister();
  GDALDatasetH in = GDALOpen((kDemDir + "west_bijou_escarpment_snippet.asc").c_str(), GA_ReadOnly);
  ASSERT_NE(in, nullptr);
  const std::string tif = (dir / "bijou.tif").string();
  GDALDatasetH copy = GDALCreateCopy(GDALGetDriverByName("GTiff"), tif.c_str(), in, FALSE,
                                     nullptr, nullptr, nullptr);
  ASSERT_NE(copy, nullptr);
  GDALClose(copy);
  GDALClose(in);
  const std::string points = " --start -104.3380,39.5110 --goal -104.3180,39.5110 --json --out ";
  const CliResult from_tif =
      cli_test::RunPitchlab("plan " + tif + points + (dir / "t").string(), dir.path());
  const CliResult from_asc = cli_test::RunPitchlab(
      "plan " + kDemDir + "west_bijou_escarpment_snippet.asc" + points + (dir / "a").string(),
      dir.path());
  ASSERT_EQ(from_tif.exit_code, 0) << from_tif.err;
  ASSERT_EQ(from_asc.exit_code, 0) << from_asc.err;
  const nlohmann::json t = nlohmann::json::parse(from_tif.out);
  const nlohmann::json a = nlohmann::json::parse(from_asc.out);
  EXPECT_EQ(t["input"]["kind"], "DEM (raster, read by GDAL)");
  EXPECT_EQ(t["input"]["coordinates"], "longitude/latitude [deg]");
  EXPECT_TRUE(t["found"].get<bool>());
  EXPECT_NEAR(t["length_m"].get<double>(), a["length_m"].get<double>(), 1e-6);
  EXPECT_EQ(Slurp(dir / "t" / "path.csv"), Slurp(dir / "a" / "path.csv"));
}

// A file that is no raster, under a raster's name: exit 1 naming it, no output folder.
TEST(UserMapsCli, ATifThatIsNoRasterIsRefusedNamingIt) {
  const ScopedTempDir dir("user_maps");
  std::ofstream(dir / "notes.tif") << "not a raster\n";
  const CliResult r = cli_test::RunPitchlab(
      "plan " + (dir / "notes.tif").string() + " --start 0,0 --goal 1,1 --out " +
          (dir / "p").string(),
      dir.path());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find((dir / "notes.tif").string() + ": cannot be read as a raster"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "p"));
}

TEST(UserMapsCli, PlansOnADemWithoutPrjInItsOwnMetres) {
  const ScopedTempDir dir("user_maps");
  // Down the West Bijou gully's western side, 67 m as the crow flies (3 m cells; the file's
  // easting/northing, no .prj; its floor and walls are steeper than the P3-AT's 19.3 deg).
  const CliResult r =
      cli_test::RunPitchlab("plan " + kDemDir +
                                "west_bijou_gully.asc --start 559727,4380461 --goal 559736,4380395 "
                                "--json --out " +
                                (dir / "p").string(),
                            dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["input"]["resampled"].get<bool>());
  EXPECT_FALSE(fs::exists(dir / "p" / "path.geojson"));
  EXPECT_NE(j["geojson"].get<std::string>().find("not georeferenced"), std::string::npos);
  // The first waypoint is the centre of the start's cell, in the file's own metres:
  // 559705 + 7.5 x 3, 4380220 + 80.5 x 3.
  std::ifstream csv(dir / "p" / "path.csv");
  std::string header, first;
  std::getline(csv, header);
  std::getline(csv, first);
  EXPECT_EQ(first.substr(0, first.find(',', first.find(',', 2) + 1)), "0,559727.5000,4380461.5000")
      << first;
  EXPECT_GE(j["length_m"].get<double>(), std::hypot(9.0, 66.0));
}

TEST(UserMapsCli, PlansOnAMapServerOccupancyGrid) {
  const ScopedTempDir dir("user_maps");
  // 40 x 20 cells of 0.1 m, free but for a wall in column 20 (x 2.0-2.1 m) below y 1.4 m
  // (rows 0-13; image rows 6-19 from the top).
  std::ostringstream pgm;
  pgm << "P2\n40 20\n255\n";
  for (int row = 0; row < 20; ++row)
    for (int col = 0; col < 40; ++col) pgm << (col == 20 && row >= 6 ? 0 : 254) << " ";
  std::ofstream(dir / "room.pgm") << pgm.str();
  std::ofstream(dir / "room.yaml") << "image: room.pgm\nresolution: 0.1\norigin: [0, 0, 0]\n"
                                      "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  const CliResult r = cli_test::RunPitchlab("plan " + (dir / "room.yaml").string() +
                                                " --start 0.5,0.5 --goal 3.5,0.5 --json --out " +
                                                (dir / "p").string(),
                                            dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["found"].get<bool>());
  // Round the wall's end: the P3-AT's footprint (centres closer than 0.2985 m to the wall or
  // the edge blocked) leaves rows 16-17 free at columns 18-22, so from cell (5, 5) up to row 16,
  // 5 columns along it and down to (35, 5): 22 diagonal and 8 straight moves of 0.1 m.
  EXPECT_NEAR(j["length_m"].get<double>(), 0.1 * (22 * M_SQRT2 + 8), 1e-4);
  EXPECT_TRUE(fs::exists(dir / "p" / "traversability.png"));
  EXPECT_TRUE(fs::exists(dir / "p" / "path.png"));
  EXPECT_FALSE(fs::exists(dir / "p" / "elevation.png"));  // no heights in an occupancy grid
  EXPECT_EQ(j["input"]["kind"], "map_server occupancy grid");
}

TEST(UserMapsCli, BadUserMapsAreRefusedNamingFileAndLineWithNothingWritten) {
  const ScopedTempDir dir("user_maps");
  std::ofstream(dir / "bad.asc") << "ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n"
                                    "1 2\n3 oops\n";
  std::ofstream(dir / "bad.yaml") << "image: m.pgm\nresolution: 0.1\nresolution: 0.2\n";
  std::ofstream(dir / "map.tif") << "II*";  // a TIFF's byte order and nothing after it
  std::ofstream(dir / "map.png") << "\x89PNG";
  const struct {
    std::string map, message;
    int exit_code;
  } cases[] = {
      {(dir / "bad.asc").string(), (dir / "bad.asc").string() + ":7: 'oops' is not a finite", 1},
      {(dir / "bad.yaml").string(), (dir / "bad.yaml").string() + ":3: 'resolution' is given twice",
       1},
      {(dir / "map.tif").string(),
       (dir / "map.tif").string() + ": cannot be read as a raster: Cannot read TIFF header", 1},
      {(dir / "map.png").string(), "must be a .plem", 2},
  };
  for (const auto& c : cases) {
    const CliResult r = cli_test::RunPitchlab(
        "plan " + c.map + " --start 0,0 --goal 1,1 --out " + (dir / "p").string(), dir.path());
    EXPECT_EQ(r.exit_code, c.exit_code) << c.map << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "p")) << c.map;
  }
}

TEST(UserMapsCli, PlanHelpStatesEveryDefault) {
  const ScopedTempDir dir("user_maps");
  const CliResult r = cli_test::RunPitchlab("plan --help", dir.path());
  ASSERT_EQ(r.exit_code, 0);
  for (const char* text :
       {"robot p3at: step 0.089 m, inclination 19.3 deg, 0.497 m wide, 0.508 m long",
        "weights: roughness 10, length 1, inclination_x 1, inclination_y 1",
        "unknown: forbid (unknown_penalty 1 when penalise)", "clearance_m 0, clearance_cost 0",
        "algorithm astar", "MAP.asc", "MAP.yaml", "coarser than the robot"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text << "\n" << r.out;
}

}  // namespace
}  // namespace pitchlab
