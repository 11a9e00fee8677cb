// `pitchlab bench`: a sweep of closed-loop runs (worlds x seeds), each in its own child process
// and run folder, one JSON line per run in runs.jsonl, a summary per world. `--shard K/N` runs
// every N-th run of the list so a cluster job array covers a sweep; `--summarize` merges shards.

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "pitchlab/mission/app_config.hpp"
#include "bench_compare.hpp"
#include "bench_records.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "pitchlab/mission/cleanup_registry.hpp"
#include "pitchlab/sensors/fnv1a.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "pitchlab/mission/run_config.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "sweep_statistics.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using json = BenchRecord;

constexpr auto kPollPeriod = std::chrono::milliseconds(20);
// How long an interrupted bench waits for its runs to remove their staging folders (a run's is at
// most ~8 MB: well under a second) before it kills them and removes the folders itself.
constexpr auto kChildCleanup = std::chrono::seconds(10);
constexpr std::size_t kMaxReasonChars = 300;

/// One world of the sweep: `label` names its runs and summary row ("office", "yard" for yard.xml).
struct BenchWorld {
  std::string label;  ///< catalog name or file stem
  std::string arg;    ///< what `pitchlab run --world` gets: the name, or the file's absolute path
};

/// One run of the sweep; `index` is its place in the full worlds x seeds list.
struct BenchRun {
  std::size_t index = 0;
  BenchWorld world;
  std::uint64_t seed = 0;
  std::string Id() const { return world.label + "-s" + std::to_string(seed); }
};

struct Shard {
  int k = 1, n = 1;  ///< 1-based shard k of n
  std::string Text() const { return std::to_string(k) + "/" + std::to_string(n); }
};

/// What the sweep needs besides the list of runs.
struct SweepSettings {
  fs::path out;
  Shard shard;
  int jobs = 1;
  double timeout_s = 600.0;
  std::optional<fs::path> config;
  /// ConfigHash of the config's bytes, recorded per run: a resumed sweep must use the same one.
  std::string config_hash;
  /// What every run drives (RouteArgs): `pitchlab run`'s --via and --round-trip, passed on.
  std::vector<std::string> route_args;
  /// The route as runs.jsonl records it ("goal", "round-trip", "via X,Y;...", ...): a resumed
  /// sweep must drive the same.
  std::string route;
  /// --keep failed: a successful run's folder keeps only kKeptOfSuccesses.
  bool keep_failed_only = false;
};

/// A child process running one `pitchlab run`.
struct Running {
  BenchRun run;
  pid_t pid = -1;
  Clock::time_point started;
  bool timed_out = false;
};

CliArgs BenchArgs() {
  CliArgs args(
      "bench",
      "A sweep of closed-loop runs: every world x every seed, each run isolated in its\n"
      "own process and run folder (DIR/runs/<world>-s<seed>). One JSON line per run is\n"
      "appended to DIR/runs.jsonl as it ends; runs already recorded there are skipped, so\n"
      "a killed sweep resumes (with the same --config: each line records its config_hash,\n"
      "and a sweep with another is refused). Each world's ground truth is ray cast by its\n"
      "first run and read from DIR/truth by the others (pitchlab run --truth-cache). A\n"
      "summary per world is printed and written to DIR/summary.json. With --shard K/N\n"
      "only runs whose index % N == K-1 are run, e.g. --shard\n"
      "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT; merge the shards' folders with\n"
      "--summarize DIR1 DIR2 ... . `--compare A B` says whether sweep B differs from\n"
      "sweep A, world by world (medians, intervals, p-values; no runs). Exit 0 when every\n"
      "run of the shard is recorded (failed runs are results, see the summary); 2 on bad\n"
      "input.");
  args.Option("worlds", "W1,W2,...", "built-in worlds (" + BuiltinWorldNames() + ") or MJCF files",
              "office,urban,terrain,gully")
      .Option("seeds", "A..B|S1,S2,...", "seeds: ranges and lists, e.g. 1..20 or 1,5,9 or 1..3,7",
              "1..20")
      .Option("out", "DIR", "bench folder (created when missing; resumed when it exists)")
      .Option("shard", "K/N", "run only shard K of N (1-based)", "1/1")
      .Option("jobs", "J", "runs at once", "1")
      .Option("timeout-s", "S", "wall time per run before it is killed and recorded as failed",
              "600")
      .Option("keep", "all|failed",
              "what stays of each run's folder: everything, or for successful runs only "
              "metrics.json, config.yaml and the trajectories (a terrain run's folder holds "
              "~75 MB, mostly each stop's scan.pcd; failures keep all, to be looked at)",
              "all")
      .Option("config", "FILE.yaml", "configuration passed to every run (see README)")
      .Option("via", "x,y[;x,y...]",
              "waypoints every run drives through before the goal (as `pitchlab run --via`; "
              "a waypoint off a world's map fails that world's runs)")
      .Flag("round-trip",
            "every run drives to its world's default goal (through --via) and back to the start")
      .Flag("summarize", "merge the runs.jsonl of the given folders into one summary; no runs")
      .Flag("compare",
            "how the second of two bench folders differs from the first, world by world: each "
            "metric's medians, the change with its 95 % bootstrap interval and a permutation "
            "test's p-value, success with Fisher's exact test; no runs")
      .Flag("merge", "same as --summarize")
      .Flag("json", "print the summary as JSON on stdout (the table goes to stderr)")
      .Flag("quiet", "no progress on stderr")
      .Positionals("[DIR...]",
                   "with --summarize: bench folders (or runs.jsonl files) to merge; with "
                   "--compare: two of them, A then B",
                   0, 1 << 20);
  return args;
}

