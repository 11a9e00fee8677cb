#include "bench_compare.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

#include "bench_records.hpp"
#include "sweep_statistics.hpp"

namespace pitchlab::apps {
namespace {

namespace fs = std::filesystem;
using json = BenchRecord;

constexpr int kResamples = 10000;
constexpr std::uint64_t kSeed = 1;  // the same sweeps always give the same figures

// The run metrics compared: a record key (or the false-hazard share) and how the table names it.
struct Metric {
  const char* key;
  const char* label;
};
constexpr const char* kFalseHazards = "false_hazard_percent";
const Metric kMetrics[] = {
    {"wall_time_s", "wall per run [s]"},
    {"sim_time_s", "simulated time [s]"},
    {"stops", "stops"},
    {"final_pose_error_m", "final pose error [m]"},
    {"ate_m", "ATE [m]"},
    {"ate_aligned_m", "ATE after alignment [m]"},
    {kFalseHazards, "false hazards [%]"},
    {"forbidden_cells_crossed", "forbidden cells crossed"},
    {"hazard_cells_crossed", "hazard cells crossed"},
};

std::vector<double> Values(const std::vector<const json*>& runs, const Metric& m) {
  return std::string(m.key) == kFalseHazards ? FalseHazardPercent(runs) : Numbers(runs, m.key);
}

int Successes(const std::vector<const json*>& runs) {
  int n = 0;
  for (const json* r : runs) n += r->value("success", false) ? 1 : 0;
  return n;
}

json CompareWorld(const std::vector<const json*>& a, const std::vector<const json*>& b) {
  json w;
  w["runs_a"] = a.size();
  w["runs_b"] = b.size();
  const int ok_a = Successes(a), ok_b = Successes(b);
  w["success"] = {{"a", ok_a},
                  {"b", ok_b},
                  {"p_value", FisherExactTwoSided(ok_a, static_cast<int>(a.size()), ok_b,
                                                  static_cast<int>(b.size()))}};
  json metrics = json::object();
  for (const Metric& m : kMetrics) {
    const std::vector<double> va = Values(a, m), vb = Values(b, m);
    json row = {{"label", m.label}, {"n_a", va.size()}, {"n_b", vb.size()}};
    if (!va.empty() && !vb.empty()) {
      const MedianChange c = CompareMedians(va, vb, kResamples, kSeed);
      row["median_a"] = c.median_a;
      row["median_b"] = c.median_b;
      row["change"] = c.change;
      row["interval_95"] = {c.low, c.high};
      row["p_value"] = c.p_value;
    }
    metrics[m.key] = std::move(row);
  }
  w["metrics"] = std::move(metrics);
  return w;
}

void PrintTable(const json& report, std::FILE* out) {
  std::fprintf(out, "A: %s\nB: %s\n", report["a"].get<std::string>().c_str(),
               report["b"].get<std::string>().c_str());
  for (const auto& [world, w] : report["worlds"].items()) {
    std::fprintf(out, "\n%s: %d runs in A, %d in B\n", world.c_str(), w["runs_a"].get<int>(),
                 w["runs_b"].get<int>());
    if (w["runs_a"].get<int>() == 0 || w["runs_b"].get<int>() == 0) continue;
    std::fprintf(out, "  %-26s %11s %11s %11s   %-24s %7s\n", "", "A median", "B median", "change",
                 "95 % interval of change", "p");
    const json& s = w["success"];
    char a_ok[32], b_ok[32];
    std::snprintf(a_ok, sizeof(a_ok), "%d/%d", s["a"].get<int>(), w["runs_a"].get<int>());
    std::snprintf(b_ok, sizeof(b_ok), "%d/%d", s["b"].get<int>(), w["runs_b"].get<int>());
    std::fprintf(out, "  %-26s %11s %11s %11s   %-24s %7.3f (Fisher)\n", "success", a_ok, b_ok, "",
                 "", s["p_value"].get<double>());
    for (const auto& [key, row] : w["metrics"].items()) {
      if (!row.contains("change")) {
        std::fprintf(out, "  %-26s %11s\n", row["label"].get<std::string>().c_str(),
                     "(no values on one side)");
        continue;
      }
      char interval[64], p[16];
      const double p_value = row["p_value"].get<double>();
      std::snprintf(p, sizeof(p), p_value < 0.001 ? "<0.001" : "%.3f", p_value);
      std::snprintf(interval, sizeof(interval), "[%+.4g, %+.4g]",
                    row["interval_95"][0].get<double>(), row["interval_95"][1].get<double>());
      std::fprintf(out, "  %-26s %11.4g %11.4g %+11.4g   %-24s %7s\n",
                   row["label"].get<std::string>().c_str(), row["median_a"].get<double>(),
                   row["median_b"].get<double>(), row["change"].get<double>(), interval, p);
    }
  }
  std::fprintf(out,
               "\nchange: B's median minus A's; interval: 95 %% percentile bootstrap of that "
               "change;\np: two-sided permutation test of it (%d relabellings, seed %d). A "
               "world's runs share its start\nand goal, so a code change moves every route: "
               "runs are compared as two sets, not seed by seed.\n",
               kResamples, static_cast<int>(kSeed));
}

}  // namespace

int CompareSweeps(const std::string& a, const std::string& b, bool as_json) {
  const fs::path file_a = RecordsFile(a, "--compare"), file_b = RecordsFile(b, "--compare");
  const std::vector<json> records_a = ReadRecords(file_a), records_b = ReadRecords(file_b);
  // A run recorded twice counts once, as in the sweep's own summary.
  RunsByWorld world_a = UniqueRunsByWorld(records_a), world_b = UniqueRunsByWorld(records_b);
  json report = {{"a", file_a.string()},
                 {"b", file_b.string()},
                 {"resamples", kResamples},
                 {"seed", kSeed},
                 {"worlds", json::object()}};
  for (const auto& [w, runs] : world_b) world_a[w];  // every world of either: empty in A if not
  for (const auto& [w, ra] : world_a) {
    const std::vector<const json*>& rb = world_b[w];
    if (ra.empty() || rb.empty()) {
      report["worlds"][w] = {{"runs_a", ra.size()}, {"runs_b", rb.size()}};
    } else {
      report["worlds"][w] = CompareWorld(ra, rb);
    }
  }
  if (as_json) {
    PrintTable(report, stderr);
    std::printf("%s\n", report.dump(2).c_str());
  } else {
    PrintTable(report, stdout);
  }
  return 0;
}

}  // namespace pitchlab::apps
