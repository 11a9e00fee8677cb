// `pitchlab merge`: register a sequence of scans into one map cloud and write it with the
// estimated trajectory (CSV and TUM); with --loop-closure, over a pose graph that closes loops.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "cloud_input.hpp"
#include "commands.hpp"
#include "pitchlab/mapping/atomic_file.hpp"
#include "pitchlab/mapping/map_builder.hpp"
#include "pitchlab/mapping/trajectory_metrics.hpp"
#include "pitchlab/mapping/tum_trajectory.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"

namespace pitchlab::apps {
namespace {

CliArgs MergeArgs() {
  CliArgs args(
      "merge",
      "Registers each scan against the map built from the scans before it (scan-to-map),\n"
      "merges the ones that register, and writes the voxel-downsampled map (in the first\n"
      "scan's base_link) and the trajectory CSV. Scans that fail are reported and left out.\n"
      "Scans that carry an odometry pose (a 3DTK scan's .pose) give each registration its\n"
      "prior; --prior-error bounds it. --loop-closure makes the merged scans the nodes of a\n"
      "pose graph: after each merge, earlier scans the robot may be back at are registered\n"
      "against it, a loop is kept only when the graph agrees with it (chi-square test), and the\n"
      "trajectory and map follow the optimised poses. The trajectory is also written in the TUM\n"
      "format (timestamp tx ty tz qx qy qz qw) beside the CSV. Exit 0 when every scan merged, 1\n"
      "when some did not (map still written), 2 on bad arguments.\n\n" +
          std::string(sensors::CloudFormatsHelp()));
  args.Positionals("SCANS...", "scans in acquisition order (any format below)", 1, 100000)
      .Option("out", "MAP.pcd", "where to write the map")
      .Option("trajectory", "FILE.csv",
              "where to write the trajectory (default: MAP_trajectory.csv)")
      .Option("config", "FILE.yaml", "registration settings in its 'registration:' section")
      .Option("voxel", "METRES", "map voxel edge", "0.1")
      .Option("prior-error", "metres,degrees",
              "how far each scan's odometry pose may be off since the last merged scan")
      .Option("sensor-origin", "x,y,z", kSensorOriginHelp)
      .Flag("as-recorded", kAsRecordedHelp)
      .Flag("loop-closure", "close loops over a pose graph of the merged scans")
      .Option("information-scale", "S",
              "with --loop-closure: factor in (0, 1] on every edge's information (default 0.1; "
              "mapping/README.md)")
      .Flag("json", "print the per-scan results as JSON on stdout");
  return args;
}

std::string TrajectoryPath(const CliArgs& args, const std::string& out) {
  if (args.Has("trajectory")) return args.Get("trajectory");
  std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + "_trajectory.csv")).string();
}

// The TUM file beside the CSV: its path with the extension .tum.
std::string TumPath(const std::string& trajectory_csv) {
  return std::filesystem::path(trajectory_csv).replace_extension(".tum").string();
}

// Each pose stamped with its scan's first line's stamp, or with its position in the sequence [s]
// when the scans' stamps do not increase (files that carry none): TUM associates poses by time.
std::vector<mapping::StampedPose> Stamped(const std::vector<mapping::TrajectoryPose>& trajectory,
                                          const std::vector<double>& stamps_s) {
  bool increasing = true;
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    increasing &= stamps_s[trajectory[i].scan_index] > stamps_s[trajectory[i - 1].scan_index];
  }
  std::vector<mapping::StampedPose> out;
  for (const mapping::TrajectoryPose& p : trajectory) {
    out.push_back(
        {increasing ? stamps_s[p.scan_index] : static_cast<double>(p.scan_index), p.T_map_base});
  }
  return out;
}

// Each loop closure tried for the step: the earlier scan, what its registration concluded and,
// when it succeeded, the graph's verdict.
nlohmann::json LoopAttemptsJson(const mapping::MergeStep& step,
                                const std::vector<std::string>& files) {
  nlohmann::json out = nlohmann::json::array();
  for (const mapping::LoopAttempt& a : step.loop_attempts) {
    nlohmann::json j = {{"against", files[a.target_scan_index]},
                        {"outcome", mapping::ToString(a.registration.outcome)},
                        {"reason", a.registration.reason},
                        {"accepted", a.tested && a.decision.accepted}};
    if (a.tested) {
      j["chi2_increase"] = a.decision.chi2_increase;
      j["gate_chi2"] = a.decision.gate_chi2;
    }
    out.push_back(j);
  }
  return out;
}

