// `pitchlab run`: the closed-loop stop-scan-go mission in a simulated world, scored against
// ground truth, written to one run folder with a report.

#include <mujoco/mujoco.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <random>
#include <sstream>

#include "app_config.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "hw_backend.hpp"
#include "interrupt.hpp"
#include "mission.hpp"
#include "output_paths.hpp"
#include "progress.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_truth.hpp"
#include "pitchlab/sim/sim_rig.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "pitchlab/worlds/world_metadata.hpp"
#include "run_config.hpp"
#include "run_folder.hpp"
#include "run_outputs.hpp"
#include "run_scoring.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kMapMargin_m = 1.0;
// The attitude sensor, a MEMS inclinometer: 0.2 deg of noise per read, and a calibration residual
// of 0.1 deg per axis, constant over a run (drawn per seed).
constexpr double kAttitudeSigma_rad = 0.2 * kDegToRad;
constexpr double kAttitudeBiasSigma_rad = 0.1 * kDegToRad;
constexpr std::uint64_t kAttitudeSeedSalt = 0x6174746974756465;  // "attitude": its own stream

CliArgs RunArgs() {
  CliArgs args("run",
               "Closed-loop stop-scan-go mission in a simulated world: scan, register against\n"
               "the map (odometry as prior), update the elevation map, plan to the goal, drive a\n"
               "prefix of the path, repeat until the goal. Scored against ground truth; writes a\n"
               "run folder with scans, maps, paths, trajectories, metrics.json and report.html.");
  args.Option("world", "NAME|FILE.xml",
              "built-in world (" + BuiltinWorldNames() + ") or any MJCF file", "terrain")
      .Option("start", "x,y,yaw", "start pose: metres, metres, degrees (default: the world's)")
      .Option("goal", "x,y", "goal in metres (default: the world's default goal)")
      .Option("robot", "p3at|p3dx", "robot model, overrides the config's robot.model")
      .Option("seed", "N", "seed of every random source, overrides the config's seed")
      .Option("config", "FILE.yaml", "configuration (see README)")
      .Option("out", "DIR", "run folder to create (default: runs/<world>-s<seed>-<time>)")
      .Option("backend", "sim|hw",
              "sim (default) or hw: the real devices of the config's `hw` "
              "section (`run --backend hw --help`), overrides the config's backend")
      .Flag("json", "print metrics.json on stdout at the end")
      .Flag("quiet", "no progress on stderr");
  return args;
}

std::string DefaultOut(const std::string& world, std::uint64_t seed) {
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  const std::string name = std::filesystem::path(world).stem().string();
  return "runs/" + name + "-s" + std::to_string(seed) + "-" + stamp;
}

worlds::WorldMetadata LoadMetadata(const std::filesystem::path& world) {
  char error[1000] = "";
  mjModel* model = mj_loadXML(world.string().c_str(), nullptr, error, sizeof(error));
  if (model == nullptr)
    throw std::runtime_error("cannot load world '" + world.string() + "': " + error);
  const worlds::WorldMetadata meta = worlds::ReadWorldMetadata(model);
  mj_deleteModel(model);
  return meta;
}

}  // namespace

