// Crafted maps and the paths they would give (issue 18): a .plem whose hash is valid but whose
// numbers are not a map's is refused on load, and no path file ever holds a non-finite number.

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/elevation_io.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/planning/path_io.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using mapping::ElevationMap;
using mapping::GridGeometry;

class CorruptMap : public ::testing::Test {
 protected:
  // A 4 x 3 map of a flat floor at 1 m, saved (so with a valid hash) after `edit`.
  std::string Saved(GridGeometry g, const std::function<void(std::vector<mapping::CellStats>&)>&
                                        edit = [](auto&) {}) {
    ElevationMap map(g, mapping::GeodeticOrigin{46.77, 23.59, 360});
    std::vector<mapping::CellStats> cells(g.cell_count());
    for (auto& c : cells) c.count = 1, c.mean_z = c.min_z = c.max_z = 1.0f;
    edit(cells);
    map.SetCells(std::move(cells));
    const std::string path = (dir_ / "m.plem").string();
    EXPECT_TRUE(mapping::SaveElevationMap(map, path));
    return path;
  }
  const test_support::ScopedTempDir dir_{"corrupt_map"};
};

TEST_F(CorruptMap, AnInfiniteCellSizeIsRefusedOnLoad) {
  GridGeometry g = GridGeometry::FromArea(0, 0, 0.4, 0.3, 0.1);
  g.cell_m = std::numeric_limits<double>::infinity();
  const auto loaded = mapping::LoadElevationMap(Saved(g));
  ASSERT_FALSE(loaded);
  EXPECT_NE(loaded.error().message.find("cell size inf m is not finite"), std::string::npos)
      << loaded.error().message;
}

TEST_F(CorruptMap, ANanHeightInAKnownCellIsRefusedOnLoad) {
  const GridGeometry g = GridGeometry::FromArea(0, 0, 0.4, 0.3, 0.1);
  const auto loaded = mapping::LoadElevationMap(
      Saved(g, [](auto& cells) { cells[5].mean_z = std::numeric_limits<float>::quiet_NaN(); }));
  ASSERT_FALSE(loaded);
  EXPECT_NE(loaded.error().message.find("cell 5 (column 1, row 1) holds a non-finite value"),
            std::string::npos)
      << loaded.error().message;
}

// A second highest point above the highest (or a second extreme missing from a cell of several
// points) is no cell's statistics: the step rule would read a step that no point holds.
TEST_F(CorruptMap, SecondExtremesOutsideTheExtremesAreRefusedOnLoad) {
  const GridGeometry g = GridGeometry::FromArea(0, 0, 0.4, 0.3, 0.1);
  const auto above = mapping::LoadElevationMap(Saved(g, [](auto& cells) {
    cells[7].count = 3;
    cells[7].next_min_z = 1.0f;
    cells[7].next_max_z = 1.5f;
  }));
  ASSERT_FALSE(above);
  EXPECT_NE(above.error().message.find("cell 7 has second extremes (1, 1.5) outside its "
                                       "extremes (1, 1)"),
            std::string::npos)
      << above.error().message;
  const auto missing = mapping::LoadElevationMap(Saved(g, [](auto& cells) { cells[2].count = 2; }));
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("cell 2 has second extremes (inf, -inf)"),
            std::string::npos)
      << missing.error().message;
}

TEST_F(CorruptMap, AnIntactMapStillLoads) {
  const auto loaded = mapping::LoadElevationMap(Saved(GridGeometry::FromArea(0, 0, 0.4, 0.3, 0.1)));
  ASSERT_TRUE(loaded) << loaded.error().message;
}

TEST_F(CorruptMap, AFolderATruncatedAndAnEmptyFileAreRefusedByName) {
  const auto folder = mapping::LoadElevationMap(dir_.path().string());
  ASSERT_FALSE(folder);
  EXPECT_NE(folder.error().message.find(dir_.path().string() + ": cannot read"), std::string::npos)
      << folder.error().message;
  const std::string saved = Saved(GridGeometry::FromArea(0, 0, 0.4, 0.3, 0.1));
  fs::resize_file(saved, fs::file_size(saved) - 1);
  const auto truncated = mapping::LoadElevationMap(saved);
  ASSERT_FALSE(truncated);
  EXPECT_NE(truncated.error().message.find("hash mismatch"), std::string::npos)
      << truncated.error().message;
  std::ofstream(dir_ / "empty.plem").close();
  const auto empty = mapping::LoadElevationMap((dir_ / "empty.plem").string());
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().message.find("bad magic"), std::string::npos) << empty.error().message;
}