// Loop closures over the sequence; with every scan's ground truth, the wrong ones too.
nlohmann::json LoopClosuresJson(const mapping::MapBuilder& builder,
                                const std::vector<std::optional<Eigen::Isometry3d>>& truth) {
  const mapping::LoopClosureCounts c = builder.loop_closures();
  nlohmann::json out = {{"registered", c.registered},
                        {"registration_failed", c.registration_failed},
                        {"accepted", c.accepted},
                        {"rejected", c.rejected}};
  std::size_t wrong = 0;
  for (const mapping::LoopClosure& l : builder.accepted_loops()) {
    const auto& a = truth[l.from_scan_index];
    const auto& b = truth[l.to_scan_index];
    if (!a || !b) return out;  // no truth, no verdict
    wrong += mapping::IsWrongLoopClosure(l.T_from_to, a->inverse() * *b);
  }
  out["wrong"] = wrong;
  return out;
}

// The trajectory as CSV: a header, then one line a merged scan.
std::string TrajectoryCsv(const std::vector<std::string>& files,
                          const std::vector<mapping::TrajectoryPose>& trajectory) {
  std::ostringstream csv;
  csv << "scan,file,x_m,y_m,z_m,qw,qx,qy,qz\n";
  csv.precision(9);
  for (const mapping::TrajectoryPose& p : trajectory) {
    const Eigen::Vector3d t = p.T_map_base.translation();
    const Eigen::Quaterniond q(p.T_map_base.rotation());
    csv << p.scan_index << "," << files[p.scan_index] << "," << t.x() << "," << t.y() << ","
        << t.z() << "," << q.w() << "," << q.x() << "," << q.y() << "," << q.z() << "\n";
  }
  return csv.str();
}

}  // namespace

