// `pitchlab bench` end to end in the small yard world: shards cover a sweep exactly once and
// merge to the unsharded summary, a failing run is recorded while the others finish, a killed or
// re-run sweep resumes, and bad input fails before any run starts.

#include <sys/wait.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;
using nlohmann::json;

const fs::path kYard = fs::path(PITCHLAB_SOURCE_DIR) / "tests/data/worlds/yard.xml";

std::vector<json> Records(const fs::path& bench_dir) {
  std::vector<json> records;
  std::istringstream in(Slurp(bench_dir / "runs.jsonl"));
  for (std::string line; std::getline(in, line);) records.push_back(json::parse(line));
  return records;
}

std::multiset<std::string> RunIds(const std::vector<json>& records) {
  std::multiset<std::string> ids;
  for (const json& r : records) {
    ids.insert(r["world"].get<std::string>() + "-s" + std::to_string(r["seed"].get<int>()));
  }
  return ids;
}

class BenchCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_.emplace("bench_cli");
    dir_ = scratch_->path();
  }
  static void TearDownTestSuite() { scratch_.reset(); }

  static CliResult Exec(const std::string& args) {
    return cli_test::RunPitchlab("bench " + args, dir_);
  }
  // The suite's folder, from its set-up to its tear-down (or the end of the process).
  static inline std::optional<test_support::ScopedTempDir> scratch_;
  static inline fs::path dir_;
};

// The counts of a summary row, without the timings that differ from sweep to sweep.
json Counts(const json& row) {
  return {{"world", row["world"]},
          {"runs", row["runs"]},
          {"successes", row["successes"]},
          {"failures", row["failures"]},
          {"runs_over_forbidden_cells", row["runs_over_forbidden_cells"]},
          {"runs_over_true_hazards", row["runs_over_true_hazards"]},
          {"failure_reasons", row["failure_reasons"]}};
}

