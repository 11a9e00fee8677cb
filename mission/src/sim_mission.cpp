#include "pitchlab/mission/sim_mission.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "background_jobs.hpp"
#include "report_summary.hpp"
#include "run_pictures.hpp"
#include "truth_cache.hpp"
#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_truth.hpp"
#include "pitchlab/mission/run_folder.hpp"
#include "pitchlab/mission/waypoint_route.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sensors/number_text.hpp"
#include "pitchlab/sensors/stopwatch.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
// The map covers the world's bounds and this much around them: a robot at the edge of the bounds
// still has its own footprint and the ground beside it on the map [m].
constexpr double kMapMargin_m = 1.0;
// The attitude sensor, a MEMS inclinometer: 0.2 deg of noise per read, and a calibration residual
// of 0.1 deg per axis, constant over a run (drawn per seed).
constexpr double kAttitudeSigma_rad = 0.2 * kDegToRad;
constexpr double kAttitudeBiasSigma_rad = 0.1 * kDegToRad;
constexpr std::uint64_t kAttitudeSeedSalt = 0x6174746974756465;  // "attitude": its own stream

void CheckOnMap(const std::string& what, const Eigen::Vector2d& p, const worlds::Bounds2d& b) {
  if (p.x() < b.x_min_m || p.x() > b.x_max_m || p.y() < b.y_min_m || p.y() > b.y_max_m) {
    throw std::runtime_error(what + " (" + NumberText(p.x()) + ", " + NumberText(p.y()) +
                             ") is off the map: the world spans x " + NumberText(b.x_min_m) +
                             " .. " + NumberText(b.x_max_m) + ", y " +
                             NumberText(b.y_min_m) + " .. " + NumberText(b.y_max_m));
  }
}

// The run's start (given or the world's), waypoints and goal (given or the world's), checked on
// its map; a round trip makes the goal its last waypoint and the start its goal.
void ResolveEnds(const SimMissionSpec& spec, const worlds::WorldMetadata& meta,
                 Eigen::Vector3d& start, std::vector<Eigen::Vector2d>& via, Eigen::Vector2d& goal) {
  start = spec.start.value_or(
      Eigen::Vector3d(meta.default_start.x_m, meta.default_start.y_m, meta.default_start.yaw_rad));
  if (spec.goal_m) {
    goal = *spec.goal_m;
  } else if (meta.default_goal) {
    goal = Eigen::Vector2d(meta.default_goal->x_m, meta.default_goal->y_m);
  } else {
    throw std::invalid_argument("world '" + spec.world_file.string() +
                                "' names no default goal: give one");
  }
  via = spec.via_m;
  for (std::size_t k = 0; k < via.size(); ++k) {
    if (!via[k].allFinite()) {
      throw std::invalid_argument("waypoint " + std::to_string(k + 1) + " is not a finite point");
    }
    CheckOnMap("waypoint " + std::to_string(k + 1), via[k], meta.bounds);
  }
  CheckOnMap("goal", goal, meta.bounds);
  if (spec.round_trip) {
    via.push_back(goal);
    goal = start.head<2>();
  }
}

// What the truth knows on the mission's grid: the true map's traversability and the optimum.
struct Truth {
  mapping::ElevationLayers layers;
  planning::TraversabilityGrid grid;
  planning::Path optimum;
};

Truth TruthOf(const mapping::ElevationMap& map, const MissionConfig& mission,
              const Eigen::Vector2d& start) {
  Truth truth;
  truth.layers = mapping::ComputeTruthLayers(map, mission.layers);
  truth.grid = planning::BuildTraversability(truth.layers, mission.planner);
  auto optimum = PlanRoute(truth.grid, start, mission.via_m, mission.goal_m, mission.algorithm);
  if (!optimum) {
    throw std::runtime_error(std::string(mission.via_m.empty() ? "the goal" : "the route") +
                             " is unreachable on the true map: " + optimum.error().message);
  }
  truth.optimum = std::move(*optimum);
  return truth;
}

// What the ground truth's rays see: the world without the robot.
sensors::RayCasterOptions TruthCasterOptions() {
  sensors::RayCasterOptions options;
  options.exclude_subtree_of_body = sim::kRobotBody;
  return options;
}

