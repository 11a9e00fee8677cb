#include "report_summary.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

TEST(Significant, KeepsThreeDigitsWithoutExponents) {
  EXPECT_EQ(Significant(25.68077843840243), "25.7");
  EXPECT_EQ(Significant(0.22125407960202068), "0.221");
  EXPECT_EQ(Significant(233.52000000038808), "234");
  EXPECT_EQ(Significant(0.0771), "0.0771");
  EXPECT_EQ(Significant(1.1012593157578525), "1.10");
  EXPECT_EQ(Significant(10205), "10205");  // whole numbers are never rounded
  EXPECT_EQ(Significant(-2.35321), "-2.35");
  EXPECT_EQ(Significant(0), "0");
  EXPECT_EQ(Significant(0.342, 2), "0.34");
  EXPECT_EQ(Significant(std::numeric_limits<double>::infinity()), "-");
}

nlohmann::json SafeSuccess() {
  return {{"success", true},
          {"reason", "goal reached"},
          {"hazard_cells_crossed", 0},
          {"forbidden_cells_crossed", 0},
          {"closest_approach_to_forbidden_m", 0.34}};
}

TEST(StageRows, TimesBelowTheTablesResolutionReadAsSuch) {
  const nlohmann::json m = {
      {"stages",
       {{"ground_truth",
         {{"wall_s", 3.84e-6}, {"cpu_s", 1.21}, {"wall_share", 5e-7}, {"cpu_share", 0.098}}},
        {"registration",
         {{"wall_s", 1.8449}, {"cpu_s", 3.5}, {"wall_share", 0.2391}, {"cpu_share", 0.28}}},
        {"scoring",
         {{"wall_s", 0.0}, {"cpu_s", 0.0651}, {"wall_share", 0.0}, {"cpu_share", 0.0053}}}}}};
  const auto rows = StageRows(m);
  const auto row = [&](const std::string& label_start) {
    for (const auto& r : rows)
      if (r[0].rfind(label_start, 0) == 0) return r;
    return std::vector<std::string>{};
  };
  const std::vector<std::string> truth = row("ground truth"), registration = row("registration"),
                                 scoring = row("scoring");
  ASSERT_EQ(truth.size(), 5u);
  ASSERT_EQ(registration.size(), 5u);
  ASSERT_EQ(scoring.size(), 5u);
  EXPECT_EQ(truth, (std::vector<std::string>{truth[0], "< 0.001", "1.21", "< 0.01", "9.8"}));
  EXPECT_EQ(registration, (std::vector<std::string>{registration[0], "1.84", "3.50", "24", "28"}));
  EXPECT_EQ(scoring[1], "0");  // nothing is not "below the resolution"
  EXPECT_EQ(scoring[4], "0.53");
}

TEST(ReadOutcome, ASafeRunReachedItsGoal) {
  const Outcome o = ReadOutcome(SafeSuccess());
  EXPECT_TRUE(o.success);
  EXPECT_TRUE(o.safe);
  EXPECT_EQ(o.headline, "Goal reached");
  EXPECT_EQ(o.reason, "goal reached");
  EXPECT_TRUE(o.safety.empty());
}

TEST(ReadOutcome, CrossingTrueHazardsMakesASuccessUnsafe) {
  nlohmann::json m = SafeSuccess();
  m["hazard_cells_crossed"] = 3;
  m["forbidden_cells_crossed"] = 7;
  m["closest_approach_to_forbidden_m"] = 0.0;
  const Outcome o = ReadOutcome(m);
  EXPECT_TRUE(o.success);
  EXPECT_FALSE(o.safe);
  EXPECT_EQ(o.headline, "Goal reached, but unsafe");
  ASSERT_EQ(o.safety.size(), 3u);
  EXPECT_NE(o.safety[0].find("3 true hazard cells"), std::string::npos);
  EXPECT_NE(o.safety[1].find("7 forbidden cells"), std::string::npos);
  EXPECT_NE(o.safety[2].find("0 m from a true hazard cell"), std::string::npos);
}