// ---- input ----------------------------------------------------------------------------------

std::vector<std::string> SplitList(const std::string& text, const std::string& option) {
  std::vector<std::string> items;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) throw CliError("--" + option + " '" + text + "' has an empty item");
    items.push_back(item);
  }
  if (items.empty()) throw CliError("--" + option + " is empty");
  return items;
}

/// "1..20", "1,5,9", "1..3,7" -> the seeds in the order given; empty ranges and repeats are errors.
std::vector<std::uint64_t> ParseSeeds(const std::string& text) {
  std::vector<std::uint64_t> seeds;
  for (const std::string& item : SplitList(text, "seeds")) {
    const auto dots = item.find("..");
    if (dots == std::string::npos) {
      seeds.push_back(ParseWholeNumber(item, "seed"));
      continue;
    }
    const std::uint64_t first = ParseWholeNumber(item.substr(0, dots), "seed");
    const std::uint64_t last = ParseWholeNumber(item.substr(dots + 2), "seed");
    if (last < first) {
      throw CliError("--seeds range '" + item + "' is empty: write the smaller seed first (" +
                     std::to_string(last) + ".." + std::to_string(first) + ")");
    }
    if (last - first >= 1000000) throw CliError("--seeds range '" + item + "' is too long");
    for (std::uint64_t i = 0; i <= last - first; ++i) seeds.push_back(first + i);
  }
  std::set<std::uint64_t> seen;
  for (std::uint64_t s : seeds) {
    if (!seen.insert(s).second)
      throw CliError("--seeds lists seed " + std::to_string(s) + " twice");
  }
  return seeds;
}

/// Every world resolved now, so a typo fails before any run starts.
std::vector<BenchWorld> ParseWorlds(const std::string& text) {
  std::vector<BenchWorld> worlds;
  std::set<std::string> labels;
  for (const std::string& item : SplitList(text, "worlds")) {
    fs::path file;
    try {
      file = worlds::ResolveWorld(item, WorldsDir());
    } catch (const std::invalid_argument& e) {
      throw CliError(std::string("--worlds: ") + e.what());
    }
    const bool is_name = fs::path(item).extension() != ".xml";
    BenchWorld w{is_name ? item : fs::path(item).stem().string(),
                 is_name ? item : fs::absolute(file).lexically_normal().string()};
    if (!labels.insert(w.label).second) {
      throw CliError("--worlds names two worlds '" + w.label + "' (run folders would collide)");
    }
    worlds.push_back(w);
  }
  return worlds;
}

Shard ParseShard(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos) throw CliError("--shard '" + text + "' is not K/N (e.g. 1/4)");
  Shard s;
  const std::uint64_t k = ParseWholeNumber(text.substr(0, slash), "--shard K");
  const std::uint64_t n = ParseWholeNumber(text.substr(slash + 1), "--shard N");
  if (n < 1 || n > 1000000 || k < 1 || k > n) {
    throw CliError("--shard " + text + ": need 1 <= K <= N (K is 1-based, like " +
                   "$SLURM_ARRAY_TASK_ID with --array=1-N)");
  }
  s.k = static_cast<int>(k);
  s.n = static_cast<int>(n);
  return s;
}

/// FNV-1a (64 bits) of a config file's bytes as 16 hex digits; "built-in-defaults" without one.
/// Identifies the configuration a run was made with (a file edited in place changes it).
std::string ConfigHash(const std::string& bytes) {
  if (bytes.empty()) return "built-in-defaults";
  sensors::Fnv1a64 hash;
  hash.Add(bytes);
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash.value()));
  return text;
}

/// Loads the config the way `pitchlab run` will, so a bad file fails before any run.
fs::path CheckConfig(const std::string& path) {
  try {
    const mission::AppConfig config = mission::LoadAppConfig(path);
    mission::ParseRunSettings(mission::ReadBinaryFile(path), config.source, config.rig.robot.model);
  } catch (const std::exception& e) {
    throw CliError(std::string("--config: ") + e.what());
  }
  return fs::absolute(path);
}

