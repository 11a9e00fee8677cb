// `pitchlab merge`: register a sequence of scans into one map cloud and write it with the
// estimated trajectory.

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "cloud_input.hpp"
#include "commands.hpp"
#include "pitchlab/mapping/map_builder.hpp"
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
      "prior; --prior-error bounds it. Exit 0 when every scan merged, 1 when some did not\n"
      "(map still written), 2 on bad arguments.\n\n" +
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
      .Flag("json", "print the per-scan results as JSON on stdout");
  return args;
}

std::string TrajectoryPath(const CliArgs& args, const std::string& out) {
  if (args.Has("trajectory")) return args.Get("trajectory");
  std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + "_trajectory.csv")).string();
}

void WriteTrajectory(const std::string& path, const std::vector<std::string>& files,
                     const std::vector<mapping::TrajectoryPose>& trajectory) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream csv(tmp);
    if (!csv) throw std::runtime_error(path + ": cannot be written");
    csv << "scan,file,x_m,y_m,z_m,qw,qx,qy,qz\n";
    csv.precision(9);
    for (const mapping::TrajectoryPose& p : trajectory) {
      const Eigen::Vector3d t = p.T_map_base.translation();
      const Eigen::Quaterniond q(p.T_map_base.rotation());
      csv << p.scan_index << "," << files[p.scan_index] << "," << t.x() << "," << t.y() << ","
          << t.z() << "," << q.w() << "," << q.x() << "," << q.y() << "," << q.z() << "\n";
    }
    if (!csv.flush()) throw std::runtime_error(path + ": write failed");
  }
  std::filesystem::rename(tmp, path);
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
  for (const std::string& file : files) {
    const sensors::Scan3D scan_read = LoadInputCloud(file, origin);
    const sensors::Scan3D* scan = &scan_read;
    if (!builder) {  // one sensor for the sequence: where the first scan says it sits
      config.sensor_base = scan->sensor_origin->cast<float>();
      builder.emplace(config);
      if (scan->has_odometry) T_odom_first = scan->T_world_base;
    }
    std::optional<Eigen::Isometry3d> odometry;
    if (T_odom_first && scan->has_odometry) odometry = T_odom_first->inverse() * scan->T_world_base;
    Result<mapping::MergeStep> step = builder->Add(mapping::CloudFromScan(*scan), odometry,
                                                   odometry ? bound : std::nullopt);
    if (!step) throw std::runtime_error(file + ": " + step.error().message);
    failed += step->merged ? 0 : 1;
    nlohmann::json s = {{"file", file},
                        {"merged", step->merged},
                        {"outcome", mapping::ToString(step->registration.outcome)},
                        {"reason", step->registration.reason},
                        {"path", mapping::ToString(step->registration.path)},
                        {"inlier_ratio", step->registration.inlier_ratio},
                        {"time_s", step->registration.timings.total_s}};
    if (scan->has_truth && step->merged) {
      if (!T_world_first) T_world_first = scan->T_world_base;
      const mapping::PoseError e =
          mapping::ComparePoses(step->T_map_base, T_world_first->inverse() * scan->T_world_base);
      s["ground_truth_error"] = {{"rotation_deg", e.rotation_deg},
                                 {"translation_m", e.translation_m}};
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
  if (Result<void> written = sensors::WriteScanPcd(map, out); !written) {
    throw std::runtime_error(written.error().message);
  }
  const std::string trajectory_path = TrajectoryPath(args, out);
  WriteTrajectory(trajectory_path, files, builder->trajectory());
  if (args.Flagged("json")) {
    std::cout << nlohmann::json{{"map", out},
                                {"map_points", map.points.size()},
                                {"trajectory", trajectory_path},
                                {"scans", files.size()},
                                {"merged", files.size() - failed},
                                {"steps", steps}}
                     .dump(2)
              << "\n";
  } else {
    std::printf("wrote %s (%zu points) and %s: %zu of %zu scans merged\n", out.c_str(),
                map.points.size(), trajectory_path.c_str(), files.size() - failed, files.size());
  }
  return failed == 0 ? 0 : 1;
}

}  // namespace pitchlab::apps
