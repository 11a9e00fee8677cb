// `pitchlab_worldgen dem` on DEMs as users get them: GeoTIFFs (written here by GDAL, the peer,
// from our test grids) build the very world their ESRI grid builds, placed from the coordinate
// system the file carries; coordinate systems a world cannot be placed in are refused naming the
// file, and leave nothing.

#include <sys/wait.h>

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "gdal_peer.hpp"
#include "pitchlab/worlds/world_metadata.hpp"
#include "test_support.hpp"

namespace pitchlab::worlds {
namespace {

namespace fs = std::filesystem;
using ::test_support::CopyAsGeoTiff;

const fs::path kDemDir = fs::path(PITCHLAB_TEST_DATA_DIR) / "dem";

struct Outcome {
  int exit_code = -1;
  std::string err;
};

// pitchlab_worldgen with `args`; its exit code and what it wrote to stderr.
Outcome Worldgen(const std::string& args, const fs::path& scratch) {
  const fs::path err = scratch / "stderr.txt";
  const std::string command =
      std::string(PITCHLAB_WORLDGEN_EXE) + " " + args + " > /dev/null 2> " + err.string();
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test::ReadBytes(err)};
}

// Two worlds are one: the same placement on the Earth and bounds, and the same ground under a
// 9 x 9 grid of points across them (the GeoTIFF's float32 heights: 0.1 mm at 2000 m).
void ExpectSameWorld(const fs::path& a, const fs::path& b) {
  const test::ModelPtr ma = test::LoadModel(a), mb = test::LoadModel(b);
  ASSERT_TRUE(ma && mb);
  const WorldMetadata wa = ReadWorldMetadata(ma.get()), wb = ReadWorldMetadata(mb.get());
  ASSERT_EQ(wa.geodetic_origin.has_value(), wb.geodetic_origin.has_value());
  if (wa.geodetic_origin) {
    EXPECT_NEAR(wa.geodetic_origin->latitude_deg, wb.geodetic_origin->latitude_deg, 1e-9);
    EXPECT_NEAR(wa.geodetic_origin->longitude_deg, wb.geodetic_origin->longitude_deg, 1e-9);
    EXPECT_NEAR(wa.geodetic_origin->height_m, wb.geodetic_origin->height_m, 2e-3);
  }
  EXPECT_NEAR(wa.bounds.x_min_m, wb.bounds.x_min_m, 1e-6);
  EXPECT_NEAR(wa.bounds.x_max_m, wb.bounds.x_max_m, 1e-6);
  EXPECT_NEAR(wa.bounds.y_min_m, wb.bounds.y_min_m, 1e-6);
  EXPECT_NEAR(wa.bounds.y_max_m, wb.bounds.y_max_m, 1e-6);
  const test::DataPtr da(mj_makeData(ma.get())), db(mj_makeData(mb.get()));
  mj_forward(ma.get(), da.get());
  mj_forward(mb.get(), db.get());
  const Bounds2d& box = wa.bounds;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; j <= 8; ++j) {
      const double x = box.x_min_m + (box.x_max_m - box.x_min_m) * i / 8.0;
      const double y = box.y_min_m + (box.y_max_m - box.y_min_m) * j / 8.0;
      const double za = test::SurfaceHeight(ma.get(), da.get(), x, y);
      ASSERT_FALSE(std::isnan(za)) << x << ", " << y;
      EXPECT_NEAR(test::SurfaceHeight(mb.get(), db.get(), x, y), za, 2e-3) << x << ", " << y;
    }
  }
}