SweepSettings ParseSweepSettings(const CliArgs& args) {
  SweepSettings s;
  s.out = args.Get("out");
  s.shard = ParseShard(args.Get("shard"));
  const std::uint64_t jobs = ParseWholeNumber(args.Get("jobs"), "--jobs");
  if (jobs < 1 || jobs > 1024) throw CliError("--jobs must be 1..1024");
  s.jobs = static_cast<int>(jobs);
  s.timeout_s = args.GetNumbers("timeout-s", 1)[0];
  if (!(s.timeout_s > 0)) throw CliError("--timeout-s must be positive");
  const std::string keep = args.Get("keep");
  if (keep != "all" && keep != "failed") {
    throw CliError("--keep must be all or failed, not '" + keep + "'");
  }
  s.keep_failed_only = keep == "failed";
  if (args.Has("config")) s.config = CheckConfig(args.Get("config"));
  s.config_hash = ConfigHash(s.config ? mission::ReadBinaryFile(*s.config) : std::string());
  std::vector<std::string> route;
  if (args.Has("via")) {
    (void)args.GetPoints("via");  // the format now (exit 2 before any run); the bounds per world, by run
    s.route_args = {"--via", args.Get("via")};
    route.push_back("via " + args.Get("via"));
  }
  if (args.Flagged("round-trip")) {
    s.route_args.push_back("--round-trip");
    route.push_back("round-trip");
  }
  s.route = route.empty() ? "goal" : route.size() == 1 ? route[0] : route[0] + ", " + route[1];
  return s;
}

/// The full list in a fixed order (worlds outer, seeds inner), then the shard's share of it.
std::vector<BenchRun> ShardRuns(const std::vector<BenchWorld>& worlds,
                                const std::vector<std::uint64_t>& seeds, const Shard& shard) {
  std::vector<BenchRun> runs;
  std::size_t index = 0;
  for (const BenchWorld& w : worlds) {
    for (std::uint64_t seed : seeds) {
      if (index % shard.n == static_cast<std::size_t>(shard.k - 1))
        runs.push_back({index, w, seed});
      ++index;
    }
  }
  return runs;
}

// ---- runs.jsonl -----------------------------------------------------------------------------

/// runs.jsonl opened for appending whole lines; each Append reaches the file before it returns.
class RecordLog {
 public:
  explicit RecordLog(const fs::path& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd_ < 0) {
      throw std::runtime_error("cannot open '" + path.string() + "': " + std::strerror(errno));
    }
    // A line torn by a killed bench must not swallow the next record.
    std::ifstream in(path, std::ios::binary | std::ios::ate);
    if (in.tellg() > 0) {
      in.seekg(-1, std::ios::end);
      if (in.get() != '\n') WriteAll("\n");
    }
  }
  ~RecordLog() { ::close(fd_); }
  RecordLog(const RecordLog&) = delete;
  RecordLog& operator=(const RecordLog&) = delete;

  void Append(const json& record) { WriteAll(record.dump() + "\n"); }

 private:
  void WriteAll(const std::string& text) {
    // One write() per line, so shards appending to a shared file do not interleave lines.
    const ssize_t n = ::write(fd_, text.data(), text.size());
    if (n != static_cast<ssize_t>(text.size())) {
      throw std::runtime_error("cannot append to '" + path_.string() +
                               "': " + std::strerror(errno));
    }
    ::fdatasync(fd_);
  }
  fs::path path_;
  int fd_ = -1;
};

// ---- one run in a child process -------------------------------------------------------------

fs::path RunDir(const fs::path& out, const BenchRun& run) { return out / "runs" / run.Id(); }
fs::path LogPath(const fs::path& out, const BenchRun& run) {
  return out / "logs" / (run.Id() + ".log");
}

/// Removes the hidden staging folders `.<id>.partial-*` a killed run leaves behind.
void RemoveStaging(const fs::path& out, const BenchRun& run) {
  const std::string prefix = "." + run.Id() + ".partial-";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(out / "runs", ec)) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) fs::remove_all(e.path(), ec);
  }
}

/// Starts `pitchlab run` for `run` with stdout and stderr in its log. The child dies with the
/// bench (PR_SET_PDEATHSIG), so a killed sweep leaves no orphan runs.
pid_t StartRun(const SweepSettings& s, const BenchRun& run) {
  std::vector<std::string> words = {"pitchlab", "run",
                                    "--world",  run.world.arg,
                                    "--seed",   std::to_string(run.seed),
                                    "--out",    RunDir(s.out, run).string(),
                                    "--truth-cache", (s.out / "truth").string(),
                                    "--json"};
  if (s.config) words.insert(words.end(), {"--config", s.config->string()});
  words.insert(words.end(), s.route_args.begin(), s.route_args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const std::string log = LogPath(s.out, run).string();
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {  // child: async-signal-safe calls only
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDONLY);
    if (fd < 0 || null < 0) ::_exit(127);
    ::dup2(null, 0);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    // The bench blocks SIGINT / SIGTERM for its watcher thread; a run starts with them open (a
    // hardware run's own handlers rely on it).
    sigset_t interrupts;
    sigemptyset(&interrupts);
    sigaddset(&interrupts, SIGINT);
    sigaddset(&interrupts, SIGTERM);
    ::sigprocmask(SIG_UNBLOCK, &interrupts, nullptr);
    ::execv("/proc/self/exe", argv.data());
    static const char kMessage[] = "bench: cannot exec /proc/self/exe\n";
    [[maybe_unused]] const ssize_t ignored = ::write(2, kMessage, sizeof(kMessage) - 1);
    ::_exit(127);
  }
  return pid;
}