// The world as placed, for the ground truth's ray caster on another thread: the geoms' poses,
// all of the simulation's state the caster reads, copied before the mission starts (the
// simulation steps on meanwhile), and a caster of its own, built (BuildCaster) on that thread with
// an mjData of its own holding them (made there: clearing its 100 MB solver stack took 0.09 s of
// the run's start). The caster reads the model's geoms, which the mission never writes (it
// changes the timestep and the joints' state only).
struct TruthScene {
  explicit TruthScene(sim::SimRig& rig) : model(rig.sim().model()) {
    const mjData* d = rig.sim().data();
    geom_xpos.assign(d->geom_xpos, d->geom_xpos + 3 * model->ngeom);
    geom_xmat.assign(d->geom_xmat, d->geom_xmat + 9 * model->ngeom);
  }
  void BuildCaster() {
    data.reset(mj_makeData(model));
    if (!data) throw std::runtime_error("ground truth: mj_makeData failed");
    std::copy(geom_xpos.begin(), geom_xpos.end(), data->geom_xpos);
    std::copy(geom_xmat.begin(), geom_xmat.end(), data->geom_xmat);
    caster = sensors::MakeEmbreeRayCaster(model, data.get(), TruthCasterOptions());
  }
  const mjModel* model;
  std::vector<mjtNum> geom_xpos, geom_xmat;
  std::unique_ptr<mjData, void (*)(mjData*)> data{nullptr, &mj_deleteData};
  std::unique_ptr<sensors::RayCaster> caster;
};

// What a stop's files are made from, copied when the stop ends: the mission goes on meanwhile.
struct StopSnapshot {
  StopRecord stop;
  StopView view;  // what the stop's picture shows of the map so far
};

// The probes of a simulated run: its clock, its ground truth and its attitude sensor, the
// inclinometer's roll and pitch (truth plus a seeded bias and noise); the laser's line time for
// the stage breakdown.
MissionProbes SimProbes(sim::SimRig& rig, std::uint64_t seed) {
  sim::Simulation& sim = rig.sim();
  // One generator and one noise distribution for the whole run (the distribution keeps state
  // between draws): the same seed gives the same readings.
  struct Inclinometer {
    std::mt19937_64 rng;
    std::normal_distribution<double> noise{0.0, kAttitudeSigma_rad};
    Eigen::Vector2d bias = Eigen::Vector2d::Zero();
  };
  auto sensor = std::make_shared<Inclinometer>();
  sensor->rng.seed(seed ^ kAttitudeSeedSalt);
  std::normal_distribution<double> attitude_bias(0.0, kAttitudeBiasSigma_rad);
  // Both draws in one expression, as every recorded run made them (which one a compiler makes
  // first is its choice): the same seed keeps giving the same bytes.
  sensor->bias = Eigen::Vector2d(attitude_bias(sensor->rng), attitude_bias(sensor->rng));
  MissionProbes probes;
  probes.now_s = [&sim] { return sim.time_s(); };
  probes.line_time = [&rig] { return rig.scanner().line_time(); };
  probes.true_pose = [&sim] { return sim.T_world_base(); };
  probes.roll_pitch_rad = [&sim, sensor] {
    const Eigen::Matrix3d R = sim.T_world_base().linear();
    const double roll = std::atan2(R(2, 1), R(2, 2));
    const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    return Eigen::Vector2d(roll + sensor->bias.x() + sensor->noise(sensor->rng),
                           pitch + sensor->bias.y() + sensor->noise(sensor->rng));
  };
  return probes;
}

// What the run folder says about a simulated run besides the mission's result; its config.yaml
// is the configuration as used plus the mount error the simulator drew from the seed
// (lms200.mount_error_sigma_deg): truth the pipeline never saw, so a comment, not a setting.
RunContext SimContext(const SimMissionSpec& spec, const RunSettings& settings,
                      const Eigen::Vector3d& start,
                      const std::optional<mapping::GeodeticOrigin>& origin,
                      const sim::SimRig& rig) {
  RunContext context;
  context.world = spec.world_name.empty() ? spec.world_file.stem().string() : spec.world_name;
  context.world_file = spec.world_file.string();
  context.robot = spec.config.rig.robot.model == sim::P3Model::kP3AT ? "p3at" : "p3dx";
  context.seed = spec.config.seed;
  context.start = start;
  context.goal = settings.mission.goal_m;
  context.via = settings.mission.via_m;
  context.geodetic_origin = origin;
  context.mount_error_rpy_rad = rig.mount_error_rpy_rad();
  const Eigen::Vector3d mount_error_deg = rig.mount_error_rpy_rad() * 180.0 / kPi;
  std::ostringstream truth;
  truth.precision(6);
  truth << "# sim truth: scanner mount error drawn for this run, roll/pitch/yaw [deg]: ["
        << mount_error_deg.x() << ", " << mount_error_deg.y() << ", " << mount_error_deg.z()
        << "]\n";
  context.config_yaml = AppConfigToYaml(spec.config) + RunSettingsToYaml(settings) + truth.str();
  context.planner = MissionPlanner(settings.mission);
  context.layers = settings.mission.layers;
  context.loop_closure = settings.mission.registration.loop_closure.enabled;
  return context;
}

}  // namespace