// A UTM DEM (the West Bijou gully, 3 m, UTM 13N, an .asc with no .prj) as a GeoTIFF that says
// UTM 13N: placed from the file alone, it is the world the .asc builds with --utm-zone 13N.
TEST(WorldgenDem, AUtmGeoTiffIsTheWorldItsAscBuildsWithTheZoneGiven) {
  const test::ScopedTempDir dir("worldgen_dem");
  const fs::path asc = kDemDir / "west_bijou_gully.asc";
  CopyAsGeoTiff(asc, dir / "gully.tif", 32613);
  const std::string common = " --cell 1 --relief-seed 4";
  const Outcome from_asc = Worldgen("dem --in " + asc.string() + " --utm-zone 13N" + common +
                                        " --out " + (dir / "asc.xml").string(),
                                    dir.path());
  ASSERT_EQ(from_asc.exit_code, 0) << from_asc.err;
  const Outcome from_tif =
      Worldgen("dem --in " + (dir / "gully.tif").string() + common + " --out " +
                   (dir / "tif.xml").string(),
               dir.path());
  ASSERT_EQ(from_tif.exit_code, 0) << from_tif.err;
  ExpectSameWorld(dir / "asc.xml", dir / "tif.xml");
  // The provenance names the placement read from the file.
  EXPECT_NE(test::ReadBytes(dir / "tif.xml").find("UTM 13N"), std::string::npos);
}

// An .asc whose .prj says UTM needs no --utm-zone either (it once did: only GEOGCS was read).
TEST(WorldgenDem, AnAscWithAUtmPrjIsPlacedByIt) {
  const test::ScopedTempDir dir("worldgen_dem");
  fs::copy_file(kDemDir / "west_bijou_gully.asc", dir / "gully.asc");
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  ASSERT_EQ(OSRImportFromEPSG(srs, 32613), OGRERR_NONE);
  ASSERT_EQ(OSRMorphToESRI(srs), OGRERR_NONE);
  char* wkt = nullptr;
  OSRExportToWkt(srs, &wkt);
  test::WriteText(dir / "gully.prj", wkt);
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  const std::string common = " --cell 1";
  ASSERT_EQ(Worldgen("dem --in " + (dir / "gully.asc").string() + common + " --out " +
                         (dir / "prj.xml").string(),
                     dir.path())
                .exit_code,
            0);
  ASSERT_EQ(Worldgen("dem --in " + (kDemDir / "west_bijou_gully.asc").string() +
                         " --utm-zone 13N" + common + " --out " + (dir / "zone.xml").string(),
                     dir.path())
                .exit_code,
            0);
  ExpectSameWorld(dir / "prj.xml", dir / "zone.xml");
}

// A longitude/latitude DEM (1" SRTM) as a GeoTIFF is the world its .asc and GEOGCS .prj build.
TEST(WorldgenDem, AGeographicGeoTiffIsTheWorldItsAscBuilds) {
  const test::ScopedTempDir dir("worldgen_dem");
  const fs::path asc = kDemDir / "west_bijou_escarpment_snippet.asc";
  CopyAsGeoTiff(asc, dir / "bijou.tif");
  ASSERT_EQ(
      Worldgen("dem --in " + asc.string() + " --cell 2 --out " + (dir / "asc.xml").string(),
               dir.path())
          .exit_code,
      0);
  const Outcome tif = Worldgen(
      "dem --in " + (dir / "bijou.tif").string() + " --cell 2 --out " + (dir / "tif.xml").string(),
      dir.path());
  ASSERT_EQ(tif.exit_code, 0) << tif.err;
  ExpectSameWorld(dir / "asc.xml", dir / "tif.xml");
}