TEST_F(BenchCli, ShardsCoverEveryRunOnceAndMergeToTheUnshardedSummary) {
  const std::string sweep = "--worlds " + kYard.string() + " --seeds 1..3 --jobs 2 --json";
  const CliResult whole = Exec(sweep + " --out " + (dir_ / "whole").string());
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const json summary = json::parse(whole.out);
  EXPECT_EQ(summary, json::parse(Slurp(dir_ / "whole/summary.json")));
  EXPECT_EQ(summary["total"]["runs"], 3);
  EXPECT_EQ(summary["total"]["successes"], 3) << Slurp(dir_ / "whole/runs.jsonl");
  EXPECT_NE(whole.err.find("run 3 of 3: yard seed"), std::string::npos) << whole.err;

  const std::vector<json> all = Records(dir_ / "whole");
  ASSERT_EQ(all.size(), 3u);
  for (const json& r : all) {
    EXPECT_EQ(r["exit_code"], 0);
    EXPECT_EQ(r["reason"], "goal reached");
    EXPECT_GT(r["sim_time_s"].get<double>(), 0.0);
    EXPECT_GT(r["distance_m"].get<double>(), 11.0);
    EXPECT_TRUE(r["final_pose_error_m"].is_number());
    EXPECT_TRUE(r["max_registration_error_m"].is_number());
    EXPECT_TRUE(r["registration_step_max_m"].is_number());
    EXPECT_TRUE(r["cost_ratio"].is_number());
    EXPECT_TRUE(r["hazards_touched_steepest_deg"].is_number());
    EXPECT_TRUE(fs::exists(dir_ / "whole" / r["run_dir"].get<std::string>() / "metrics.json"));
  }
  // The unsafe runs the table counts are the runs whose robot crossed such cells.
  int over_forbidden = 0, over_hazards = 0;
  for (const json& r : all) {
    over_forbidden += r["forbidden_cells_crossed"].get<int>() > 0;
    over_hazards += r["hazard_cells_crossed"].get<int>() > 0;
  }
  EXPECT_EQ(summary["total"]["runs_over_forbidden_cells"], over_forbidden);
  EXPECT_EQ(summary["total"]["runs_over_true_hazards"], over_hazards);
  double steepest = 0;
  for (const json& r : all)
    steepest = std::max(steepest, r["hazards_touched_steepest_deg"].get<double>());
  EXPECT_DOUBLE_EQ(summary["total"]["steepest_hazard_touched_deg"].get<double>(), steepest);
  EXPECT_NE(whole.err.find("unsafe forb/haz"), std::string::npos) << whole.err;

  for (const char* shard : {"1/2", "2/2"}) {
    const std::string out = (dir_ / ("shard" + std::string(1, shard[0]))).string();
    const CliResult r = Exec(sweep + " --shard " + shard + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << shard << ": " << r.err;
  }
  const std::vector<json> one = Records(dir_ / "shard1"), two = Records(dir_ / "shard2");
  EXPECT_EQ(one.size(), 2u);  // runs 0 and 2 of the list
  EXPECT_EQ(two.size(), 1u);  // run 1
  std::vector<json> both = one;
  both.insert(both.end(), two.begin(), two.end());
  EXPECT_EQ(RunIds(both), RunIds(all));  // every run exactly once

  const CliResult merged =
      Exec("--summarize --json " + (dir_ / "shard1").string() + " " + (dir_ / "shard2").string());
  ASSERT_EQ(merged.exit_code, 0) << merged.err;
  const json m = json::parse(merged.out);
  ASSERT_EQ(m["worlds"].size(), summary["worlds"].size());
  EXPECT_EQ(Counts(m["worlds"][0]), Counts(summary["worlds"][0]));
  EXPECT_EQ(Counts(m["total"]), Counts(summary["total"]));

  // A re-run of a finished shard skips what runs.jsonl already records.
  const CliResult again = Exec(sweep + " --shard 1/2 --out " + (dir_ / "shard1").string());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(Records(dir_ / "shard1").size(), 2u);
  EXPECT_NE(again.err.find("2 already recorded"), std::string::npos) << again.err;
}

TEST_F(BenchCli, FailingRunsAreRecordedWithTheirReasonAndTheOthersFinish) {
  // A copy of the yard without a default goal: `pitchlab run` refuses it, exit 2, no folder.
  std::string no_goal = Slurp(kYard);
  const auto line = no_goal.find("<numeric name=\"pitchlab:default_goal\"");
  ASSERT_NE(line, std::string::npos);
  no_goal.erase(line, no_goal.find('\n', line) - line);
  std::ofstream(dir_ / "nogoal.xml") << no_goal;

  const CliResult r = Exec("--quiet --worlds " + (dir_ / "nogoal.xml").string() + "," +
                           kYard.string() + " --seeds 4 --out " + (dir_ / "mixed").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::map<std::string, json> by_world;
  for (const json& rec : Records(dir_ / "mixed")) by_world[rec["world"]] = rec;
  ASSERT_EQ(by_world.size(), 2u);
  EXPECT_FALSE(by_world["nogoal"]["success"].get<bool>());
  EXPECT_EQ(by_world["nogoal"]["exit_code"], 2);
  EXPECT_NE(by_world["nogoal"]["reason"].get<std::string>().find("no default goal"),
            std::string::npos)
      << by_world["nogoal"];
  EXPECT_TRUE(by_world["yard"]["success"].get<bool>()) << by_world["yard"];

  // A mission that fails inside the run: its folder and metrics exist, the reason is the run's.
  std::ofstream(dir_ / "budget.yaml") << "run: {time_budget_s: 1}\n";
  const CliResult budget =
      Exec("--quiet --worlds " + kYard.string() + " --seeds 1 --config " +
           (dir_ / "budget.yaml").string() + " --out " + (dir_ / "budget").string());
  ASSERT_EQ(budget.exit_code, 0) << budget.err;
  const json spent = Records(dir_ / "budget").at(0);
  EXPECT_FALSE(spent["success"].get<bool>());
  EXPECT_EQ(spent["exit_code"], 1);
  EXPECT_NE(spent["reason"].get<std::string>().find("time budget"), std::string::npos) << spent;
  EXPECT_TRUE(fs::exists(dir_ / "budget/runs/yard-s1/metrics.json"));

  // A run over its wall-time limit is killed; no half-written folder is left behind.
  const CliResult slow =
      Exec("--quiet --worlds " + kYard.string() + " --seeds 1,2 --jobs 2 --timeout-s 0.2 --out " +
           (dir_ / "slow").string());
  ASSERT_EQ(slow.exit_code, 0) << slow.err;
  for (const json& rec : Records(dir_ / "slow")) {
    EXPECT_FALSE(rec["success"].get<bool>());
    EXPECT_NE(rec["reason"].get<std::string>().find("timeout"), std::string::npos) << rec;
  }
  EXPECT_TRUE(fs::is_empty(dir_ / "slow/runs"));
}

// --keep failed: a successful run keeps its numbers, config and trajectories; a failed one keeps
// everything, to be looked at.
TEST_F(BenchCli, KeepFailedLeavesSuccessesTheirMetricsAndFailuresEverything) {
  const CliResult ok = Exec("--quiet --keep failed --worlds " + kYard.string() +
                            " --seeds 4 --out " + (dir_ / "keep").string());
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  ASSERT_TRUE(Records(dir_ / "keep").at(0)["success"].get<bool>());
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_ / "keep/runs/yard-s4")) {
    left.insert(e.path().filename().string());
  }
  EXPECT_EQ(left, (std::set<std::string>{"config.yaml", "metrics.json", "trajectories.geojson",
                                         "trajectory_estimated.csv", "trajectory_estimated.tum",
                                         "trajectory_true.csv", "trajectory_true.tum"}));

  std::ofstream(dir_ / "keep_budget.yaml") << "run: {time_budget_s: 1}\n";
  const CliResult failed =
      Exec("--quiet --keep failed --worlds " + kYard.string() + " --seeds 1 --config " +
           (dir_ / "keep_budget.yaml").string() + " --out " + (dir_ / "keep_failed").string());
  ASSERT_EQ(failed.exit_code, 0) << failed.err;
  EXPECT_FALSE(Records(dir_ / "keep_failed").at(0)["success"].get<bool>());
  EXPECT_TRUE(fs::exists(dir_ / "keep_failed/runs/yard-s1/report.html"));
  EXPECT_TRUE(fs::exists(dir_ / "keep_failed/runs/yard-s1/stops"));

  const CliResult bad = Exec("--keep some --worlds " + kYard.string() + " --seeds 1 --out " +
                             (dir_ / "keep_bad").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--keep must be all or failed"), std::string::npos) << bad.err;
}

TEST_F(BenchCli, ARoundTripSweepDrivesEveryRunToTheGoalAndBackAndResumesOnlyTheSameRoute) {
  const fs::path out = dir_ / "round_trip";
  const std::string sweep = "--quiet --worlds " + kYard.string() + " --out " + out.string();
  const CliResult r = Exec(sweep + " --seeds 1 --round-trip");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json record = Records(out).at(0);
  EXPECT_EQ(record["route"], "round-trip");
  EXPECT_TRUE(record["success"].get<bool>()) << record;
  const json metrics =
      json::parse(Slurp(out / record["run_dir"].get<std::string>() / "metrics.json"));
  // The yard's default start (-5.5, 0) is the goal of a round trip; its default goal (5.5, 0)
  // the one waypoint, reached.
  EXPECT_DOUBLE_EQ(metrics["goal"]["x_m"].get<double>(), -5.5);
  ASSERT_EQ(metrics["route"]["via"].size(), 1u);
  EXPECT_DOUBLE_EQ(metrics["route"]["via"][0]["x_m"].get<double>(), 5.5);
  EXPECT_EQ(metrics["route"]["waypoints_reached"].get<int>(), 1);
  // There and back: at least twice the 11 m between start and goal, less the goal tolerance
  // (0.5 m) at each end.
  EXPECT_GT(record["distance_m"].get<double>(), 2 * 11.0 - 2 * 0.5);
  // Resuming the folder with another route would mix the runs: refused, nothing run.
  const CliResult plain = Exec(sweep + " --seeds 1,2");
  EXPECT_EQ(plain.exit_code, 2);
  EXPECT_NE(plain.err.find("drove another route (round-trip: yard-s1)"), std::string::npos)
      << plain.err;
  EXPECT_EQ(Records(out).size(), 1u);
}

struct BadBench {
  std::string args, message;
};

TEST_F(BenchCli, BadInputGivesAClearErrorBeforeAnyRunStarts) {
  std::ofstream(dir_ / "bad.yaml") << "run: {drive_per_stop_m: -1}\n";
  const std::string yard = " --worlds " + kYard.string();
  const BadBench cases[] = {
      {yard + " --seeds 1..2 --shard 3/2", "need 1 <= K <= N"},
      {yard + " --seeds 1..2 --shard 0/2", "need 1 <= K <= N"},
      {yard + " --seeds 1..2 --shard 2", "not K/N"},
      {yard + " --seeds 5..1", "is empty"},
      {yard + " --seeds 1,x", "not a whole number"},
      {yard + " --seeds 1,1", "twice"},
      {" --worlds " + kYard.string() + ",atlantis --seeds 1", "unknown world 'atlantis'"},
      {yard + " --seeds 1 --jobs 0", "--jobs"},
      {yard + " --seeds 1 --config " + (dir_ / "bad.yaml").string(), "drive_per_stop_m"},
      {yard + " --seeds 1 --via 1,x", "'x', not a number"},
      {yard + " --seeds 1 --via 1", "needs 2 comma-separated numbers"},
  };
  for (const BadBench& c : cases) {
    const CliResult r = Exec(c.args + " --out " + (dir_ / "never").string());
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << " said: " << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "never")) << c.args;
  }
  const CliResult missing = Exec("--summarize " + (dir_ / "nowhere").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("no runs.jsonl"), std::string::npos) << missing.err;
}