int RunRun(int argc, char** argv) {
  // backend: hw (config or --backend): the same mission over the hardware drivers.
  if (SelectedBackend(argc, argv) == Backend::kHw) return RunHwMission(argc, argv);
  InstallInterruptCleanup("pitchlab run");  // first: before any thread starts
  const auto wall_start = std::chrono::steady_clock::now();
  CliArgs args = RunArgs();
  if (!args.Parse(argc, argv)) return 0;
  const bool quiet = args.Flagged("quiet");

  AppConfig config =
      LoadAppConfig(args.Has("config") ? std::optional(args.Get("config")) : std::nullopt);
  if (args.Has("seed")) {
    config.seed = args.GetWholeNumber("seed");
    config.sensors.lms200.seed = config.rig.lms200.seed = config.rig.odometry.seed =
        config.rig.imu.seed = config.seed;
  }
  if (args.Has("robot")) config.rig.robot.model = ParseRobotModel(args.Get("robot"));
  const std::string config_text =
      args.Has("config") ? ReadBinaryFile(args.Get("config")) : std::string();
  RunSettings settings = ParseRunSettings(config_text, config.source, config.rig.robot.model);

  const std::string world = args.Get("world");
  const std::string out = args.Has("out") ? args.Get("out") : DefaultOut(world, config.seed);
  CheckNewFolder("out", out);  // before the work, not after a 50-second run
  const std::filesystem::path world_path = worlds::ResolveWorld(world, WorldsDir());
  const worlds::WorldMetadata meta = LoadMetadata(world_path);
  Eigen::Vector3d start(meta.default_start.x_m, meta.default_start.y_m, meta.default_start.yaw_rad);
  if (args.Has("start")) {
    const std::vector<double> s = args.GetNumbers("start", 3);
    start = Eigen::Vector3d(s[0], s[1], s[2] * kDegToRad);
  }
  Eigen::Vector2d goal;
  if (args.Has("goal")) {
    const std::vector<double> g = args.GetNumbers("goal", 2);
    goal = Eigen::Vector2d(g[0], g[1]);
  } else if (meta.default_goal) {
    goal = Eigen::Vector2d(meta.default_goal->x_m, meta.default_goal->y_m);
  } else {
    throw CliError("world '" + world + "' names no default goal: give --goal x,y");
  }
  const worlds::Bounds2d& b = meta.bounds;
  if (goal.x() < b.x_min_m || goal.x() > b.x_max_m || goal.y() < b.y_min_m ||
      goal.y() > b.y_max_m) {
    throw std::runtime_error("goal (" + std::to_string(goal.x()) + ", " + std::to_string(goal.y()) +
                             ") is off the map: the world spans x " + std::to_string(b.x_min_m) +
                             " .. " + std::to_string(b.x_max_m) + ", y " +
                             std::to_string(b.y_min_m) + " .. " + std::to_string(b.y_max_m));
  }

  RunFolder folder(out);
  sim::SimRig rig(world_path.string(), config.rig);
  Result<Eigen::Isometry3d> placed = rig.PlaceRobot(start.x(), start.y(), start.z());
  if (!placed) throw std::runtime_error("cannot place the robot: " + placed.error().message);

  MissionConfig& mission = settings.mission;
  mission.goal_m = goal;
  mission.mount = config.rig.robot.mount;
  mission.map_area = mapping::GridGeometry::Covering(Eigen::Vector2d(b.x_min_m, b.y_min_m),
                                                     Eigen::Vector2d(b.x_max_m, b.y_max_m),
                                                     settings.cell_m, kMapMargin_m);
  std::optional<mapping::GeodeticOrigin> origin;
  if (meta.geodetic_origin) {
    origin = mapping::GeodeticOrigin{meta.geodetic_origin->latitude_deg,
                                     meta.geodetic_origin->longitude_deg,
                                     meta.geodetic_origin->height_m};
  }
  // Ground truth on the same grid: the true map, what is truly traversable, the true optimum.
  if (!quiet) {
    std::fprintf(stderr, "run: ground truth of %s: true surface on %d x %d cells\n", world.c_str(),
                 mission.map_area.size_x, mission.map_area.size_y);
  }
  mapping::TruthConfig truth_config;
  truth_config.progress = QuarterProgress("run: ground truth", "rows", quiet);
  mapping::ElevationMap truth_map =
      mapping::ComputeTrueElevationMap(rig.caster(), mission.map_area, truth_config);
  const mapping::ElevationLayers truth_layers = mapping::ComputeLayers(truth_map, mission.layers);
  const planning::TraversabilityGrid truth_grid =
      planning::BuildTraversability(truth_layers, mission.planner);
  if (!quiet) std::fprintf(stderr, "run: ground truth: the best path on the true map\n");
  auto optimum = planning::PlanPath(truth_grid, start.head<2>(), goal, mission.algorithm);
  if (!optimum) {
    throw std::runtime_error("the goal is unreachable on the true map: " + optimum.error().message);
  }

  sim::Simulation& sim = rig.sim();
  MissionProbes probes;
  probes.now_s = [&sim] { return sim.time_s(); };
  probes.true_pose = [&sim] { return sim.T_world_base(); };
  // The attitude sensor: the inclinometer's roll and pitch, truth plus its seeded bias and noise.
  std::mt19937_64 attitude_rng(config.seed ^ kAttitudeSeedSalt);
  std::normal_distribution<double> attitude_noise(0.0, kAttitudeSigma_rad);
  std::normal_distribution<double> attitude_bias(0.0, kAttitudeBiasSigma_rad);
  const Eigen::Vector2d bias(attitude_bias(attitude_rng), attitude_bias(attitude_rng));
  probes.roll_pitch_rad = [&sim, &attitude_rng, &attitude_noise, bias] {
    const Eigen::Matrix3d R = sim.T_world_base().linear();
    const double roll = std::atan2(R(2, 1), R(2, 2));
    const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    return Eigen::Vector2d(roll + bias.x() + attitude_noise(attitude_rng),
                           pitch + bias.y() + attitude_noise(attitude_rng));
  };
  MissionObserver observer;
  observer.on_stop = [&](const StopRecord& stop, const MissionResult& so_far) {
    WriteStopOutputs(folder, stop, so_far, origin, world_path.stem().string());
  };
  observer.on_progress = [&](const std::string& text) {
    if (quiet) return;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    std::fprintf(stderr, "run: %s | sim %.0f s, wall %.1f s (%.0fx real time)\n", text.c_str(),
                 sim.time_s(), wall, wall > 0 ? sim.time_s() / wall : 0.0);
  };
  const MissionResult result = RunMission(rig, rig.base(), *placed, mission, probes, observer);
  const planning::TraversabilityGrid final_grid = planning::BuildTraversability(
      mapping::ComputeLayers(result.elevation, mission.layers), mission.planner);
  const RunScore score =
      ScoreRun(result, truth_grid, final_grid, start.head<2>(), goal, mission.algorithm);

  RunContext context;
  context.world = world;
  context.world_file = world_path.string();
  context.robot = config.rig.robot.model == sim::P3Model::kP3AT ? "p3at" : "p3dx";
  context.seed = config.seed;
  context.start = start;
  context.goal = goal;
  context.geodetic_origin = origin;
  // The mount error the simulator drew from the seed (lms200.mount_error_sigma_deg): truth the
  // pipeline never saw, so a comment, not a setting read back.
  const Eigen::Vector3d mount_error_deg = rig.mount_error_rpy_rad() * 180.0 / M_PI;
  std::ostringstream truth;
  truth.precision(6);
  truth << "# sim truth: scanner mount error drawn for this run, roll/pitch/yaw [deg]: ["
        << mount_error_deg.x() << ", " << mount_error_deg.y() << ", " << mount_error_deg.z()
        << "]\n";
  context.config_yaml = AppConfigToYaml(config) + RunSettingsToYaml(settings) + truth.str();
  context.planner = MissionPlanner(mission);
  context.layers = mission.layers;
  context.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  WriteFinalOutputs(folder, context, result, score, &truth_layers, *optimum);
  folder.Commit();

  const nlohmann::json metrics = RunMetrics(context, result, score);
  if (args.Flagged("json")) std::cout << metrics.dump(2) << "\n";
  std::fprintf(stderr, "run: %s: %s after %zu stops, %.0f s simulated in %.1f s; report: %s\n",
               result.success ? "success" : "FAILED", result.reason.c_str(), result.stops.size(),
               result.end_s - result.start_s, context.wall_time_s,
               (folder.final_path() / "report.html").string().c_str());
  return result.success ? 0 : 1;
}

}  // namespace pitchlab::apps