// The truth's hazards under the footprint, by kind, and how steep the steepest was against the
// limit the truth judged it by.
TEST(ReadOutcome, SaysWhatTheHazardsUnderTheFootprintWere) {
  nlohmann::json m = SafeSuccess();
  m["forbidden_cells_crossed"] = 5;
  m["hazards_touched"] = {{"too_steep", 4}, {"step", 1}, {"drop", 0},
                          {"steepest_deg", 16.4213}, {"too_steep_limit_deg", 16.0}};
  Outcome o = ReadOutcome(m);
  ASSERT_EQ(o.safety.size(), 2u);
  EXPECT_EQ(o.safety[1],
            "the true hazards under its footprint: 4 too-steep cells (the steepest 16.4 deg; the "
            "limit 16.0 deg), 1 step cell");
  // A safe run says nothing of hazards, whatever the metrics hold.
  m["forbidden_cells_crossed"] = 0;
  o = ReadOutcome(m);
  EXPECT_TRUE(o.safe);
  EXPECT_TRUE(o.safety.empty());
  // Forbidden cells by the grid's edge alone: no hazard to describe.
  m["forbidden_cells_crossed"] = 2;
  m["hazards_touched"] = {{"too_steep", 0}, {"step", 0}, {"drop", 0},
                          {"steepest_deg", 0.0}, {"too_steep_limit_deg", 16.0}};
  EXPECT_EQ(ReadOutcome(m).safety.size(), 1u);
}

TEST(ReadOutcome, TouchingAHazardIsUnsafeEvenWithoutCrossingIt) {
  nlohmann::json m = SafeSuccess();
  m["closest_approach_to_forbidden_m"] = 0.02;  // prints as 0.0 m at the report's precision
  EXPECT_FALSE(ReadOutcome(m).safe);
  m["closest_approach_to_forbidden_m"] = 0.1;  // one cell away: not touching
  EXPECT_TRUE(ReadOutcome(m).safe);
  m["closest_approach_to_forbidden_m"] = nullptr;  // no hazard within 5 m
  EXPECT_TRUE(ReadOutcome(m).safe);
}

TEST(ReadOutcome, AFailedRunKeepsItsReason) {
  const Outcome o = ReadOutcome({{"success", false}, {"reason", "no path: goal walled in"}});
  EXPECT_FALSE(o.success);
  EXPECT_EQ(o.headline, "Failed");
  EXPECT_EQ(o.reason, "no path: goal walled in");
  EXPECT_TRUE(o.safe);  // a hardware run has no truth: nothing known to be unsafe
}