// The .plem's runs of unseen cells (PLELEV02) are lengths read from the file: mangled ones must
// never send the reader past the grid or the file, even when the hash was written anew for them
// (a crafted file). 3000 mutations of a sparse map (1-4 bytes changed in its cell runs, or the
// file cut or lengthened), each with its hash recomputed: every one loads as a whole map or is
// refused as "not a pitchlab elevation map", never a crash (the sanitizer build checks the reads).
// A header whose grid no memory holds is refused before anything is allocated: mutated anywhere,
// the first such run of this test asked for 17 GB and died of std::bad_alloc.
TEST_F(CorruptMap, MangledCellRunsWithAValidHashAreRefusedNotFollowed) {
  const GridGeometry g = GridGeometry::FromArea(0, 0, 3.0, 2.0, 0.1);  // 30 x 20 cells
  const std::string path = Saved(g, [](auto& cells) {
    for (std::size_t k = 0; k < cells.size(); ++k)
      if (k % 7 != 0 && k % 11 != 0) cells[k] = mapping::CellStats{};  // unseen
  });
  std::ifstream in(path, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(good.substr(0, 8), "PLELEV03");
  const auto fnv1a = [](const std::string& bytes) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : bytes) h = (h ^ c) * 1099511628211ull;
    return h;
  };
  std::mt19937 rng(38);
  int loaded = 0, refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string body = good.substr(0, good.size() - 8);
    switch (trial % 4) {
      case 0:  // cut
        body.resize(8 + rng() % (body.size() - 8));
        break;
      case 1:  // lengthened
        body.append(1 + rng() % 64, static_cast<char>(rng()));
        break;
      default:  // 1-4 bytes changed after the header (72 bytes): the runs and the records
        for (int b = 0, n = 1 + rng() % 4; b < n; ++b)
          body[72 + rng() % (body.size() - 72)] = static_cast<char>(rng());
    }
    const std::uint64_t hash = fnv1a(body);
    body.append(reinterpret_cast<const char*>(&hash), 8);
    std::ofstream(dir_ / "mangled.plem", std::ios::binary | std::ios::trunc) << body;
    const auto map = mapping::LoadElevationMap((dir_ / "mangled.plem").string());
    if (map) {
      ++loaded;
      ASSERT_EQ(map->cells().size(), map->geometry().cell_count()) << "trial " << trial;
    } else {
      ++refused;
      ASSERT_NE(map.error().message.find("not a pitchlab elevation map"), std::string::npos)
          << "trial " << trial << ": " << map.error().message;
    }
  }
  EXPECT_GT(refused, 1000);  // the mutations reach the checks, not only harmless values
  EXPECT_GT(loaded, 0);      // and some change only a value, which loads

  std::string huge = good.substr(0, good.size() - 8);
  const std::int32_t side = 1 << 30;  // 2^60 cells
  std::memcpy(huge.data() + 32, &side, 4);
  std::memcpy(huge.data() + 36, &side, 4);
  const std::uint64_t hash = fnv1a(huge);
  huge.append(reinterpret_cast<const char*>(&hash), 8);
  std::ofstream(dir_ / "huge.plem", std::ios::binary | std::ios::trunc) << huge;
  const auto refused_huge = mapping::LoadElevationMap((dir_ / "huge.plem").string());
  ASSERT_FALSE(refused_huge);
  EXPECT_NE(refused_huge.error().message.find("a grid of 1073741824 x 1073741824 cells"),
            std::string::npos)
      << refused_huge.error().message;
}

TEST_F(CorruptMap, APathWithoutFinitePositionsIsNotWritten) {
  planning::Path path;
  path.waypoints = {{0.05, 0.05, 1.0}, {std::nan(""), std::nan(""), 1.0}};
  const fs::path csv = dir_ / "path.csv", geojson = dir_ / "path.geojson";
  const auto c = planning::WritePathCsv(path, csv.string());
  ASSERT_FALSE(c);
  EXPECT_NE(c.error().message.find("waypoint 1 has no finite position"), std::string::npos)
      << c.error().message;
  EXPECT_FALSE(planning::WritePathGeoJson(path, mapping::GeodeticOrigin{46.77, 23.59, 360},
                                          geojson.string()));
  EXPECT_TRUE(fs::is_empty(dir_.path())) << "a path file or its temporary was left";
}

TEST_F(CorruptMap, GeoJsonIsValidJsonEvenWithANonFiniteProperty) {
  planning::Path path;
  path.waypoints = {{0.05, 0.05, 1.0}, {0.15, 0.05, std::nan("")}};
  path.max_inclination_rad = std::nan("");  // an unknown cell's inclination
  const fs::path geojson = dir_ / "path.geojson";
  ASSERT_TRUE(planning::WritePathGeoJson(path, mapping::GeodeticOrigin{46.77, 23.59, 360},
                                         geojson.string()));
  std::ifstream in(geojson);
  const auto j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  ASSERT_FALSE(j.is_discarded()) << "not JSON";
  EXPECT_TRUE(j["features"][0]["properties"]["max_inclination_deg"].is_null());
}

}  // namespace
}  // namespace pitchlab