// `--compare A B` on two recorded sweeps (no runs; a run recorded twice counts once): the same
// runs twice show no change; a world whose runs all got slower and half of them failed shows the
// change, its interval and p-values that tell it apart; a world in one sweep only is named, not
// compared.
TEST_F(BenchCli, CompareTellsTwoSweepsApartWorldByWorld) {
  const fs::path a = dir_ / "compare_a", b = dir_ / "compare_b";
  fs::create_directories(a);
  fs::create_directories(b);
  std::ofstream ra(a / "runs.jsonl"), rb(b / "runs.jsonl");
  for (int seed = 1; seed <= 20; ++seed) {
    const json run = {{"world", "yard"},         {"seed", seed},
                      {"success", true},         {"wall_time_s", 10.0 + seed % 5},
                      {"false_hazard_cells", 3}, {"map_cells_compared", 1000}};
    ra << run.dump() << "\n";
    json slower = run;
    slower["wall_time_s"] = 100.0 + seed % 5;
    slower["success"] = seed % 2 == 0;
    rb << slower.dump() << "\n";
  }
  rb << json({{"world", "gully"}, {"seed", 1}, {"success", true}}).dump() << "\n";
  // A resumed sweep's second record of a run: the first counts, as in the summary.
  ra << json({{"world", "yard"}, {"seed", 3}, {"success", false}, {"wall_time_s", 1000.0}}).dump()
     << "\n";
  ra.close();
  rb.close();
  const CliResult same = Exec("--compare " + a.string() + " " + a.string() + " --json");
  ASSERT_EQ(same.exit_code, 0) << same.err;
  const json s = json::parse(same.out)["worlds"]["yard"];
  EXPECT_EQ(s["runs_a"].get<int>(), 20);
  EXPECT_EQ(s["metrics"]["wall_time_s"]["change"].get<double>(), 0.0);
  EXPECT_EQ(s["metrics"]["wall_time_s"]["p_value"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(s["metrics"]["false_hazard_percent"]["median_a"].get<double>(), 0.3);
  EXPECT_EQ(s["success"]["p_value"].get<double>(), 1.0);

  const CliResult apart = Exec("--compare " + a.string() + " " + b.string() + " --json");
  ASSERT_EQ(apart.exit_code, 0) << apart.err;
  const json report = json::parse(apart.out);
  const json& wall = report["worlds"]["yard"]["metrics"]["wall_time_s"];
  EXPECT_DOUBLE_EQ(wall["change"].get<double>(), 90.0);
  EXPECT_LT(wall["p_value"].get<double>(), 0.001);
  EXPECT_GE(wall["interval_95"][0].get<double>(), 86.0);  // 100 - 14 at the least
  EXPECT_LE(wall["interval_95"][1].get<double>(), 94.0);
  const json& success = report["worlds"]["yard"]["success"];
  EXPECT_EQ(success["a"].get<int>(), 20);
  EXPECT_EQ(success["b"].get<int>(), 10);
  EXPECT_LT(success["p_value"].get<double>(), 0.001);
  EXPECT_EQ(report["worlds"]["gully"]["runs_a"].get<int>(), 0);
  EXPECT_FALSE(report["worlds"]["gully"].contains("metrics"));
  // The table, on stderr beside --json, names what it compares.
  EXPECT_NE(apart.err.find("wall per run [s]"), std::string::npos) << apart.err;
  EXPECT_NE(apart.err.find("(Fisher)"), std::string::npos) << apart.err;

  const CliResult one = Exec("--compare " + a.string());
  EXPECT_EQ(one.exit_code, 2);
  EXPECT_NE(one.err.find("--compare needs two bench folders"), std::string::npos) << one.err;
  const CliResult missing = Exec("--compare " + a.string() + " " + (dir_ / "nowhere").string());
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("no runs.jsonl"), std::string::npos) << missing.err;
}

}  // namespace
}  // namespace pitchlab
