// Crafted maps and the paths they would give (issue 18): a .plem whose hash is valid but whose
// numbers are not a map's is refused on load, and no path file ever holds a non-finite number.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
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