/// The last non-empty line of a run's log: what a run that died early said last.
std::string LastLogLine(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  if (last.size() > kMaxReasonChars) last = last.substr(0, kMaxReasonChars) + "...";
  return last;
}

json Field(const json& metrics, const char* pointer) {
  const json::json_pointer p(pointer);
  return metrics.contains(p) ? metrics.at(p) : json();
}

/// The metrics.json of a finished run folder, or null when it is missing or unreadable.
json ReadMetrics(const fs::path& run_dir) {
  std::ifstream in(run_dir / "metrics.json");
  if (!in) return json();
  json m = json::parse(in, nullptr, /*allow_exceptions=*/false);
  return m.is_object() ? m : json();
}

/// The runs.jsonl line of one run: how its process ended plus the headline metrics.
json MakeRecord(const SweepSettings& s, const BenchRun& run, std::optional<int> exit_code,
                std::optional<int> signal, bool timed_out, double wall_s) {
  const json metrics = ReadMetrics(RunDir(s.out, run));
  json r = {{"world", run.world.label},
            {"seed", run.seed},
            {"index", run.index},
            {"shard", s.shard.Text()},
            {"config_hash", s.config_hash},
            {"route", s.route},
            {"exit_code", exit_code ? json(*exit_code) : json()},
            {"signal", signal ? json(*signal) : json()},
            {"wall_time_s", wall_s},
            {"run_dir", (fs::path("runs") / run.Id()).string()},
            {"log", (fs::path("logs") / (run.Id() + ".log")).string()}};
  const bool have_metrics = metrics.is_object();
  r["success"] = exit_code == 0 && have_metrics && metrics.value("success", false);
  if (timed_out) {
    char text[64];
    std::snprintf(text, sizeof(text), "timeout: killed after %g s", s.timeout_s);
    r["reason"] = text;
  } else if (signal) {
    r["reason"] = std::string("crashed: signal ") + std::to_string(*signal) + " (" +
                  ::strsignal(*signal) + ")";
  } else if (have_metrics) {
    r["reason"] = metrics.value("reason", std::string());
  } else {
    r["reason"] = "exit " + std::to_string(exit_code.value_or(-1)) +
                  " without metrics.json: " + LastLogLine(LogPath(s.out, run));
  }
  r["has_metrics"] = have_metrics;
  r["sim_time_s"] = Field(metrics, "/sim_time_s");
  r["run_wall_time_s"] = Field(metrics, "/wall_time_s");
  r["real_time_factor"] = Field(metrics, "/real_time_factor");
  r["stops"] = Field(metrics, "/stops");
  r["distance_m"] = Field(metrics, "/distance_m");
  r["odometry_distance_m"] = Field(metrics, "/odometry_distance_m");
  r["final_pose_error_m"] = Field(metrics, "/final_pose_error/translation_m");
  r["final_pose_error_deg"] = Field(metrics, "/final_pose_error/rotation_deg");
  // The stops' absolute trajectory error (metrics.json "trajectory_error"): unaligned, since the
  // start is known, and after SE(3) alignment.
  r["ate_m"] = Field(metrics, "/trajectory_error/ate/unaligned/rmse_m");
  r["ate_aligned_m"] = Field(metrics, "/trajectory_error/ate/aligned/rmse_m");
  // With run: {loop_closure: true} only (null otherwise): the ATE of the stops as they were
  // registered (the one above is after the last optimisation) and the loop edges' verdicts.
  r["ate_live_m"] = Field(metrics, "/trajectory_error_live/ate/unaligned/rmse_m");
  r["loop_closures_accepted"] = Field(metrics, "/loop_closures/accepted");
  r["loop_closures_rejected"] = Field(metrics, "/loop_closures/rejected");
  r["loop_closures_wrong"] = Field(metrics, "/loop_closures/wrong");
  r["final_true_distance_to_goal_m"] = Field(metrics, "/final_true_distance_to_goal_m");
  r["max_registration_error_m"] = Field(metrics, "/max_registration_error/translation_m");
  r["max_registration_error_deg"] = Field(metrics, "/max_registration_error/rotation_deg");
  r["registration_step_max_m"] = Field(metrics, "/registration_step_error/max_m");
  r["registration_step_max_deg"] = Field(metrics, "/registration_step_error/max_deg");
  r["registration_failures"] = Field(metrics, "/registration_failures");
  r["cost_ratio"] = Field(metrics, "/cost_ratio");
  r["closest_approach_to_forbidden_m"] = Field(metrics, "/closest_approach_to_forbidden_m");
  r["forbidden_cells_crossed"] = Field(metrics, "/forbidden_cells_crossed");
  r["hazard_cells_crossed"] = Field(metrics, "/hazard_cells_crossed");
  r["hazards_touched_steepest_deg"] = Field(metrics, "/hazards_touched/steepest_deg");
  r["map_cells_compared"] = Field(metrics, "/map_hazards/cells_compared");
  r["false_hazard_cells"] = Field(metrics, "/map_hazards/false_hazard_cells");
  r["false_hazard_cells_out_of_reach"] =
      Field(metrics, "/map_hazards/false_hazard_cells_out_of_reach");
  r["missed_hazard_cells"] = Field(metrics, "/map_hazards/missed_hazard_cells");
  r["max_tilt_deg"] = Field(metrics, "/max_tilt_deg");
  r["odometry_drift_p90_per_m"] = Field(metrics, "/odometry_drift/p90_per_m");
  return r;
}