// A raster of oblong cells (2 m west to east, 1 m south to north, as Copernicus' 1.5" x 1" are
// oblong) whose heights rise 0.1 per metre east and 0.2 per metre north: the world's ground rises
// the same (bicubic resampling keeps a plane), which a grid read with square cells would not.
TEST(WorldgenDem, OblongCellsKeepTheirSpacing) {
  const test::ScopedTempDir dir("worldgen_dem");
  const int nx = 30, ny = 60;
  GDALAllRegister();
  GDALDatasetH d = GDALCreate(GDALGetDriverByName("GTiff"), (dir / "oblong.tif").string().c_str(),
                              nx, ny, 1, GDT_Float32, nullptr);
  ASSERT_NE(d, nullptr);
  double gt[6] = {0, 2, 0, 60, 0, -1};  // west edge 0, north edge 60 m
  GDALSetGeoTransform(d, gt);
  std::vector<float> z(static_cast<std::size_t>(nx) * ny);
  for (int row = 0; row < ny; ++row)
    for (int col = 0; col < nx; ++col)
      z[row * nx + col] = static_cast<float>(0.1 * (2 * col + 1) + 0.2 * (60 - row - 0.5));
  ASSERT_EQ(GDALRasterIO(GDALGetRasterBand(d, 1), GF_Write, 0, 0, nx, ny, z.data(), nx, ny,
                         GDT_Float32, 0, 0),
            CE_None);
  GDALClose(d);
  const fs::path out = dir / "oblong.xml";
  const Outcome built = Worldgen(
      "dem --in " + (dir / "oblong.tif").string() + " --local --cell 0.5 --out " + out.string(),
      dir.path());
  ASSERT_EQ(built.exit_code, 0) << built.err;
  const test::ModelPtr m = test::LoadModel(out);
  ASSERT_TRUE(m);
  const test::DataPtr data(mj_makeData(m.get()));
  mj_forward(m.get(), data.get());
  const WorldMetadata w = ReadWorldMetadata(m.get());
  // The valid data span 58 x 59 m between cell centres, centred on the origin.
  EXPECT_NEAR(w.bounds.x_max_m - w.bounds.x_min_m, 58.0 - 2.0, 0.5);
  EXPECT_NEAR(w.bounds.y_max_m - w.bounds.y_min_m, 59.0 - 2.0, 0.5);
  const double z0 = test::SurfaceHeight(m.get(), data.get(), 0, 0);
  for (const auto& [x, y] : {std::pair{10.0, 0.0}, {0.0, 10.0}, {-12.0, 20.0}, {20.0, -25.0}}) {
    EXPECT_NEAR(test::SurfaceHeight(m.get(), data.get(), x, y) - z0, 0.1 * x + 0.2 * y, 2e-3)
        << x << ", " << y;
  }
}

// --area builds the part of a DEM in the rectangle: heights rising 0.1 per metre east and 0.2
// per metre north over 200 x 150 m of 5 m cells; the part between x 50 .. 100 and y 20 .. 60 is
// a world 50 x 40 m (between its outer cell centres, less the bounds' 1 m margin) whose origin
// lies at the part's centre, at its height there. Mistakes in the option exit 2; an area beside
// the DEM exits 1 naming the DEM's extent.
TEST(WorldgenDem, AnAreaBuildsThatPartOfTheDem) {
  const test::ScopedTempDir dir("worldgen_dem");
  std::string text = "ncols 40\nnrows 30\nxllcorner 0\nyllcorner 0\ncellsize 5\n";
  for (int row = 0; row < 30; ++row) {
    for (int col = 0; col < 40; ++col) {
      const double x = 5 * col + 2.5, y = 5 * (29 - row) + 2.5;
      text += std::to_string(0.1 * x + 0.2 * y) + " ";
    }
    text += "\n";
  }
  test::WriteText(dir / "plane.asc", text);
  const fs::path out = dir / "part.xml";
  const Outcome built = Worldgen("dem --in " + (dir / "plane.asc").string() +
                                     " --local --area 50,20,100,60 --cell 1 --out " + out.string(),
                                 dir.path());
  ASSERT_EQ(built.exit_code, 0) << built.err;
  const test::ModelPtr m = test::LoadModel(out);
  ASSERT_TRUE(m);
  const WorldMetadata w = ReadWorldMetadata(m.get());
  // Centres 52.5 .. 97.5 and 22.5 .. 57.5: 45 x 35 m, less 1 m each side.
  EXPECT_NEAR(w.bounds.x_max_m - w.bounds.x_min_m, 43.0, 1.0);
  EXPECT_NEAR(w.bounds.y_max_m - w.bounds.y_min_m, 33.0, 1.0);
  const std::string xml = test::ReadBytes(out);
  const std::size_t at = xml.find("origin height ");
  ASSERT_NE(at, std::string::npos) << xml.substr(0, 300);
  // The part's centre (75, 40): 0.1 * 75 + 0.2 * 40.
  EXPECT_NEAR(std::stod(xml.substr(at + 14)), 15.5, 0.01);

  for (const char* bad : {"50,20,100", "50,20,40,60", "a,b,c,d", "50,20,100,60,1"}) {
    const Outcome mistake = Worldgen("dem --in " + (dir / "plane.asc").string() +
                                         " --local --area " + bad + " --out " + out.string(),
                                     dir.path());
    EXPECT_EQ(mistake.exit_code, 2) << bad << ": " << mistake.err;
  }
  const fs::path beside = dir / "beside.xml";
  const Outcome outside = Worldgen("dem --in " + (dir / "plane.asc").string() +
                                       " --local --area 500,500,600,600 --out " + beside.string(),
                                   dir.path());
  EXPECT_EQ(outside.exit_code, 1);
  EXPECT_NE(outside.err.find("the grid spans x 2.5 .. 197.5, y 2.5 .. 147.5"), std::string::npos)
      << outside.err;
  EXPECT_FALSE(fs::exists(beside));
}

