// `pitchlab worlds`: every built-in world with its default start and goal, as text and as JSON.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

using cli_test::CliResult;

TEST(WorldsCli, JsonListsEveryWorldWithItsDefaultStartAndGoal) {
  const test_support::ScopedTempDir dir("worlds");
  const CliResult r = cli_test::RunPitchlab("worlds --json", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json list = nlohmann::json::parse(r.out);
  ASSERT_EQ(list.size(), 6u);
  for (const auto& w : list) {
    const std::string name = w["name"].get<std::string>();
    ASSERT_TRUE(w["default_start"].is_object()) << name;
    ASSERT_TRUE(w["default_goal"].is_object()) << name << ": every built-in world is a mission";
    EXPECT_TRUE(w["default_goal"]["x_m"].is_number() && w["default_goal"]["y_m"].is_number());
  }
  // The gully's, as GullyConfig and its DEM's flattest spot put them (worlds/README.md).
  const auto& gully = list[5];
  ASSERT_EQ(gully["name"], "gully");
  EXPECT_DOUBLE_EQ(gully["default_start"]["x_m"].get<double>(), -0.075);
  EXPECT_DOUBLE_EQ(gully["default_start"]["y_m"].get<double>(), 45.825);
  EXPECT_DOUBLE_EQ(gully["default_goal"]["x_m"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(gully["default_goal"]["y_m"].get<double>(), 35.5);
}

TEST(WorldsCli, TextShowsEachWorldsStartAndGoal) {
  const test_support::ScopedTempDir dir("worlds");
  const CliResult r = cli_test::RunPitchlab("worlds", dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("start x, y [m], yaw [deg]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("goal x, y [m]"), std::string::npos) << r.out;
  // One line per world: name, size, start, goal (to the millimetre, no trailing zeros).
  for (const char* line : {"office ", "-8, 0, 0 ", "6.67, 4 ", "gully ", "-0.075, 45.825, 0 ",
                           "3, 35.5 ", "terrain ", "-25, 25 "}) {
    EXPECT_NE(r.out.find(line), std::string::npos) << line << " missing in\n" << r.out;
  }
}

}  // namespace
}  // namespace pitchlab
