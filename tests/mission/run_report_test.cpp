#include "run_report.hpp"

#include <gtest/gtest.h>

#include "pitchlab/mission/stage_times.hpp"
#include "report_scene.hpp"
#include "scoped_temp_dir.hpp"
#include "synthetic_report.hpp"

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

class RunReport : public ::testing::Test {
 protected:
  const test_support::ScopedTempDir dir_{"run_report"};
};

TEST_F(RunReport, AFailedRunShowsItsReasonBeforeEverythingElse) {
  const RunReportInput in = testing::SyntheticReport(dir_.path(), 1000, 40);
  const std::string html = RenderRunReport(in, LoadThreeJs(DefaultThreeJsDir()));
  const std::size_t outcome = html.find("<div id=outcome class=\"outcome failed\"");
  ASSERT_NE(outcome, std::string::npos);
  EXPECT_NE(html.find("<div class=headline>Failed</div>"), std::string::npos);
  const std::size_t reason = html.find(std::string("Reason: ") + testing::kSyntheticReason);
  ASSERT_NE(reason, std::string::npos);
  EXPECT_LT(outcome, reason);
  EXPECT_LT(reason, html.find("id=key-metrics"));
  EXPECT_LT(html.find("id=key-metrics"), html.find("id=view3d"));
  EXPECT_LT(html.find("id=view3d"), html.find("<details>"));
  // The key metrics carry their units and a few digits, not JSON.
  EXPECT_NE(html.find("<td class=l>distance driven</td><td>3.14</td><td class=l>m</td>"),
            std::string::npos);
}

TEST_F(RunReport, ASuccessThatCrossedHazardsSaysSoBesideTheOutcome) {
  RunReportInput in = testing::SyntheticReport(dir_.path(), 1000, 40);
  in.metrics["success"] = true;
  in.metrics["reason"] = "goal reached";
  in.metrics["hazard_cells_crossed"] = 2;
  in.metrics["forbidden_cells_crossed"] = 2;
  const std::string html = RenderRunReport(in, LoadThreeJs(DefaultThreeJsDir()));
  const std::size_t outcome =
      html.find("<div id=outcome class=\"outcome unsafe\" data-success=true data-safe=false>");
  ASSERT_NE(outcome, std::string::npos);
  EXPECT_NE(html.find("Goal reached, but unsafe"), std::string::npos);
  const std::size_t unsafe = html.find("Unsafe: the true trajectory crossed 2 true hazard cells");
  ASSERT_NE(unsafe, std::string::npos);
  EXPECT_LT(unsafe, html.find("id=key-metrics"));
}

TEST_F(RunReport, WithoutThreeJsThePageSaysWhyAndHasNoViewer) {
  const RunReportInput in = testing::SyntheticReport(dir_.path(), 1000, 40);
  const Result<ThreeJs> missing = LoadThreeJs(dir_ / "no_such_folder");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("three.min.js"), std::string::npos);
  EXPECT_NE(missing.error().message.find("libjs-three"), std::string::npos);
  const std::string html = RenderRunReport(in, missing);
  EXPECT_NE(html.find("<div id=view3d data-status=unavailable>"), std::string::npos);
  EXPECT_NE(html.find("The 3D view is unavailable: "), std::string::npos);
  EXPECT_EQ(html.find("scene-data"), std::string::npos);
  EXPECT_NE(html.find(testing::kSyntheticReason), std::string::npos);  // the rest is all there
}

TEST_F(RunReport, TabulatesWhereTheRunsTimeWentStageByStage) {
  RunReportInput in = testing::SyntheticReport(dir_.path(), 1000, 40);
  StageBreakdown b;
  b.run = {40.0, 32.0};
  b.stages[Stage::kPhysicsDriving] = {20.0, 16.0};
  b.stages[Stage::kRegistration] = {4.0, 8.0};
  in.metrics["stages"] = StagesJson(b);
  const std::string html = RenderRunReport(in, LoadThreeJs(DefaultThreeJsDir()));
  const std::size_t heading = html.find("<h2 id=\"stages\">");
  ASSERT_NE(heading, std::string::npos);
  EXPECT_NE(html.find("<a href=#stages>"), std::string::npos) << "the jump list links it";
  const auto row = [&](const std::string& cells) {
    const std::size_t at = html.find(cells, heading);
    EXPECT_NE(at, std::string::npos) << cells;
    return at;
  };
  // Wall and CPU seconds, then their shares of the run in percent.
  const std::size_t driving =
      row("<td>physics while driving</td><td>20.0</td><td>16.0</td><td>50</td><td>50</td>");
  const std::size_t registration =
      row("<td>registration</td><td>4.00</td><td>8.00</td><td>10</td><td>25</td>");
  // Other: 40 - 24 s wall, 32 - 24 s CPU; the whole run last.
  const std::size_t other = row("</td><td>16.0</td><td>8.00</td><td>40</td><td>25</td>");
  const std::size_t whole = row("<td>whole run</td><td>40.0</td><td>32.0</td><td>100</td>");
  EXPECT_LT(driving, registration);
  EXPECT_LT(registration, other);
  EXPECT_LT(other, whole);
  EXPECT_NE(html.find("<th>stage</th><th>wall [s]</th><th>CPU [s]</th><th>wall [%]</th>", heading),
            std::string::npos);
}

TEST_F(RunReport, AHardwareRunWithoutStagesHasNoStageTable) {
  const RunReportInput in = testing::SyntheticReport(dir_.path(), 1000, 40);
  ASSERT_FALSE(in.metrics.contains("stages"));
  const std::string html = RenderRunReport(in, LoadThreeJs(DefaultThreeJsDir()));
  EXPECT_EQ(html.find("<h2 id=\"stages\">"), std::string::npos);
  EXPECT_EQ(html.find("href=#stages"), std::string::npos);
}

TEST_F(RunReport, LinksTheRunFiles) {
  const RunReportInput in = testing::SyntheticReport(dir_.path(), 1000, 40);
  const std::string html = RenderRunReport(in, LoadThreeJs(DefaultThreeJsDir()));
  EXPECT_NE(html.find("<a href=\"metrics.json\">metrics.json</a>: every metric"),
            std::string::npos);
  EXPECT_NE(html.find("<a href=\"stops/000/map.png\">stops/000/map.png</a>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"elevation.png\">elevation.png</a>"), std::string::npos);
}

// The largest scene a run can put in a page (kSceneMaxPoints points, kSceneMaxCells cells)
// with three.js inlined stays under the 10 MB a browser opens without a pause.
TEST_F(RunReport, TheLargestPageStaysUnderTenMegabytes) {
  const Result<ThreeJs> three = LoadThreeJs(DefaultThreeJsDir());
  ASSERT_TRUE(three) << three.error().message << " (scripts/setup.sh installs libjs-three)";
  const RunReportInput in = testing::SyntheticReport(dir_.path(), kSceneMaxPoints, 400);
  const std::string html = RenderRunReport(in, three);
  EXPECT_NE(html.find("REVISION=\"111\""), std::string::npos);  // three.js is in it
  EXPECT_LT(html.size(), 10u * 1000 * 1000);
}

}  // namespace
}  // namespace pitchlab::mission