// ---- the sweep ------------------------------------------------------------------------------

/// Reaps `r` if it has ended (killing it first when over time); returns its record then.
std::optional<json> Poll(const SweepSettings& s, Running& r) {
  const double wall_s = std::chrono::duration<double>(Clock::now() - r.started).count();
  int status = 0;
  const pid_t done = ::waitpid(r.pid, &status, WNOHANG);
  if (done == 0) {
    if (wall_s > s.timeout_s && !r.timed_out) {
      ::kill(r.pid, SIGKILL);
      r.timed_out = true;
    }
    return std::nullopt;
  }
  std::optional<int> exit_code, signal;
  if (done < 0) {
    signal = 0;  // lost the child (should not happen): recorded as a crash
  } else if (WIFEXITED(status)) {
    exit_code = WEXITSTATUS(status);
  } else {
    signal = WTERMSIG(status);
  }
  if (signal) RemoveStaging(s.out, r.run);
  return MakeRecord(s, r.run, exit_code, signal, r.timed_out, wall_s);
}

void PrintProgress(const json& record, std::size_t done, std::size_t total) {
  const json& sim = record["sim_time_s"];
  std::fprintf(stderr, "bench: run %zu of %zu: %s seed %llu: %s%s%s (%.1f s wall", done, total,
               record["world"].get<std::string>().c_str(),
               static_cast<unsigned long long>(record["seed"].get<std::uint64_t>()),
               record["success"].get<bool>() ? "success" : "FAILED",
               record["success"].get<bool>() ? "" : ": ",
               record["success"].get<bool>() ? "" : record["reason"].get<std::string>().c_str(),
               record["wall_time_s"].get<double>());
  if (sim.is_number()) std::fprintf(stderr, ", %.0f s simulated", sim.get<double>());
  std::fprintf(stderr, ")\n");
}

/// What a successful run's folder keeps with --keep failed: its numbers and what it was run with,
/// and the trajectories (small, and what trajectory-evaluation tools read).
const char* const kKeptOfSuccesses[] = {
    "metrics.json",         "config.yaml",         "trajectory_true.csv",
    "trajectory_true.tum",  "trajectories.geojson", "trajectory_estimated.csv",
    "trajectory_estimated.tum", "trajectory_estimated_live.tum"};

/// Removes everything but kKeptOfSuccesses from a finished run's folder; what cannot be removed is
/// said on stderr (the sweep goes on: its records are complete without the files).
void PruneRun(const fs::path& dir) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (std::find(std::begin(kKeptOfSuccesses), std::end(kKeptOfSuccesses), name) !=
        std::end(kKeptOfSuccesses)) {
      continue;
    }
    std::error_code rm;
    fs::remove_all(it->path(), rm);
    if (rm) std::fprintf(stderr, "bench: cannot remove %s: %s\n", it->path().c_str(),
                         rm.message().c_str());
  }
  if (ec) std::fprintf(stderr, "bench: cannot list %s: %s\n", dir.c_str(), ec.message().c_str());
}

/// A run whose folder was committed but never recorded (the bench died in between).
json RecoveredRecord(const SweepSettings& s, const BenchRun& run) {
  const json metrics = ReadMetrics(RunDir(s.out, run));
  const bool ok = metrics.is_object() && metrics.value("success", false);
  json r = MakeRecord(s, run, ok ? 0 : 1, std::nullopt, false,
                      metrics.is_object() ? metrics.value("wall_time_s", 0.0) : 0.0);
  r["recovered"] = true;
  return r;
}

/// On SIGINT / SIGTERM: passes the signal on to the running runs (each removes its own staging
/// folder), waits up to kChildCleanup for them, kills what is left, removes their staging folders.
/// True when runs were stopped.
bool StopRuns(const SweepSettings& s, std::vector<Running>& running, int signal) {
  for (const Running& r : running) ::kill(r.pid, signal);
  const auto deadline = Clock::now() + kChildCleanup;
  for (const Running& r : running) {
    while (::waitpid(r.pid, nullptr, WNOHANG) == 0) {
      if (Clock::now() > deadline) {
        ::kill(r.pid, SIGKILL);
        ::waitpid(r.pid, nullptr, 0);
        break;
      }
      std::this_thread::sleep_for(kPollPeriod);
    }
    RemoveStaging(s.out, r.run);
  }
  const bool stopped = !running.empty();
  running.clear();  // reaped here: the sweep must not poll them again and record them as crashes
  return stopped;
}