TEST(KeyMetrics, ShowsUnitsAndLeavesOutWhatIsUnknown) {
  nlohmann::json m = SafeSuccess();
  m["distance_m"] = 25.68077843840243;
  m["stops"] = 9;
  m["final_pose_error"] = {{"translation_m", 0.2212}, {"rotation_deg", 1.1012}};
  m["cost_ratio"] = nullptr;  // failed runs have none
  const std::vector<MetricRow> rows = KeyMetrics(m);
  auto find = [&](const std::string& label) -> const MetricRow* {
    for (const MetricRow& r : rows)
      if (r.label == label) return &r;
    return nullptr;
  };
  ASSERT_NE(find("distance driven"), nullptr);
  EXPECT_EQ(find("distance driven")->value, "25.7");
  EXPECT_EQ(find("distance driven")->unit, "m");
  ASSERT_NE(find("stops"), nullptr);
  EXPECT_EQ(find("stops")->value, "9");  // a count, not 9.00
  ASSERT_NE(find("final heading error"), nullptr);
  EXPECT_EQ(find("final heading error")->unit, "deg");
  EXPECT_EQ(find("path cost / optimal cost"), nullptr);
  const auto false_hazards_row = [](const std::vector<MetricRow>& of) {
    const auto r = std::find_if(of.begin(), of.end(), [](const MetricRow& row) {
      return row.label == "false hazard cells in the final map";
    });
    return r == of.end() ? std::optional<MetricRow>() : std::optional<MetricRow>(*r);
  };
  m["map_hazards"] = {{"cells_compared", 10205}, {"false_hazard_cells", 31}};
  const std::optional<MetricRow> false_hazards = false_hazards_row(KeyMetrics(m));
  ASSERT_TRUE(false_hazards);
  EXPECT_EQ(false_hazards->value, "31");
  EXPECT_NE(false_hazards->note.find("of 10205 cells compared"), std::string::npos);
  EXPECT_EQ(false_hazards->note.find("out of its reach"), std::string::npos);  // none said
  // The truly free cells the robot could not reach are said beside the count, not in it.
  m["map_hazards"]["false_hazard_cells_out_of_reach"] = 8;
  const std::optional<MetricRow> roof = false_hazards_row(KeyMetrics(m));
  ASSERT_TRUE(roof);
  EXPECT_EQ(roof->value, "31");
  EXPECT_NE(roof->note.find("; 8 more out of its reach"), std::string::npos);
  EXPECT_EQ(find("wall time"), nullptr);
  // The trajectory error (issue 20's standard metric) from metrics.json's nested keys; a
  // hardware run's null leaves it out.
  EXPECT_EQ(find("absolute trajectory error (RMSE)"), nullptr);
  m["trajectory_error"] = {{"ate", {{"unaligned", {{"rmse_m", 0.10922}}},
                                    {"aligned", {{"rmse_m", 0.075184}}}}}};
  const std::vector<MetricRow> with_ate = KeyMetrics(m);
  auto ate = [&](const std::string& label) {
    const auto it = std::find_if(with_ate.begin(), with_ate.end(),
                                 [&](const MetricRow& r) { return r.label == label; });
    return it == with_ate.end() ? std::string("missing") : it->value + " " + it->unit;
  };
  EXPECT_EQ(ate("absolute trajectory error (RMSE)"), "0.109 m");
  EXPECT_EQ(ate("absolute trajectory error, aligned"), "0.0752 m");
  m["trajectory_error"] = nullptr;
  for (const MetricRow& r : KeyMetrics(m)) {
    EXPECT_EQ(r.label.find("trajectory error"), std::string::npos) << r.label;
  }
  // The map's slopes against the truth's where the planner decides on them; level ground's bin,
  // and a bin without a supported slope (an office has no steep cells), are left out.
  m["map_tilt_against_truth"] = nlohmann::json::array({{{"true_from_deg", 0.0},
                                                        {"true_to_deg", 8.0},
                                                        {"cells", 900},
                                                        {"map_unsupported", 90},
                                                        {"median_error_deg", 0.15},
                                                        {"p10_error_deg", -1.3},
                                                        {"p90_error_deg", 1.6}},
                                                       {{"true_from_deg", 8.0},
                                                        {"true_to_deg", 16.0},
                                                        {"cells", 400},
                                                        {"map_unsupported", 40},
                                                        {"median_error_deg", -0.11},
                                                        {"p10_error_deg", -1.82},
                                                        {"p90_error_deg", 1.55}},
                                                       {{"true_from_deg", 16.0},
                                                        {"true_to_deg", 90.0},
                                                        {"cells", 3},
                                                        {"map_unsupported", 3},
                                                        {"median_error_deg", 0.0},
                                                        {"p10_error_deg", 0.0},
                                                        {"p90_error_deg", 0.0}}});
  std::vector<std::string> slopes;
  for (const MetricRow& r : KeyMetrics(m)) {
    if (r.label.rfind("map slope error", 0) == 0)
      slopes.push_back(r.label + ": " + r.value + " | " + r.note);
  }
  ASSERT_EQ(slopes.size(), 1u);
  EXPECT_EQ(slopes[0],
            "map slope error, true slope 8-16 deg: -0.110 | map minus truth, median; 10-90 %: "
            "-1.82 .. 1.55 deg, over 360 cells with a supported slope");
}

}  // namespace
}  // namespace pitchlab::mission