int RunMerge(int argc, char** argv) {
  CliArgs args = MergeArgs();
  if (!args.Parse(argc, argv)) return 0;
  const std::string out = args.Get("out");
  mapping::MapConfig config;
  if (args.Has("config")) config.registration = mapping::LoadRegistrationConfig(args.Get("config"));
  config.map_voxel_m = args.GetNumbers("voxel", 1)[0];
  if (!(config.map_voxel_m > 0)) throw CliError("--voxel must be > 0");
  std::optional<mapping::GuessUncertainty> bound;
  if (const auto e = PriorErrorOption(args)) bound = mapping::GuessUncertainty{e->first, e->second};
  const std::optional<Eigen::Vector3d> origin = SensorOriginOption(args);

  const std::vector<std::string>& files = args.positionals();
  nlohmann::json steps = nlohmann::json::array();
  std::size_t failed = 0;
  std::optional<Eigen::Isometry3d> T_world_first;  // ground truth of simulated scans, if any
  std::optional<Eigen::Isometry3d> T_odom_first;   // odometry of the first scan, if it has one
  std::optional<mapping::MapBuilder> builder;
  config.loop_closure.enabled = args.Flagged("loop-closure");
  if (args.Has("information-scale")) {
    if (!config.loop_closure.enabled) throw CliError("--information-scale needs --loop-closure");
    const double scale = args.GetNumbers("information-scale", 1)[0];
    if (!(scale > 0 && scale <= 1)) throw CliError("--information-scale must lie in (0, 1]");
    config.loop_closure.information_scale = scale;
  }
  std::vector<double> stamps_s;
  std::vector<std::optional<Eigen::Isometry3d>> truth;  // T_map_base of each scan, when known
  for (const std::string& file : files) {
    nlohmann::json line_pitch;
    const sensors::Scan3D scan_read =
        LoadInputCloud(file, origin, !args.Flagged("as-recorded"), &line_pitch);
    const sensors::Scan3D* scan = &scan_read;
    if (!builder) {  // one sensor for the sequence: where the first scan says it sits
      config.sensor_base = scan->sensor_origin->cast<float>();
      builder.emplace(config);
      if (scan->has_odometry) T_odom_first = scan->T_world_base;
    }
    std::optional<Eigen::Isometry3d> odometry;
    if (T_odom_first && scan->has_odometry) odometry = T_odom_first->inverse() * scan->T_world_base;
    Result<mapping::MergeStep> step =
        builder->Add(mapping::CloudFromScan(*scan), odometry, odometry ? bound : std::nullopt);
    if (!step) throw std::runtime_error(file + ": " + step.error().message);
    failed += step->merged ? 0 : 1;
    stamps_s.push_back(scan->stamp_s);
    if (scan->has_truth && !T_world_first) T_world_first = scan->T_world_base;
    truth.push_back(scan->has_truth ? std::optional<Eigen::Isometry3d>(T_world_first->inverse() *
                                                                       scan->T_world_base)
                                    : std::nullopt);
    nlohmann::json s = {{"file", file},
                        {"merged", step->merged},
                        {"outcome", mapping::ToString(step->registration.outcome)},
                        {"reason", step->registration.reason},
                        {"path", mapping::ToString(step->registration.path)},
                        {"inlier_ratio", step->registration.inlier_ratio},
                        {"time_s", step->registration.timings.total_s},
                        {"line_pitch", line_pitch}};
    if (truth.back() && step->merged) {
      const mapping::PoseError e = mapping::ComparePoses(step->T_map_base, *truth.back());
      s["ground_truth_error"] = {{"rotation_deg", e.rotation_deg},
                                 {"translation_m", e.translation_m}};
    }
    if (config.loop_closure.enabled) {
      s["loops"] = LoopAttemptsJson(*step, files);
      s["reposed"] = step->reposed;
    }
    steps.push_back(s);
    if (!args.Flagged("json")) {
      std::printf("%s: %s (%s)\n", file.c_str(), step->merged ? "merged" : "NOT merged",
                  step->registration.reason.c_str());
    }
  }
  sensors::Scan3D map;
  for (const Eigen::Vector3f& p : builder->MapCloud()) {
    sensors::ScanPoint sp;
    sp.x = p.x(), sp.y = p.y(), sp.z = p.z();
    sp.range_m = p.norm();
    map.points.push_back(sp);
  }
  // The map and its two trajectories are one answer: each file is written whole or not at all,
  // and when one cannot be written those already written are removed with it.
  const std::string trajectory_path = TrajectoryPath(args, out);
  const std::string tum_path = TumPath(trajectory_path);
  std::vector<std::string> written;
  const auto write = [&](const std::string& path, const Result<void>& result) {
    if (!result) {
      for (const std::string& w : written) std::remove(w.c_str());
      throw std::runtime_error(result.error().message);
    }
    written.push_back(path);
  };
  write(out, sensors::WriteScanPcd(map, out));
  write(trajectory_path, mapping::WriteFileAtomically(
                             trajectory_path, TrajectoryCsv(files, builder->trajectory())));
  write(tum_path,
        mapping::WriteTumTrajectory(tum_path, Stamped(builder->trajectory(), stamps_s)));
  nlohmann::json summary = {{"map", out},
                            {"map_points", map.points.size()},
                            {"trajectory", trajectory_path},
                            {"trajectory_tum", tum_path},
                            {"scans", files.size()},
                            {"merged", files.size() - failed}};
  if (config.loop_closure.enabled) summary["loop_closures"] = LoopClosuresJson(*builder, truth);
  // The estimate as it ends (optimised, with loop closure) against the truth.
  if (const auto& last = builder->trajectory().back(); truth[last.scan_index]) {
    const mapping::PoseError e = mapping::ComparePoses(last.T_map_base, *truth[last.scan_index]);
    summary["final_ground_truth_error"] = {{"rotation_deg", e.rotation_deg},
                                           {"translation_m", e.translation_m}};
  }
  if (args.Flagged("json")) {
    summary["steps"] = steps;
    std::cout << summary.dump(2) << "\n";
  } else {
    std::printf("wrote %s (%zu points), %s and %s: %zu of %zu scans merged\n", out.c_str(),
                map.points.size(), trajectory_path.c_str(), tum_path.c_str(), files.size() - failed,
                files.size());
    if (config.loop_closure.enabled) {
      const mapping::LoopClosureCounts c = builder->loop_closures();
      std::printf(
          "loop closures: %zu accepted, %zu rejected by the graph's test, %zu of %zu "
          "registrations failed\n",
          c.accepted, c.rejected, c.registration_failed, c.registered);
    }
  }
  return failed == 0 ? 0 : 1;
}

}  // namespace pitchlab::apps