/// Runs `pending` with at most `jobs` at once, appending each record to the log as it ends.
void RunSweep(const SweepSettings& s, const std::vector<BenchRun>& pending, RecordLog& log,
              bool quiet) {
  std::vector<Running> running;
  std::mutex running_mutex;  // the interruption's watcher thread reads `running`
  // Set under running_mutex when the interruption takes the runs over: from then on the sweep
  // starts and records nothing (a run it stopped is no result, and a resumed sweep must run it;
  // the sweep used to poll the reaped runs and record them as "crashed: signal 0").
  bool stopping = false;
  const int cleanup = mission::RegisterCleanup(
      [&](int signal) {
        std::lock_guard<std::mutex> lock(running_mutex);
        stopping = true;
        return StopRuns(s, running, signal);
      },
      "the unfinished runs' folders (their logs stay in " + (s.out / "logs").string() + ")");
  struct Unregister {
    int id;
    ~Unregister() { mission::UnregisterCleanup(id); }
  } unregister{cleanup};
  std::size_t next = 0, done = 0;
  const auto finish = [&](const json& record) {
    log.Append(record);
    if (s.keep_failed_only && record.value("success", false)) {
      PruneRun(s.out / record["run_dir"].get<std::string>());
    }
    ++done;
    if (!quiet) PrintProgress(record, done, pending.size());
  };
  while (next < pending.size() || !running.empty()) {
    while (next < pending.size() && static_cast<int>(running.size()) < s.jobs) {
      const BenchRun& run = pending[next++];
      RemoveStaging(s.out, run);
      if (fs::exists(RunDir(s.out, run))) {
        finish(RecoveredRecord(s, run));
        continue;
      }
      if (!quiet) {
        std::fprintf(stderr, "bench: start %s seed %llu (%zu of %zu)\n", run.world.label.c_str(),
                     static_cast<unsigned long long>(run.seed), next, pending.size());
      }
      std::lock_guard<std::mutex> lock(running_mutex);
      if (stopping) break;
      running.push_back({run, StartRun(s, run), Clock::now(), false});
    }
    bool reaped = false;
    std::unique_lock<std::mutex> lock(running_mutex);
    if (stopping) {
      lock.unlock();
      mission::WaitIfInterrupted();  // the watcher ends the process
    }
    for (auto it = running.begin(); it != running.end();) {
      if (std::optional<json> record = Poll(s, *it)) {
        finish(*record);
        it = running.erase(it);
        reaped = true;
      } else {
        ++it;
      }
    }
    const bool idle = !reaped && !running.empty();
    lock.unlock();
    if (idle) std::this_thread::sleep_for(kPollPeriod);
  }
}

// ---- summary --------------------------------------------------------------------------------

json Median(const std::vector<double>& v) {
  if (v.empty()) return json();
  return apps::Median(v);
}

// Null when no record has the value (runs without loop closure).
json Sum(const std::vector<double>& v) {
  if (v.empty()) return json();
  double sum = 0;
  for (double x : v) sum += x;
  return sum;
}

json Max(const std::vector<double>& v) {
  if (v.empty()) return json();
  return *std::max_element(v.begin(), v.end());
}

/// How many of `records` have a number above zero at `key` (runs that crossed a cell they should
/// not have; a run without the number, unscored, does not count).
std::size_t CountPositive(const std::vector<const json*>& records, const char* key) {
  const std::vector<double> v = Numbers(records, key);
  return static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [](double x) { return x > 0; }));
}

/// One summary row over `records` (all of one world, or all of them).
json SummaryRow(const std::string& world, const std::vector<const json*>& records) {
  std::size_t successes = 0;
  std::map<std::string, int> reasons;
  for (const json* r : records) {
    if (r->value("success", false)) {
      ++successes;
    } else {
      ++reasons[r->value("reason", std::string("?"))];
    }
  }
  const std::vector<double> wall = Numbers(records, "wall_time_s");
  return {{"world", world},
          {"runs", records.size()},
          {"successes", successes},
          {"failures", records.size() - successes},
          {"success_rate", records.empty() ? 0.0 : double(successes) / records.size()},
          {"median_wall_time_s", Median(wall)},
          {"max_wall_time_s", Max(wall)},
          {"median_real_time_factor", Median(Numbers(records, "real_time_factor"))},
          {"median_final_pose_error_m", Median(Numbers(records, "final_pose_error_m"))},
          {"median_ate_m", Median(Numbers(records, "ate_m"))},
          {"median_ate_aligned_m", Median(Numbers(records, "ate_aligned_m"))},
          {"median_ate_live_m", Median(Numbers(records, "ate_live_m"))},
          {"loop_closures_accepted", Sum(Numbers(records, "loop_closures_accepted"))},
          {"loop_closures_rejected", Sum(Numbers(records, "loop_closures_rejected"))},
          {"wrong_loop_closures", Sum(Numbers(records, "loop_closures_wrong"))},
          {"max_registration_error_m", Max(Numbers(records, "max_registration_error_m"))},
          {"max_registration_step_m", Max(Numbers(records, "registration_step_max_m"))},
          {"max_registration_step_deg", Max(Numbers(records, "registration_step_max_deg"))},
          {"median_cost_ratio", Median(Numbers(records, "cost_ratio"))},
          {"median_false_hazard_percent", Median(FalseHazardPercent(records))},
          {"runs_over_forbidden_cells", CountPositive(records, "forbidden_cells_crossed")},
          {"runs_over_true_hazards", CountPositive(records, "hazard_cells_crossed")},
          // How steep the worst of those was: 16.4 deg against the planner's 16 is a margin used.
          {"steepest_hazard_touched_deg", Max(Numbers(records, "hazards_touched_steepest_deg"))},
          {"failure_reasons", reasons}};
}