SimMissionSpec LoadSimMissionSpec(const std::optional<std::string>& config_path,
                                  std::optional<std::uint64_t> seed,
                                  std::optional<sim::P3Model> robot) {
  SimMissionSpec spec;
  spec.config = LoadAppConfig(config_path);
  if (seed) {
    spec.config.seed = *seed;
    spec.config.sensors.lms200.seed = spec.config.rig.lms200.seed = spec.config.rig.odometry.seed =
        spec.config.rig.imu.seed = *seed;
  }
  if (robot) spec.config.rig.robot.model = *robot;
  const std::string text = config_path ? ReadBinaryFile(*config_path) : std::string();
  spec.settings = ParseRunSettings(text, spec.config.source, spec.config.rig.robot.model);
  return spec;
}

worlds::WorldMetadata LoadWorldMetadata(const std::filesystem::path& world_file) {
  char error[1000] = "";
  mjModel* model = mj_loadXML(world_file.string().c_str(), nullptr, error, sizeof(error));
  if (model == nullptr)
    throw std::runtime_error("cannot load world '" + world_file.string() + "': " + error);
  try {
    const worlds::WorldMetadata meta = worlds::ReadWorldMetadata(model);
    mj_deleteModel(model);
    return meta;
  } catch (...) {
    mj_deleteModel(model);
    throw;
  }
}

