// `pitchlab scan`: place the robot in a world, sweep the laser once, write the 3D scan as PCD.

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "pitchlab/mission/app_config.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "output_paths.hpp"
#include "pitchlab/sensors/scan_pcd.hpp"
#include "pitchlab/sim/sim_rig.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

CliArgs ScanArgs() {
  CliArgs args("scan",
               "Places the robot in a world, lets it settle, sweeps the pitching LMS200 once and\n"
               "writes the 3D scan as a binary PCD (points in base_link; the ground-truth pose of\n"
               "base_link in the world is the PCD VIEWPOINT).");
  args.Option("world", "NAME|FILE.xml", "built-in world (" + BuiltinWorldNames() +
                                            ") or any MJCF file", "terrain")
      .Option("pose", "x,y,yaw", "start pose: metres, metres, degrees (default: the world's start)")
      .Option("config", "FILE.yaml", "rig configuration (see README)")
      .Option("robot", "p3at|p3dx", "robot model, overrides the config's robot.model")
      .Option("caster", "embree|mujoco",
              "ray caster: Embree, or MuJoCo mj_ray as reference (not on a heightfield with more "
              "rows than columns, such as the gully's, which MuJoCo 2.2.2's mj_ray reads past)",
              "embree")
      .Option("out", "FILE.pcd", "where to write the scan")
      .Flag("json", "print the summary as JSON on stdout")
      .Flag("quiet", "no progress on stderr");
  return args;
}

nlohmann::json PoseJson(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d t = T.translation();
  const Eigen::Matrix3d R = T.rotation();
  // ZYX (yaw, pitch, roll) as REP-103 reports attitude.
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  nlohmann::json matrix = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) matrix.push_back(T.matrix()(r, c));
  }
  return {{"x_m", t.x()},
          {"y_m", t.y()},
          {"z_m", t.z()},
          {"roll_deg", roll * kRadToDeg},
          {"pitch_deg", pitch * kRadToDeg},
          {"yaw_deg", yaw * kRadToDeg},
          {"T_world_base", matrix}};
}

}  // namespace

int RunScan(int argc, char** argv) {
  CliArgs args = ScanArgs();
  if (!args.Parse(argc, argv)) return 0;
  const std::string out = args.Get("out");
  CheckOutputFile("out", out);  // before the simulation, not after it
  const bool json = args.Flagged("json");
  const bool quiet = args.Flagged("quiet");

  mission::AppConfig config =
      mission::LoadAppConfig(args.Has("config") ? std::optional(args.Get("config")) : std::nullopt);
  if (args.Has("robot")) config.rig.robot.model = ParseRobotModel(args.Get("robot"));
  const std::string caster = args.Get("caster");
  if (caster != "embree" && caster != "mujoco") {
    throw CliError("--caster '" + caster + "' is not a caster (embree, mujoco)");
  }
  config.rig.caster = caster == "embree" ? sim::CasterKind::kEmbree : sim::CasterKind::kMujoco;
  const auto world_path = worlds::ResolveWorld(args.Get("world"), WorldsDir());
  std::vector<double> pose;
  if (args.Has("pose")) pose = args.GetNumbers("pose", 3);

  const auto wall_start = std::chrono::steady_clock::now();
  sim::SimRig rig(world_path.string(), config.rig);
  Result<Eigen::Isometry3d> placed =
      pose.empty() ? rig.PlaceAtDefaultStart()
                   : rig.PlaceRobot(pose[0], pose[1], pose[2] / kRadToDeg);
  if (!placed) throw std::runtime_error("cannot place the robot: " + placed.error().message);

  const bool tty = ::isatty(STDERR_FILENO);
  int last_reported = -1;
  rig.scan_source().set_progress([&](int done, int total) {
    if (quiet) return;
    const int percent = 100 * done / total;
    if (tty) {
      std::fprintf(stderr, "\rscan: line %d/%d", done, total);
      if (done == total) std::fputc('\n', stderr);
    } else if (percent / 25 != last_reported / 25) {
      std::fprintf(stderr, "scan: line %d/%d\n", done, total);
    }
    last_reported = percent;
  });
  const auto scan_start = std::chrono::steady_clock::now();
  Result<sensors::Scan3D> scan = rig.Acquire();
  if (!scan) throw std::runtime_error("scan failed: " + scan.error().message);
  const double scan_wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - scan_start).count();
  scan->world = world_path.stem().string();  // so `map --world` can tell a scan of another world
  if (Result<void> written = sensors::WriteScanPcd(*scan, out); !written) {
    throw std::runtime_error(written.error().message);
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  const std::size_t readings = scan->points.size() + scan->no_returns + scan->over_ranges;
  nlohmann::json summary = {{"world", args.Get("world")},
                            {"world_file", world_path.string()},
                            {"robot", config.rig.robot.model == sim::P3Model::kP3AT ? "p3at"
                                                                                    : "p3dx"},
                            {"seed", config.seed},
                            {"out", out},
                            {"lines", scan->lines.size()},
                            {"readings", readings},
                            {"points", scan->points.size()},
                            {"no_returns", scan->no_returns},
                            {"over_ranges", scan->over_ranges},
                            {"misses", scan->no_returns + scan->over_ranges},
                            {"scan_duration_s", scan->duration_s},
                            {"scan_wall_time_s", scan_wall_s},
                            {"wall_time_s", wall_s},
                            {"pose", PoseJson(scan->T_world_base)}};
  if (json) {
    std::cout << summary.dump(2) << "\n";
    return 0;
  }
  const Eigen::Vector3d t = scan->T_world_base.translation();
  std::printf(
      "wrote %s: %zu points of %zu readings (%zu no return, %zu over range), %zu lines\n"
      "world %s, robot at x %.3f y %.3f z %.3f m, yaw %.2f deg (ground truth)\n"
      "simulated scan %.2f s, wall time %.2f s (scan %.2f s)\n",
      out.c_str(), scan->points.size(), readings, scan->no_returns, scan->over_ranges,
      scan->lines.size(), world_path.string().c_str(), t.x(), t.y(), t.z(),
      summary["pose"]["yaw_deg"].get<double>(), scan->duration_s, wall_s, scan_wall_s);
  return 0;
}

}  // namespace pitchlab::apps
