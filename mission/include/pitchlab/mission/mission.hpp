#pragma once
// The closed-loop stop-scan-go mission (DESIGN.md pipeline step 6): stop, scan, register against
// the map (odometry as prior), update the elevation map, plan to the goal, drive a prefix of the
// path, repeat. Written against the seam interfaces only, so simulation and hardware share it.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pitchlab/mission/height_fit.hpp"
#include "pitchlab/mission/path_follower.hpp"
#include "pitchlab/mission/stage_times.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/mapping/map_builder.hpp"
#include "pitchlab/mapping/mount_from_floor.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sensors/mobile_base.hpp"
#include "pitchlab/sensors/pitching_scanner.hpp"

namespace pitchlab::mission {

struct MissionConfig {
  Eigen::Vector2d goal_m = Eigen::Vector2d::Zero();  ///< goal in the world frame [m]
  /// Waypoints driven through, in order, before the goal (world frame): each is reached like the
  /// goal, within goal_tolerance_m, and then the robot plans to the next [m].
  std::vector<Eigen::Vector2d> via_m;
  double goal_tolerance_m = 0.5;  ///< success within this of the goal (and of a waypoint) [m]
  double drive_per_stop_m = 4.0;                     ///< path length driven between two scans [m]
  int max_stops = 40;                                ///< scans at most [1]
  double time_budget_s = 1800.0;  ///< mission time at most (simulated or real) [s]
  double max_tilt_deg = 30.0;     ///< beyond this the robot is tipping over [deg]
  /// Beyond this tilt the robot backs off and marks the ground ahead as too steep, then plans
  /// again: the loaded P3-AT (laser 0.45 m up, batteries low) pitches over forward at 31 deg
  /// standing, less while braking downhill [deg].
  double caution_tilt_deg = 24.0;
  /// A drive that ends tilted more than this backs off before the robot stops to scan: sweeping
  /// the laser down shifts its weight forward, and the wheel hold creeps on steep ground [deg].
  double scan_tilt_deg = 17.0;
  /// Beyond this tilt the follower slows to slope_speed_mps (same curvature) [deg].
  double slope_tilt_deg = 10.0;
  double slope_speed_mps = 0.2;   ///< cruise speed on slopes [m/s]
  double stuck_timeout_s = 8.0;   ///< no progress while commanded for this long: stuck [s]
  double control_period_s = 0.1;  ///< path follower rate [s]
  /// Returns farther than this from the laser stay out of the elevation map the robot plans on
  /// (the merged cloud and registration keep them). Far ground is seen at a grazing angle on
  /// sparse lines, and a scan's attitude or registration error of 0.2-0.3 deg shifts it by
  /// centimetres a cell: overlapping far views of two scans read as steps and slopes that cut
  /// every way (terrain). The robot rescans every drive_per_stop_m, well inside this [m].
  double map_range_m = 10.0;
  /// Set each scan's lines right by the floor they crossed (mapping::RectifyLinePitch, about the
  /// mount's pitch axis) before registration and mapping: for a pitch unit whose reported pitch is
  /// off per line, as the real 3DTK rig's is (0.9 deg RMS; sensors::PitchUnitConfig's
  /// line_pitch_error_deg simulates one). The elevation map then takes returns only within the
  /// radius the lines were set right by (LinePitchConfig's ground radius, 4 m): the floor beyond
  /// is met by lines whose floor lay farther, which keep their error. Ground that is not level
  /// within 4 m (terrain) is levelled with the lines: this is for level floors. Off by default:
  /// a unit that reports its true pitch gains nothing, and every figure so far was measured
  /// without it.
  bool set_lines_right = false;
  /// Calibrate the laser's mount by the floor the robot stands on at its first stop
  /// (mapping::CalibrateMountFromFloor): the roll, pitch and yaw the scan plane is off its
  /// nominal mount, and every scan re-assembled on the mount found. For a rig whose mount was
  /// never calibrated (the measured LMS200 model draws 0.25 deg per axis); the robot must start
  /// on ground planar within 4 m of it. On by default: with the measured LMS200 model it took
  /// terrain seeds 1..20 from 16 to 20 of 20 (benchmarks/README.md); a floor tilted more than
  /// 2 deg is left alone, so a true mount loses nothing.
  bool calibrate_mount = true;
  /// How far odometry may be off the motion since the last merged scan (plus that scan's own
  /// registration error), the registration prior's error bound (mapping::GuessUncertainty): it
  /// narrows the geometric constraint and the search around the guess to itself, and lets
  /// odometry supply what the scene leaves free. odometry_error_m + odometry_error_per_m x the
  /// distance driven [m] ... (terrain runs, the worst ground: 0.16 m median, 0.56 m p95 over ~3 m;
  /// office: 0.12 m at most)
  double odometry_error_m = 0.3;
  double odometry_error_per_m = 0.3;  ///< ... [m/m]
  /// ... except on level ground, where wheels do not slip: distance driven with the attitude
  /// sensor reading at most 3 deg counts at this rate instead [m/m]. Level drives of the
  /// office and urban runs (90 drives of 0.3-4 m, seeds 1..6): 0.7 % median, 11 % p95 (short
  /// drives after a turn on the spot, whose slide the constant term holds), at most 0.11 m; the
  /// real 3DTK corridor pair's odometry: 1.7 cm over 1.57 m (1.1 %). Without an attitude sensor
  /// no ground is known level. The loose terrain rate let ICP slide a corridor scan 0.84 m (2 m
  /// with a grid search) along the axis to where it overlapped the map more, and call it success.
  double odometry_error_level_per_m = 0.05;
  /// ... plus odometry_error_per_rad x the angle turned off level ground [m/rad]: a skid-steer
  /// base slides as it turns on a slope, wheels skidding sideways while gravity pulls. Terrain
  /// seeds 1..20 and 101..120 (770 drives between merged stops): odometry's error against this
  /// bound grew with the turn (p99 0.40 of the bound for drives turning under 60 deg, 1.28 over
  /// 200 deg); the four drives that broke it turned 108-270 deg on 9-15 deg slopes, and one
  /// (seed 14, 0.63 m off after 242 deg) had its right registration refused, merged nothing for
  /// three stops and ended walled in by their scans at odometry's poses. 0.032 m/rad would have
  /// held all four; with 0.05 the largest reaches 0.89 of its bound.
  double odometry_error_per_rad = 0.05;
  /// ... and odometry_error_deg + odometry_error_dps x the time elapsed [deg]: the gyro's drift
  /// (0.017 deg/s p95) and the roll/pitch errors of the attitude sensor and the last registration.
  /// Odometry's rotation off the truth's between merged stops, terrain and gully seeds 1..20 (453
  /// steps 18-47 s apart, the heading from the gyro, roll and pitch from the attitude sensor): at
  /// most 0.60 / 0.75 deg, 0.55 / 0.66 deg p99; this bound is 2.5 times the largest. (It was 5 deg,
  /// from the wheel-heading odometry's 4.5 deg p99 of an early version, and let gully scans merge
  /// 4 deg turned.) A base without a gyro needs more: skid-steer wheels misjudge turns by ~10 %.
  double odometry_error_deg = 1.0;
  double odometry_error_dps = 0.03;  ///< ... [deg/s]
  /// How far a registration may tilt a scan from the attitude sensor's roll and pitch, averaged
  /// at standstill (mapping::MeasuredTilt); beyond, ICP holds them. Two stops' averages of the
  /// simulated inclinometer differ by 0.06 deg (1 sigma) and share its bias; free ICP tilted
  /// office scans 0.5-2.6 deg where it fitted too little of the map. Unused without an attitude
  /// sensor [deg].
  double tilt_tolerance_deg = 0.5;
  /// Clearance kept beyond the robot's half width when planning, for tracking error [m].
  double safety_margin_m = 0.08;
  /// The robot stops this far before the first unobserved cell of its plan, turns to face it and
  /// scans: it never drives blind into ground its laser has not seen [m].
  double unknown_margin_m = 0.5;
  /// How far the robot may drift off its plan per metre driven since its last scan [m/m]. The
  /// follower steers by odometry, and a skid-steer base slides on slopes where its wheels see
  /// nothing of it: the simulated P3-AT's odometry drifted 0.05 m per metre driven (median), 0.19
  /// (9 drives in 10) and up to 0.76 over 631 drives of terrain seeds 1..20 and 101..120
  /// (benchmarks/README.md, session 45), and the robot's footprint came over hazards its plan had
  /// kept off, up to 0.6 m from the plan where its estimate stayed within 0.1 m. A drive ends
  /// where the plan comes closer to a mapped hazard than the footprint's reach plus this times
  /// the distance driven off the floor to it (PlanClearStretch: a floor's drift, about 1 %, is
  /// within safety_margin_m), but runs a metre at least; the next scan puts the robot back on its
  /// map. 0 turns it off.
  double drift_per_m = 0.2;
  PurePursuitConfig follower;
  planning::PlannerConfig planner;
  mapping::LayerConfig layers;  ///< how the elevation map's layers are derived for planning
  planning::Algorithm algorithm = planning::Algorithm::kAStar;
  mapping::MapConfig registration;  ///< scan-to-map merging
  mapping::GridGeometry map_area;   ///< the elevation map's grid, world frame
  sensors::MountConfig mount;       ///< for the laser origin of clearance rays
  /// The laser's full beam width (Lms200Config::beam_divergence_deg, 0.25 deg): a return on a
  /// steep surface whose footprint spreads over more than a map cell along the beam stays out of
  /// the elevation map (sensors/grazing_returns.hpp) [rad].
  double beam_divergence_rad = 0.25 * 3.14159265358979323846 / 180.0;
};

/// What the loop reads besides the seam interfaces. `now_s` is required; the others may be empty.
struct MissionProbes {
  std::function<double()> now_s;  ///< the run's clock (simulated or steady) [s]
  /// Attitude sensor (an inclinometer, or an IMU's gravity vector): roll and pitch of base_link
  /// (x, y of the ZYX Euler angles) [rad]. It sets the attitude of the odometry pose, which is the
  /// registration prior and the pose a scan goes in at when registration fails; the robot slows on
  /// slopes, backs off from a tilt and knows it is tipping over by it. May be empty.
  std::function<Eigen::Vector2d()> roll_pitch_rad;
  /// Ground truth (simulation only): scoring, never steering.
  std::function<Eigen::Isometry3d()> true_pose;
  /// True once the run should stop now (Ctrl-C on hardware); polled wherever the budget is.
  std::function<bool()> interrupted;
  /// The time the scanner has spent making lines so far (simulation only: casting rays), which
  /// splits a scan's time into ray casting and the physics stepped around it. May be empty: a
  /// scan's whole time is then kPhysicsStanding.
  std::function<sensors::Elapsed()> line_time;
};

/// The planner as the mission runs it: the robot's width grown by the safety margin each side.
planning::PlannerConfig MissionPlanner(const MissionConfig& config);

/// One stop of the mission, as it happened.
struct StopRecord {
  int index = 0;
  double stamp_s = 0;        ///< when the scan started [s]
  double driven_m = 0;       ///< odometry's distance since the stop before [m]
  double turned_rad = 0;     ///< odometry's yaw turned off level ground since then [rad]
  sensors::Scan3D scan;      ///< points in base_link
  mapping::MergeStep merge;  ///< registration against the map
  /// The registration prior's error bound: how far odometry may be off since the last merged scan
  /// (odometry_error_*; unused at the first stop, which has no prior).
  mapping::GuessUncertainty prior_bound;
  Eigen::Isometry3d T_world_base_odom = Eigen::Isometry3d::Identity();  ///< odometry's pose
  Eigen::Isometry3d T_world_base = Eigen::Isometry3d::Identity();       ///< the estimate used
  /// The pose after the run's last pose-graph optimisation (registration.loop_closure on): a
  /// registered stop's node; a stop that did not register moves with the last registered stop
  /// before it. Equals T_world_base with loop closure off. Set when the mission ends.
  Eigen::Isometry3d T_world_base_final = Eigen::Isometry3d::Identity();
  std::optional<Eigen::Isometry3d> T_world_base_true;                   ///< simulation only
  std::optional<planning::Path> plan;  ///< to the goal, world frame
  std::string plan_error;              ///< why there was no plan
  std::string plan_note;               ///< how the plan was found, when not the plain way
  /// Recovery: planned through cells taken for hazards (inferred drops, hazards around a goal
  /// seen from afar) as unknown, to look from closer (plan_note says which).
  bool look_closer = false;
  double plan_to_doubt_m = 0;  ///< with look_closer: plan length before the first such cell [m]
  double plan_known_m = 0;     ///< length of the plan over observed cells [m]
  /// Length of the plan before its hazards come within the robot's drift (MissionConfig's
  /// drift_per_m, PlanClearStretch), looked for up to a stop's drive (drive_per_stop_m) [m].
  double plan_clear_m = 0;
  bool plan_seen_to_end = false;  ///< every cell of the plan observed: plan_known_m is its length
  int felt_hazards = 0;        ///< places marked too steep by the tilt so far
  bool elevation_from_odometry = false;  ///< registration failed: the scan entered the elevation
                                         ///< map at the odometry pose
  /// With elevation_from_odometry: the height that pose took from the map's ground
  /// (FitHeightOffset), when the scan overlapped enough of it.
  std::optional<HeightOffset> height_fit;
  /// With elevation_from_odometry: the map's unknown cells the scan filled; it leaves the cells
  /// the map has already seen as they are [1].
  std::size_t elevation_cells_filled = 0;
  /// With MissionConfig::set_lines_right: what setting the scan's lines right did.
  std::optional<mapping::LinePitch> line_pitch;
  /// What this stop heads for: via_m[target] while target < via_m.size(), else the goal [1].
  std::size_t target = 0;
  double distance_to_goal_m = 0;  ///< from the estimate to the target it heads for [m]
};

/// A pose of the robot while driving (sampled every control period).
struct TrajectorySample {
  double stamp_s = 0;
  Eigen::Isometry3d T_world_base_est = Eigen::Isometry3d::Identity();
  std::optional<Eigen::Isometry3d> T_world_base_true;
};

struct MissionResult {
  bool success = false;
  std::string reason;  ///< "goal reached" or why it stopped
  std::vector<StopRecord> stops;
  std::vector<TrajectorySample> trajectory;
  mapping::ElevationMap elevation;      ///< estimated, world frame
  mapping::PointCloud map_cloud_world;  ///< merged scans, world frame
  double start_s = 0, end_s = 0;        ///< clock at start and end [s]
  double odometry_distance_m = 0;       ///< driven, by odometry [m]
  double max_tilt_rad = 0;              ///< largest tilt seen by the attitude probe [rad]
  /// Time spent in the loop's stages (stage_times.hpp); those of a whole run (ground truth,
  /// outputs, scoring) are the caller's to add.
  StageTimes stages;
  std::size_t waypoints_reached = 0;    ///< of MissionConfig::via_m, in order [1]
  /// With registration.loop_closure on: MapBuilder's counts over the run and the loop edges it
  /// accepted (scan indices are MergeStep::scan_index); zero and empty when off.
  mapping::LoopClosureCounts loop_counts;
  std::vector<mapping::LoopClosure> loop_closures;
  /// With calibrate_mount: the mount the first scan's floor gave, or why there is none.
  std::optional<mapping::MountFromFloor> mount_calibration;
  std::string mount_calibration_note;
  /// When the run failed: the last stop that planned (StopRecord::index; -1 none) and the grid it
  /// planned on, as the mission had it (its refuted gaps, a recovery's relaxed cells), which the
  /// run's traversability.png, rebuilt from the final map, does not show. Empty on success.
  int last_plan_stop = -1;
  planning::TraversabilityGrid last_plan_grid;
};

/// Called after each stop is planned (for output as it happens) and with progress text.
struct MissionObserver {
  std::function<void(const StopRecord&, const MissionResult&)> on_stop;
  std::function<void(const std::string&)> on_progress;
};

/// Runs the mission from the robot's current pose `T_world_start` (known at start: the map frame
/// is the first scan's base_link placed there). Device errors end the mission with a reason; bad
/// configuration throws std::invalid_argument.
MissionResult RunMission(sensors::ScanSource& source, sensors::MobileBase& base,
                         const Eigen::Isometry3d& T_world_start, const MissionConfig& config,
                         const MissionProbes& probes, const MissionObserver& observer = {});

}  // namespace pitchlab::mission