SimMissionOutcome RunSimMission(const SimMissionSpec& spec, const std::filesystem::path& out,
                                const SimMissionObserver& observer) {
  const sensors::Stopwatch run_clock(sensors::CpuOf::kProcess);  // the side thread's too
  StageTimes stages;  // the run's own; the loop's come with its result
  if (spec.world_file.empty()) throw std::invalid_argument("mission: no world file given");
  const worlds::WorldMetadata meta = LoadWorldMetadata(spec.world_file);
  Eigen::Vector3d start;
  std::vector<Eigen::Vector2d> via;
  Eigen::Vector2d goal;
  ResolveEnds(spec, meta, start, via, goal);
  const std::string world_stem = spec.world_file.stem().string();

  RunFolder folder(out);
  sim::SimRig rig(spec.world_file.string(), spec.config.rig);
  Result<Eigen::Isometry3d> placed = rig.PlaceRobot(start.x(), start.y(), start.z());
  if (!placed) throw std::runtime_error("cannot place the robot: " + placed.error().message);

  RunSettings settings = spec.settings;
  MissionConfig& mission = settings.mission;
  mission.goal_m = goal;
  mission.via_m = via;
  mission.mount = spec.config.rig.robot.mount;
  mission.beam_divergence_rad = spec.config.rig.lms200.beam_divergence_deg * M_PI / 180.0;
  const worlds::Bounds2d& b = meta.bounds;
  mission.map_area = mapping::GridGeometry::Covering(Eigen::Vector2d(b.x_min_m, b.y_min_m),
                                                     Eigen::Vector2d(b.x_max_m, b.y_max_m),
                                                     settings.cell_m, kMapMargin_m);
  std::optional<mapping::GeodeticOrigin> origin;
  if (meta.geodetic_origin) {
    origin = mapping::GeodeticOrigin{meta.geodetic_origin->latitude_deg,
                                     meta.geodetic_origin->longitude_deg,
                                     meta.geodetic_origin->height_m};
  }
  // The true surface: kept from an earlier run of the same world and placement, or ray cast.
  std::filesystem::path truth_file;
  std::optional<mapping::ElevationMap> cached_truth;
  std::string truth_source = "true surface on " + std::to_string(mission.map_area.size_x) + " x " +
                             std::to_string(mission.map_area.size_y) + " cells, beside the mission";
  if (!spec.truth_cache_dir.empty()) {
    const sensors::ScopedTime timing(stages[Stage::kGroundTruth]);
    truth_file = TruthCacheFile(spec.truth_cache_dir, rig.sim().model(), rig.sim().data(),
                                TruthCasterOptions(), mission.map_area);
    Result<std::optional<mapping::ElevationMap>> loaded =
        LoadCachedTruth(truth_file, mission.map_area);
    if (!loaded) {
      truth_source += " (the cached one is unusable: " + loaded.error().message + ")";
    } else if (*loaded) {
      cached_truth = std::move(**loaded);
      truth_source = "true surface from " + truth_file.string();
    }
  }
  if (observer.on_setup) {
    observer.on_setup("ground truth of " +
                      (spec.world_name.empty() ? world_stem : spec.world_name) + ": " +
                      truth_source);
  }
  // The ground truth and each stop's files are made on a thread beside the mission (their CPU
  // time is theirs, their wall time what the run waits for them at the end).
  std::shared_ptr<TruthScene> truth_scene;
  if (!cached_truth) {
    const sensors::ScopedTime timing(stages[Stage::kGroundTruth]);
    truth_scene = std::make_shared<TruthScene>(rig);
  }
  std::optional<Truth> truth;
  std::string truth_cache_error;              // a cache that could not be written: said at the end
  double truth_cpu_s = 0, outputs_cpu_s = 0;  // the jobs' own, read once they are done
  BackgroundJobs side;  // declared after what its jobs use: it ends first
  side.Post([&, truth_scene] {
    const double cpu0 = sensors::ThreadCpuSeconds();
    if (cached_truth) {
      truth = TruthOf(*cached_truth, mission, start.head<2>());
    } else {
      truth_scene->BuildCaster();
      const mapping::ElevationMap map =
          mapping::ComputeTrueElevationMap(*truth_scene->caster, mission.map_area);
      truth = TruthOf(map, mission, start.head<2>());
      if (!truth_file.empty()) {
        if (Result<void> stored = StoreCachedTruth(map, truth_file); !stored) {
          truth_cache_error = stored.error().message;
        }
      }
    }
    truth_cpu_s = sensors::ThreadCpuSeconds() - cpu0;
  });

  sim::Simulation& sim = rig.sim();
  MissionObserver mission_observer;
  mission_observer.on_stop = [&](const StopRecord& stop, const MissionResult& so_far) {
    const sensors::ScopedTime timing(stages[Stage::kOutputs]);
    auto snapshot = std::make_shared<StopSnapshot>();
    snapshot->stop = stop;
    snapshot->view = ViewOfStop(so_far, stop.plan);
    side.Post([&, snapshot] {
      const double cpu0 = sensors::ThreadCpuSeconds();
      WriteStopOutputs(folder, snapshot->stop, snapshot->view, origin, world_stem);
      outputs_cpu_s += sensors::ThreadCpuSeconds() - cpu0;
    });
  };
  if (observer.on_progress) {
    mission_observer.on_progress = [&](const std::string& text) {
      observer.on_progress(text, sim.time_s());
    };
  }
  SimMissionOutcome run;
  run.result = RunMission(rig, rig.base(), *placed, mission, SimProbes(rig, spec.config.seed),
                          mission_observer);
  {
    const sensors::ScopedTime timing(stages[Stage::kOutputs]);
    side.Wait();
  }
  if (!truth_cache_error.empty() && observer.on_setup) {
    observer.on_setup("the ground truth was not kept for later runs: " + truth_cache_error);
  }
  stages[Stage::kGroundTruth].cpu_s += truth_cpu_s;
  stages[Stage::kOutputs].cpu_s += outputs_cpu_s;
  run.context = SimContext(spec, settings, start, origin, rig);
  const FinalMap final_map = [&] {
    const sensors::ScopedTime timing(stages[Stage::kOutputs]);
    return MakeFinalMap(run.context, run.result);
  }();
  // ScoreRun's grids: the final map's layers with the mission's own planner (RunContext's adds
  // the follower's safety margin to the robot's width), as the truth's.
  planning::TraversabilityGrid scored;
  {
    const sensors::ScopedTime timing(stages[Stage::kScoring]);
    scored = planning::BuildTraversability(final_map.layers, mission.planner);
    run.score =
        ScoreRun(run.result, truth->grid, scored, start.head<2>(), goal, mission.algorithm, via);
  }
  {
    const sensors::ScopedTime timing(stages[Stage::kOutputs]);
    const TruthMaps truth_maps{truth->layers, truth->grid, scored, &truth->optimum,
                               run.score.forbidden_crossed_at};
    WriteFinalData(folder, run.context, run.result, final_map, &truth_maps);
  }
  // The run's time up to its summary, which holds it (metrics.json, report.html).
  const sensors::Elapsed run_time = run_clock.Read();
  run.context.wall_time_s = run_time.wall_s;
  stages += run.result.stages;
  run.context.stages = StageBreakdown{stages, run_time};
  WriteSummary(folder, run.context, run.result, run.score, final_map);
  folder.Commit();
  run.metrics = RunMetrics(run.context, run.result, run.score);
  run.safety = ReadOutcome(run.metrics).safety;
  run.folder = folder.final_path();
  return run;
}

}  // namespace pitchlab::mission