/// Rows per world (sorted by name) and one over everything; a run recorded twice counts once.
json Summarize(const std::vector<json>& records, const std::vector<std::string>& sources) {
  std::size_t duplicates = 0;
  const RunsByWorld by_world = UniqueRunsByWorld(records, &duplicates);
  std::vector<const json*> all;
  for (const auto& [world, rs] : by_world) all.insert(all.end(), rs.begin(), rs.end());
  json rows = json::array();
  for (const auto& [world, rs] : by_world) rows.push_back(SummaryRow(world, rs));
  if (duplicates > 0) {
    std::fprintf(stderr, "bench: %zu run(s) recorded more than once; the first record counts\n",
                 duplicates);
  }
  return {{"worlds", rows},
          {"total", SummaryRow("all", all)},
          {"sources", sources},
          {"duplicates_ignored", duplicates}};
}

std::string Cell(const json& v, const char* format) {
  if (!v.is_number()) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), format, v.get<double>());
  return text;
}

void PrintTable(const json& summary, std::FILE* out) {
  // "reg max": the worst pose error of a registered stop (with the drift it inherits); "reg step
  // max": the worst error of one registration, the motion since the last merged stop; "false
  // haz": the final map's false hazard cells per cell compared with the truth, median over runs;
  // "ATE med": the stops' absolute trajectory error (RMSE, unaligned, at the final poses), median
  // over runs; "loops acc/rej/wrong": loop edges accepted and refused by the pose graph's test,
  // and accepted ones more than 0.1 m or 1 deg off the truth, summed ("-": loop closure off);
  // "unsafe forb/haz": runs whose robot crossed a forbidden cell (within half its width of a true
  // hazard) / a true hazard cell, what report.html calls "unsafe", success or not.
  std::fprintf(out, "%-14s %5s %5s %8s %18s %8s %14s %13s %13s %20s %13s %16s %20s\n", "world",
               "runs", "ok", "success", "wall med/max [s]", "RTF med", "pose err [m]",
               "ATE med [m]", "reg max [m]", "reg step max [m/deg]", "false haz [%]",
               "unsafe forb/haz", "loops acc/rej/wrong");
  std::vector<json> rows(summary["worlds"].begin(), summary["worlds"].end());
  rows.push_back(summary["total"]);
  for (const json& r : rows) {
    const std::string wall =
        Cell(r["median_wall_time_s"], "%.1f") + " / " + Cell(r["max_wall_time_s"], "%.1f");
    const std::string step = Cell(r["max_registration_step_m"], "%.3f") + " / " +
                             Cell(r["max_registration_step_deg"], "%.2f");
    const std::string loops = Cell(r["loop_closures_accepted"], "%.0f") + " / " +
                              Cell(r["loop_closures_rejected"], "%.0f") + " / " +
                              Cell(r["wrong_loop_closures"], "%.0f");
    const std::string unsafe = std::to_string(r.value("runs_over_forbidden_cells", 0)) + " / " +
                               std::to_string(r.value("runs_over_true_hazards", 0));
    std::fprintf(out, "%-14s %5zu %5zu %7.1f%% %18s %8s %14s %13s %13s %20s %13s %16s %20s\n",
                 r["world"].get<std::string>().c_str(), r["runs"].get<std::size_t>(),
                 r["successes"].get<std::size_t>(), 100.0 * r["success_rate"].get<double>(),
                 wall.c_str(), Cell(r["median_real_time_factor"], "%.1fx").c_str(),
                 Cell(r["median_final_pose_error_m"], "%.3f").c_str(),
                 Cell(r["median_ate_m"], "%.3f").c_str(),
                 Cell(r["max_registration_error_m"], "%.3f").c_str(), step.c_str(),
                 Cell(r["median_false_hazard_percent"], "%.2f").c_str(), unsafe.c_str(),
                 loops.c_str());
  }
  for (const auto& [reason, count] : summary["total"]["failure_reasons"].items()) {
    std::fprintf(out, "  failed %dx: %s\n", count.get<int>(), reason.c_str());
  }
}

/// Writes `text` to `path` through a temporary sibling and a rename (readers never see half).
void WriteAtomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp-" + std::to_string(::getpid());
  mission::WriteTextFile(tmp, text);
  fs::rename(tmp, path);
}

void Report(const json& summary, bool as_json) {
  PrintTable(summary, as_json ? stderr : stdout);
  if (as_json) std::cout << summary.dump(2) << "\n";
}

// ---- the two modes --------------------------------------------------------------------------