// Coordinate systems a world cannot be placed in are refused naming the file and the way out,
// and leave no world; with --local the same file builds (x, y read as metres). Not a raster at
// all: refused naming it.
TEST(WorldgenDem, ACoordinateSystemAWorldCannotTakeIsRefusedNamingTheFile) {
  const test::ScopedTempDir dir("worldgen_dem");
  const fs::path asc = kDemDir / "west_bijou_gully.asc";
  struct Case {
    int epsg;
    const char* file;
    const char* message;
  };
  const Case cases[] = {
      {2193, "nztm.tif", "is a Transverse Mercator but not UTM"},  // New Zealand TM 2000
      {2154, "lambert.tif", "lambert_conformal_conic"},            // France, Lambert-93
  };
  for (const Case& c : cases) {
    CopyAsGeoTiff(asc, dir / c.file, c.epsg);
    const fs::path out = dir / (std::string(c.file) + ".xml");
    const Outcome refused =
        Worldgen("dem --in " + (dir / c.file).string() + " --cell 3 --out " + out.string(),
                 dir.path());
    EXPECT_EQ(refused.exit_code, 1) << c.file;
    EXPECT_NE(refused.err.find((dir / c.file).string()), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find(c.message), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("--local"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(out)) << c.file;
    const Outcome local = Worldgen(
        "dem --in " + (dir / c.file).string() + " --local --cell 3 --out " + out.string(),
        dir.path());
    EXPECT_EQ(local.exit_code, 0) << c.file << ": " << local.err;
    EXPECT_TRUE(test::LoadModel(out)) << c.file;
  }
  // A header asking for 10^16 cells is refused before they are allocated (it died of
  // std::bad_alloc): the file cannot hold them.
  test::WriteText(dir / "huge.asc",
                  "ncols 100000000\nnrows 100000000\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2\n");
  const Outcome huge = Worldgen(
      "dem --in " + (dir / "huge.asc").string() + " --local --out " + (dir / "huge.xml").string(),
      dir.path());
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_NE(huge.err.find("huge.asc:6: nrows x ncols = 100000000 x 100000000 = "
                          "10000000000000000 values, more than the file's 71 bytes can hold"),
            std::string::npos)
      << huge.err;
  EXPECT_FALSE(fs::exists(dir / "huge.xml"));
  test::WriteText(dir / "photo.tif", "this is no raster\n");
  const fs::path out = dir / "photo.xml";
  const Outcome junk =
      Worldgen("dem --in " + (dir / "photo.tif").string() + " --out " + out.string(), dir.path());
  EXPECT_EQ(junk.exit_code, 1);
  EXPECT_NE(junk.err.find((dir / "photo.tif").string()), std::string::npos) << junk.err;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace pitchlab::worlds