int SummarizeFolders(const CliArgs& args) {
  if (args.positionals().empty()) throw CliError("--summarize needs bench folders to merge");
  std::vector<json> records;
  std::vector<std::string> sources;
  for (const std::string& item : args.positionals()) {
    const fs::path file = RecordsFile(item, "--summarize");
    std::vector<json> more = ReadRecords(file);
    for (json& r : more) r["bench_dir"] = file.parent_path().string();
    records.insert(records.end(), more.begin(), more.end());
    sources.push_back(file.string());
  }
  const json summary = Summarize(records, sources);
  if (args.Has("out")) {
    const fs::path out = args.Get("out");
    fs::create_directories(out);
    std::string lines;
    for (const json& r : records) lines += r.dump() + "\n";
    WriteAtomically(out / "runs.jsonl", lines);
    WriteAtomically(out / "summary.json", summary.dump(2) + "\n");
  }
  Report(summary, args.Flagged("json"));
  return 0;
}

/// A resumed sweep reuses the runs already recorded: they must have been made with this config
/// and driven this route. Records from before config_hash (route) was recorded say nothing and
/// are taken as they are.
void CheckSameSweep(const SweepSettings& s, const std::vector<json>& records) {
  std::map<std::string, std::vector<std::string>> other_config, other_route;  // value -> run ids
  for (const json& r : records) {
    const std::string hash = r.value("config_hash", std::string());
    if (!hash.empty() && hash != s.config_hash) other_config[hash].push_back(RecordKey(r));
    const std::string route = r.value("route", std::string());
    if (!route.empty() && route != s.route) other_route[route].push_back(RecordKey(r));
  }
  const auto made_with = [](const std::map<std::string, std::vector<std::string>>& other) {
    std::string text;
    for (const auto& [value, ids] : other) {
      text += (text.empty() ? "" : "; ") + value + ": " + ids.front() +
              (ids.size() > 1 ? " and " + std::to_string(ids.size() - 1) + " more" : "");
    }
    return text;
  };
  if (!other_config.empty()) {
    throw CliError("bench folder '" + s.out.string() + "' holds runs made with another config (" +
                   made_with(other_config) + "); this sweep's is " + s.config_hash + " (" +
                   (s.config ? "--config " + s.config->string() : std::string("no --config")) +
                   "): resuming would mix them; give a new --out, or the config they were made "
                   "with");
  }
  if (!other_route.empty()) {
    throw CliError("bench folder '" + s.out.string() + "' holds runs that drove another route (" +
                   made_with(other_route) + "); this sweep's is '" + s.route +
                   "': resuming would mix them; give a new --out, or the same --via / "
                   "--round-trip");
  }
}

int Sweep(const CliArgs& args) {
  InstallInterruptCleanup("pitchlab bench");  // first: before any thread starts
  if (!args.positionals().empty()) {
    throw CliError("unexpected argument '" + args.positionals().front() +
                   "' (folders are for --summarize)");
  }
  const std::vector<BenchWorld> worlds = ParseWorlds(args.Get("worlds"));
  const std::vector<std::uint64_t> seeds = ParseSeeds(args.Get("seeds"));
  const SweepSettings s = ParseSweepSettings(args);
  const bool quiet = args.Flagged("quiet");
  const std::vector<BenchRun> shard = ShardRuns(worlds, seeds, s.shard);

  fs::create_directories(s.out / "runs");
  fs::create_directories(s.out / "logs");
  const fs::path jsonl = s.out / "runs.jsonl";
  std::set<std::string> recorded;
  const std::vector<json> records = ReadRecords(jsonl);
  CheckSameSweep(s, records);
  for (const json& r : records) recorded.insert(RecordKey(r));
  std::vector<BenchRun> pending;
  for (const BenchRun& run : shard) {
    if (!recorded.count(run.Id())) pending.push_back(run);
  }
  if (!quiet) {
    std::fprintf(stderr,
                 "bench: shard %s: %zu of %zu runs, %zu already recorded in %s, %zu to run, %d at "
                 "a time\n",
                 s.shard.Text().c_str(), shard.size(), worlds.size() * seeds.size(),
                 shard.size() - pending.size(), jsonl.string().c_str(), pending.size(), s.jobs);
  }
  {
    RecordLog log(jsonl);
    RunSweep(s, pending, log, quiet);
  }
  // The summary covers every run recorded in the folder (all shards that share it).
  const json summary = Summarize(ReadRecords(jsonl), {jsonl.string()});
  WriteAtomically(s.out / "summary.json", summary.dump(2) + "\n");
  Report(summary, args.Flagged("json"));
  return 0;
}

}  // namespace

int RunBench(int argc, char** argv) {
  CliArgs args = BenchArgs();
  if (!args.Parse(argc, argv)) return 0;
  if (args.Flagged("compare")) {
    if (args.Flagged("summarize") || args.Flagged("merge")) {
      throw CliError("--compare and --summarize are two different modes: give one");
    }
    if (args.positionals().size() != 2) {
      throw CliError("--compare needs two bench folders (A then B), got " +
                     std::to_string(args.positionals().size()));
    }
    return CompareSweeps(args.positionals()[0], args.positionals()[1], args.Flagged("json"));
  }
  if (args.Flagged("summarize") || args.Flagged("merge")) return SummarizeFolders(args);
  return Sweep(args);
}

}  // namespace pitchlab::apps
