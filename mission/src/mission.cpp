#include "pitchlab/mission/mission.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <stdexcept>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mission/elevation_scan.hpp"
#include "pitchlab/mission/slope_guard.hpp"
#include "pitchlab/sensors/number_text.hpp"

#include "back_trail.hpp"
#include "drive_length.hpp"
#include "line_gaps.hpp"
#include "optimised_elevation.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinProgress_m = 0.05;   // less than this over stuck_timeout_s is no progress
constexpr double kMinTurnProgress_rad = 0.1;  // ... and less turn than this
constexpr double kStopTime_s = 0.5;       // braking before a scan
constexpr double kEscapeRadius_m = 1.0;   // how far a start inside a hazard margin looks out
constexpr double kGoalApproach_m = 2.0;   // a blocked goal farther than this: approach it
constexpr double kFarDoubt_m = 6.0;       // beyond this a hazard may be a sparse view (recovery)
constexpr double kHeadingTolerance_rad = 3.0 * kPi / 180;  // turning in place ends within this
constexpr double kTurnGain_per_s = 2.0;                    // yaw rate per radian of heading error
// The laser sees 180 deg ahead (the LMS200's field of view): a path within this of the heading
// lies in the next scan with 30 deg to spare, so the robot does not turn on the spot to face it.
// Such a turn buys little, and on a slope it slides a skid-steer base downhill (path_follower.hpp,
// `reverse`): terrain seeds 11 and 234 turned 55 and 47 deg at the end of a drive and slid 0.27 m
// into a crack's edge.
constexpr double kInView_rad = 60.0 * kPi / 180;
constexpr double kBackOff_m = 0.6;   // reverse this far from a tilt beyond caution
constexpr double kBackOffSpeed_mps = 0.2;
constexpr double kBackOffTiltRise_rad = 4.0 * kPi / 180;  // reversing tilts it this much more: stop
constexpr double kFeltAhead_m = 0.2;           // the tilting ground: under the front axle and on
constexpr double kMaxCentripetal_mps2 = 0.15;  // v * omega while following a path
// Beyond the path's own grade, a tilt is something the robot ran onto (a crack's edge, a rock).
// Rugged ground rocks the loaded P3-AT 12-16 deg over paths graded near 5 deg; at 8 deg those
// rocks became 1.4 m obstacle discs that sealed the rugged band before the terrain goal (terrain
// seeds 1..40: 32/40 runs at 8 deg, 36/40 at 12 deg, highest tilt 29.8 vs 27.3 deg).
constexpr double kUnexpectedTilt_rad = 12.0 * kPi / 180;
constexpr double kSlopeYawRate_rps = 0.3;  // skid-steer turns on a slope at most this fast
constexpr double kSlopeLookahead_m = 1.0;  // slow down this far before a slope (braking distance)
// Ground the attitude sensor reads at most this tilted is level for the odometry's error bound
// (odometry_error_level_per_m): the office and urban floors read 0.1 deg at most, a wheelchair
// ramp (1:12) 4.8 deg; terrain drives that stayed within 5 deg slipped 5.7 % at most (p95).
constexpr double kLevelTilt_rad = 3.0 * kPi / 180;

double Yaw(const Eigen::Isometry3d& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

// Odometry increment since `ref` applied to the pose estimated at `ref`, in the horizontal plane:
// x, y and yaw move by the odometry's planar motion; z keeps the estimate's, and so do roll and
// pitch unless an attitude sensor measured them (wheel odometry says nothing about them, and
// composing a planar turn onto a tilted frame would leak the tilt into the heading).
Eigen::Isometry3d Propagate(const Eigen::Isometry3d& T_world_base_at_ref,
                            const sensors::Odometry& ref, const sensors::Odometry& now,
                            const std::optional<Eigen::Vector2d>& roll_pitch_rad) {
  const Eigen::Matrix3d R = T_world_base_at_ref.linear();
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  const double pitch =
      roll_pitch_rad ? roll_pitch_rad->y() : std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = roll_pitch_rad ? roll_pitch_rad->x() : std::atan2(R(2, 1), R(2, 2));
  const double c = std::cos(ref.yaw_rad), s = std::sin(ref.yaw_rad);
  const double dx = now.x_m - ref.x_m, dy = now.y_m - ref.y_m;
  const Eigen::Vector3d step_base(c * dx + s * dy, -s * dx + c * dy, 0);  // in ref's frame
  const double new_yaw = yaw + std::remainder(now.yaw_rad - ref.yaw_rad, 2.0 * kPi);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(new_yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  // The wheels roll along base_link's tilted x-y plane: a drive up a slope climbs. Rotated by the
  // attitude between the two readings (the wheel odometry's frame is the ref's, turned by yaw).
  const Eigen::Matrix3d R_mid = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
  T.translation() = T_world_base_at_ref.translation() + R_mid * step_base;
  return T;
}

// The first `length_m` of the path's (x, y) polyline.
std::vector<Eigen::Vector2d> PathPrefix(const planning::Path& path, double length_m) {
  std::vector<Eigen::Vector2d> out;
  double arc = 0;
  for (const planning::Waypoint& w : path.waypoints) {
    const Eigen::Vector2d p(w.x_m, w.y_m);
    if (!out.empty()) {
      const double seg = (p - out.back()).norm();
      if (arc + seg > length_m) {
        out.push_back(out.back() + (p - out.back()) * ((length_m - arc) / seg));
        break;
      }
      arc += seg;
    }
    out.push_back(p);
  }
  return out;
}

// Inserts the scan (map frame, rays from `laser`) into the cells of `map` that have no point yet;
// the others stay as they are, clearance included. Returns the view and the cells it filled.
std::pair<mapping::ElevationMap, std::size_t> FillUnknown(
    mapping::ElevationMap& map, const std::vector<Eigen::Vector3f>& points,
    const Eigen::Vector3f& laser) {
  mapping::ElevationMap view = ViewOver(map.geometry(), points, laser);
  const mapping::GridGeometry& g = map.geometry();
  const mapping::GridGeometry& local = view.geometry();
  const int i0 = static_cast<int>(std::lround((local.x_min_m - g.x_min_m) / g.cell_m));
  const int j0 = static_cast<int>(std::lround((local.y_min_m - g.y_min_m) / g.cell_m));
  std::size_t filled = 0;
  for (int j = 0; j < local.size_y; ++j) {
    for (int i = 0; i < local.size_x; ++i) {
      filled += view.at({i, j}).known() && !map.at({i + i0, j + j0}).known();
    }
  }
  const auto merged = map.Merge(view, mapping::ElevationMap::MergeCells::kUnknown);
  if (!merged) throw std::logic_error("mission: " + merged.error().message);  // same alignment
  return {std::move(view), filled};
}

// The scan-to-map settings with the laser where the mount puts it (its mirror at zero pitch).
mapping::MapConfig WithSensor(mapping::MapConfig map, const sensors::MountConfig& mount) {
  map.sensor_base = mount.BaseToLaser(0.0).translation().cast<float>();
  return map;
}

class Mission {
 public:
  Mission(sensors::ScanSource& source, sensors::MobileBase& base, const MissionConfig& config,
          const MissionProbes& probes, const MissionObserver& observer)
      : source_(source),
        base_(base),
        config_(config),
        probes_(probes),
        observer_(observer),
        builder_(WithSensor(config.registration, config.mount)) {}

  MissionResult Run(const Eigen::Isometry3d& T_world_start);

 private:
  bool Stop(int k);  // false: the mission ends (result_.reason says why)
  // Back where the first scan was taken: turn to where it looked and scan once more as stop k
  // (ClosingLook says why).
  void ClosingLook(int k);
  // Inserts the scan (within map_range_m) at stop.T_world_base; at an odometry pose (registration
  // failed) the pose's height is first taken from the map's ground (FitHeightOffset), and the scan
  // fills only the cells the map has not seen (FillUnknown).
  void UpdateElevation(StopRecord& stop);
  // With calibrate_mount: at stop 0 the mount the floor the robot stands on says the laser is
  // on, then every scan re-assembled on it.
  void CalibrateMount(int k, sensors::Scan3D& scan);
  // Loop closure on: a registered stop's scan joins the per-scan map at the graph's pose, and
  // when this merge's optimisation moved poses every kept scan follows.
  void UpdateOptimisedElevation(const StopRecord& stop, const ElevationScan& scan);
  // Every stop's StopRecord::T_world_base_final, from the pose graph's last optimum.
  void SetFinalPoses();
  void Plan(StopRecord& stop);
  // planning::BuildTraversabilityInto `grid` (one of the members below, reused every stop).
  void Traversability(const mapping::ElevationLayers& layers,
                      const planning::PlannerConfig& planner, planning::TraversabilityGrid& grid) {
    const sensors::ScopedTime timing(result_.stages[Stage::kTraversability]);
    planning::BuildTraversabilityInto(layers, planner, grid);
  }
  tl::expected<planning::Path, planning::NoPath> PlanOn(const planning::TraversabilityGrid& grid,
                                                        const Eigen::Vector2d& here);
  // The base's Drive, its time counted as kPhysicsDriving.
  Result<sensors::Odometry> DriveBase(double v_mps, double omega_rps, double duration_s) {
    const sensors::ScopedTime timing(result_.stages[Stage::kPhysicsDriving]);
    return base_.Drive(v_mps, omega_rps, duration_s);
  }
  // The scan source's Acquire, its time split into kRayCasting (the lines, by probes_.line_time)
  // and kPhysicsStanding (the rest).
  Result<sensors::Scan3D> AcquireScan();
  bool Drive(const StopRecord& stop);
  bool Follow(const planning::Path& path, double length_m);
  // Marks the ground it was driving onto as felt (`obstacle`: the tilt came from something it ran
  // onto), then backs off. `reversing`: it was driving backwards. false: the mission ends.
  bool BackOff(const sensors::Odometry& odo, double tilt_rad, bool obstacle,
               bool reversing = false);
  // Drives kBackOff_m back the way it came (or as far as it goes): in reverse, or `forwards`
  // when it came in reverse. false: the mission ends.
  bool DriveBack(const sensors::Odometry& odo, bool forwards = false);
  std::optional<Eigen::Vector2d> Attitude() const {
    if (!probes_.roll_pitch_rad) return std::nullopt;
    return probes_.roll_pitch_rad();
  }
  // The attitude standing still: the mean of kStillReads reads, whose noise averages out (what
  // is left is the sensor's bias, the same for every stop: the map is consistently tilted by it,
  // the scans agree with each other).
  std::optional<Eigen::Vector2d> StillAttitude() const {
    constexpr int kStillReads = 25;
    if (!probes_.roll_pitch_rad) return std::nullopt;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int i = 0; i < kStillReads; ++i) sum += probes_.roll_pitch_rad();
    return sum / kStillReads;
  }
  // Angle of base_link's z from vertical [rad]; 0 without an attitude sensor.
  double Tilt() const {
    const std::optional<Eigen::Vector2d> a = Attitude();
    return a ? std::acos(std::clamp(std::cos(a->x()) * std::cos(a->y()), -1.0, 1.0)) : 0.0;
  }
  bool TurnTo(double yaw_rad);
  // Turns to yaw_rad only when that heading lies outside the laser's view (kInView_rad).
  bool FacePath(double yaw_rad);
  bool Rebase();  // the map frame = base_link where the robot is now (before the first scan)
  bool Brake();   // commands a standstill for kStopTime_s; false: the base failed (reason set)
  bool RecordSample(const sensors::Odometry& odo);  // false: tipping over (reason set)
  void Odometer(const sensors::Odometry& from, const sensors::Odometry& to);  // distance driven
  // The yaw turned off level ground (`level`: the attitude sensor read it level).
  void Turned(const sensors::Odometry& from, const sensors::Odometry& to, bool level);
  Eigen::Isometry3d Estimate(const sensors::Odometry& odo) const {
    return Propagate(T_world_base_, odo_ref_, odo, Attitude());
  }
  bool OverBudget();
  // Where the robot heads now: the next waypoint not yet reached, else the goal.
  const Eigen::Vector2d& Target() const {
    return target_ < config_.via_m.size() ? config_.via_m[target_] : config_.goal_m;
  }
  // The distance from `stop`'s estimate to its target, moving on past every waypoint within the
  // goal tolerance. True when the goal itself is reached.
  bool Arrived(StopRecord& stop);
  void Progress(const std::string& text) const {
    if (observer_.on_progress) observer_.on_progress(text);
  }

  sensors::ScanSource& source_;
  sensors::MobileBase& base_;
  const MissionConfig& config_;
  const MissionProbes& probes_;
  const MissionObserver& observer_;
  mapping::MapBuilder builder_;
  // MapBuilder::PrepareNext running beside the drive to the next stop (its own thread, which the
  // stages' stopwatches leave out: its CPU time is the registration's, added by Builder()).
  std::future<void> next_target_;
  double next_target_cpu_s_ = 0;
  // Starts PrepareNext beside whatever the mission does until its next scan is registered.
  void PrepareNextTarget() {
    next_target_ = std::async(std::launch::async, [this] {
      builder_.PrepareNext();
      next_target_cpu_s_ = sensors::ThreadCpuSeconds();
    });
  }
  // The builder, once PrepareNext (if running) is done; it rethrows what that threw.
  mapping::MapBuilder& Builder() {
    if (next_target_.valid()) {
      next_target_.get();
      result_.stages[Stage::kRegistration].cpu_s += next_target_cpu_s_;
    }
    return builder_;
  }
  // With loop closure: the registered scans kept one by one, so the map the robot plans on
  // follows the pose graph's optimised poses (result_.elevation is its combination).
  std::optional<OptimisedElevation> optimised_;
  MissionResult result_;
  Eigen::Isometry3d T_world_map_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_world_base_ = Eigen::Isometry3d::Identity();  // estimate at odo_ref_
  sensors::Odometry odo_ref_;
  std::size_t target_ = 0;  // index into config_.via_m; its size: the goal
  // Odometry distance [m] and clock [s] at the last merged scan: the prior's error bound grows
  // from there.
  double merged_distance_m_ = 0, merged_stamp_s_ = 0;
  double stop_distance_m_ = 0;  // odometry distance at the last stop's scan [m]
  // Of the odometry distance, how much was driven on level ground (kLevelTilt_rad): in total, and
  // at the last merged scan [m].
  double level_distance_m_ = 0, merged_level_m_ = 0;
  // The odometry's yaw turned off level ground [rad]: in total, at the last merged scan and at
  // the last stop's scan.
  double rough_turn_rad_ = 0, merged_rough_turn_rad_ = 0, stop_turn_rad_ = 0;
  // Whether the attitude sensor read the ground level at the last trajectory sample: turning on
  // the spot reads it no more (each read draws the sensor's noise; more reads change the run).
  bool sampled_level_ = false;
  int last_plan_stop_ = -1;             // the last stop that planned, on grid_
  bool last_stop_turned_only_ = false;  // the previous stop only turned to look ahead
  bool closing_look_ = false;           // ClosingLook's stop is under way
  bool backed_off_ = false;             // the last drive ended backing off from a tilt
  BackTrail trail_{2 * kBackOff_m};     // the way back for DriveBack
  std::vector<FeltHazard> felt_;
  // Per map cell, the shortest range a registered scan saw it from [m] (+inf: never so). A
  // recovery doubts only what was never seen from close: doubt measured from where the robot
  // stands made it walk back and forth between two routes, each far from the other's end.
  std::vector<float> nearest_view_m_;
  // Per map cell, what a bridged gap that stayed a gap when seen from close is (line_gaps.hpp).
  std::vector<RefutedGap> refuted_gaps_;
  // With calibrate_mount: the mount the first scan's floor says the laser is on
  // (mapping::CalibrateMountFromFloor), every scan re-assembled on it.
  std::optional<sensors::MountConfig> calibrated_mount_;
  // Plan's working grids, kept between stops so that their buffers (about 80 bytes a cell: a
  // 641 x 641 terrain map's are 33 MB) are allocated once, not at every stop (Plan says which
  // holds what).
  mapping::ElevationLayers layers_, relaxed_layers_;
  planning::TraversabilityGrid grid_, relaxed_grid_;
};

MissionResult Mission::Run(const Eigen::Isometry3d& T_world_start) {
  result_.start_s = probes_.now_s();
  result_.elevation = mapping::ElevationMap(config_.map_area);
  if (config_.registration.loop_closure.enabled) optimised_.emplace(config_.map_area);
  nearest_view_m_.assign(config_.map_area.cell_count(), std::numeric_limits<float>::infinity());
  T_world_map_ = T_world_base_ = T_world_start;
  Result<sensors::Odometry> odo = base_.ReadOdometry();
  if (!odo) {
    result_.reason = "base: " + odo.error().message;
  } else {
    odo_ref_ = *odo;
    result_.reason = "stop limit reached (" + std::to_string(config_.max_stops) + " stops)";
    // The laser sees 180 deg ahead: the first scan should look where the robot will go.
    const Eigen::Vector2d to_goal = Target() - T_world_start.translation().head<2>();
    // The map frame is where the robot stands when it has stopped turning: read at the end of
    // the turn, the base still turned a fraction of a degree as it braked, and every map started
    // 0.2-0.4 deg off in yaw (terrain seeds 1..8, stop 0), 0.1-0.2 m at 30 m.
    if (TurnTo(std::atan2(to_goal.y(), to_goal.x())) && Brake() && Rebase()) {
      int k = 0;
      while (k < config_.max_stops && Stop(k)) ++k;
      if (result_.success) ClosingLook(k + 1);
    }
  }
  result_.end_s = probes_.now_s();
  result_.map_cloud_world = mapping::TransformCloud(Builder().MapCloud(), T_world_map_);
  result_.loop_counts = builder_.loop_closures();
  result_.loop_closures = builder_.accepted_loops();
  SetFinalPoses();
  if (!result_.success && last_plan_stop_ >= 0) {
    result_.last_plan_stop = last_plan_stop_;
    result_.last_plan_grid = std::move(grid_);
  }
  return std::move(result_);
}

// A round trip ends where it began, but its last scans look back the way the robot came: the
// first scans' view (the start room, the corridor ahead) is behind it. An error a corridor's axis
// let in on the way back stays in the last pose (office round trips: 0.1 m along the corridor at
// the arrival), and with loop closure on the loops found are to stops that carried the same error.
// So, back within the goal tolerance of the first scan's place and facing more than kInView_rad
// away from its heading, the robot turns to that heading and scans once more, registered and
// merged like any stop (the stop limit does not count it): scan-to-map registration then meets the
// view the map was started from and re-localises the robot in it, and the loop search finds the
// first scans. A look that fails leaves the arrival as it was.
void Mission::ClosingLook(int k) {
  if (result_.stops.size() < 2) return;
  const StopRecord& first = result_.stops.front();
  const StopRecord& last = result_.stops.back();
  const Eigen::Vector2d start = first.T_world_base.translation().head<2>();
  if ((last.T_world_base.translation().head<2>() - start).norm() > config_.goal_tolerance_m) {
    return;
  }
  const double yaw = Yaw(first.T_world_base);
  if (std::abs(std::remainder(yaw - Yaw(last.T_world_base), 2.0 * kPi)) <= kInView_rad) return;
  const std::string reason = result_.reason;
  const std::size_t stops = result_.stops.size();
  Progress("back at the start: turning to the first scan's heading to close the loop");
  closing_look_ = true;
  if (!(TurnTo(yaw) && Brake() && !Stop(k) && result_.stops.size() > stops)) {
    Progress("the closing look failed (" + result_.reason + "); the run ends at its arrival");
  }
  closing_look_ = false;
  result_.success = true;
  result_.reason = reason;
}

Result<sensors::Scan3D> Mission::AcquireScan() {
  const sensors::Elapsed lines_before =
      probes_.line_time ? probes_.line_time() : sensors::Elapsed{};
  sensors::Stopwatch watch;
  Result<sensors::Scan3D> scan = source_.Acquire();
  const sensors::Elapsed scan_time = watch.Read();
  const sensors::Elapsed lines =
      probes_.line_time ? probes_.line_time() - lines_before : sensors::Elapsed{};
  result_.stages[Stage::kRayCasting] += lines;
  result_.stages[Stage::kPhysicsStanding] += scan_time - lines;
  return scan;
}

bool Mission::OverBudget() {
  if (probes_.interrupted && probes_.interrupted()) {
    result_.reason = "interrupted";
    return true;
  }
  if (probes_.now_s() - result_.start_s <= config_.time_budget_s) return false;
  result_.reason = "time budget of " + NumberText(config_.time_budget_s) + " s spent";
  return true;
}

bool Mission::Stop(int k) {
  if (OverBudget()) return false;
  StopRecord stop;
  stop.index = k;
  Result<sensors::Scan3D> scan = AcquireScan();
  if (!scan && scan.error().code == Error::Code::kTimeout && !OverBudget()) {
    // The scan waits for a standstill in vain where the base creeps: the wheel hold on a slope,
    // or a rigid four-wheeler rocking on two diagonal tyres over a bump. Back off the way it came
    // (marking the ground as too steep only when standing on a slope) and scan once more.
    Progress("scan at stop " + std::to_string(k) + " timed out waiting for a standstill (" +
             scan.error().message + "): backing off to scan again");
    Result<sensors::Odometry> odo = base_.ReadOdometry();
    const bool steep = Tilt() > config_.slope_tilt_deg * kPi / 180;
    if (odo && (steep ? BackOff(*odo, Tilt(), false) : DriveBack(*odo))) scan = AcquireScan();
  }
  if (!scan) {
    result_.reason = "scan at stop " + std::to_string(k) + " failed: " + scan.error().message;
    return false;
  }
  stop.scan = std::move(*scan);
  stop.stamp_s = stop.scan.stamp_s;
  if (config_.calibrate_mount) CalibrateMount(k, stop.scan);
  if (config_.set_lines_right) stop.line_pitch = SetLinesRight(stop.scan, config_.mount);
  if (probes_.true_pose) stop.T_world_base_true = probes_.true_pose();
  Result<sensors::Odometry> odo = base_.ReadOdometry();
  if (!odo) {
    result_.reason = "base: " + odo.error().message;
    return false;
  }
  const std::optional<Eigen::Vector2d> attitude = StillAttitude();
  stop.T_world_base_odom = Propagate(T_world_base_, odo_ref_, *odo, attitude);
  stop.driven_m = result_.odometry_distance_m - stop_distance_m_;
  stop_distance_m_ = result_.odometry_distance_m;
  stop.turned_rad = rough_turn_rad_ - stop_turn_rad_;
  stop_turn_rad_ = rough_turn_rad_;
  // Algorithm 1 against the map, odometry as the prior (none for the scan that starts the map).
  const std::optional<Eigen::Isometry3d> prior =
      k == 0 ? std::nullopt
             : std::optional<Eigen::Isometry3d>(T_world_map_.inverse() * stop.T_world_base_odom);
  const double level_m = level_distance_m_ - merged_level_m_;
  const double rough_m = result_.odometry_distance_m - merged_distance_m_ - level_m;
  stop.prior_bound = {
      config_.odometry_error_m + config_.odometry_error_per_m * rough_m +
          config_.odometry_error_level_per_m * level_m +
          config_.odometry_error_per_rad * (rough_turn_rad_ - merged_rough_turn_rad_),
      config_.odometry_error_deg + config_.odometry_error_dps * (stop.stamp_s - merged_stamp_s_)};
  const mapping::GuessUncertainty& bound = stop.prior_bound;
  // The attitude sensor's roll and pitch at standstill: the prior's tilt is right within
  // tilt_tolerance_deg, up being the world's z seen from the map frame.
  std::optional<mapping::MeasuredTilt> tilt;
  if (attitude) {
    tilt = mapping::MeasuredTilt{T_world_map_.linear().transpose() * Eigen::Vector3d::UnitZ(),
                                 config_.tilt_tolerance_deg};
  }
  Result<mapping::MergeStep> merge = [&] {
    const sensors::ScopedTime timing(result_.stages[Stage::kRegistration]);
    return Builder().Add(mapping::CloudFromScan(stop.scan), prior, bound, tilt);
  }();
  if (merge) stop.merge = *merge;
  if (stop.merge.merged) {
    merged_distance_m_ = result_.odometry_distance_m;
    merged_level_m_ = level_distance_m_;
    merged_rough_turn_rad_ = rough_turn_rad_;
    merged_stamp_s_ = stop.stamp_s;
  }
  if (!merge) stop.merge.registration.reason = merge.error().message;
  // A failed registration is never merged: the pose comes from odometry and the map keeps
  // what it had.
  // With loop closure a loop closed in this merge may have moved the new pose since: the graph's
  // latest estimate of it is the trajectory's last.
  const bool graph_pose = config_.registration.loop_closure.enabled && stop.merge.merged;
  const Eigen::Isometry3d T_map_base =
      graph_pose ? builder_.trajectory().back().T_map_base : stop.merge.T_map_base;
  stop.T_world_base = stop.merge.merged ? T_world_map_ * T_map_base : stop.T_world_base_odom;
  // A scan whose registration failed is never merged into the map cloud; the elevation map
  // still takes it at the odometry pose (said in the stop record), or an unregistrable stretch
  // of terrain would stay unknown and the robot could never plan across it. That pose's height
  // comes from the map's ground where the scan overlaps it.
  stop.elevation_from_odometry = !stop.merge.merged;
  {
    const sensors::ScopedTime timing(result_.stages[Stage::kMapUpdate]);
    UpdateElevation(stop);
  }
  T_world_base_ = stop.T_world_base;
  odo_ref_ = *odo;
  const bool arrived = Arrived(stop) || closing_look_;  // the closing look plans nothing
  if (!arrived) Plan(stop);
  result_.stops.push_back(std::move(stop));
  const StopRecord& s = result_.stops.back();
  if (observer_.on_stop) observer_.on_stop(s, result_);
  char line[200];
  const std::string target =
      s.target < config_.via_m.size() ? "waypoint " + std::to_string(s.target + 1) : "goal";
  std::snprintf(line, sizeof(line), "stop %d: %.1f m to %s, registration %s, %s", k,
                s.distance_to_goal_m, target.c_str(),
                s.merge.merged ? mapping::ToString(s.merge.registration.path) : "FAILED",
                arrived         ? "goal reached"
                : !s.plan       ? "no path"
                : s.look_closer ? "path planned through doubtful hazards, to look closer"
                                : "path planned");
  Progress(line);
  if (arrived) {
    result_.success = true;
    result_.reason = "goal reached";
    return false;
  }
  if (!s.plan) {
    result_.reason = "no path at stop " + std::to_string(k) + ": " + s.plan_error;
    return false;
  }
  // The next scan's registration target, the map around this stop, is known: it is made while
  // the robot drives and scans (the drive's physics leaves the other cores idle).
  PrepareNextTarget();
  return Drive(s);
}

bool Mission::Arrived(StopRecord& stop) {
  const Eigen::Vector2d here = stop.T_world_base.translation().head<2>();
  for (;;) {
    stop.target = target_;
    stop.distance_to_goal_m = (Target() - here).norm();
    if (stop.distance_to_goal_m > config_.goal_tolerance_m) return false;
    if (target_ == config_.via_m.size()) return true;
    Progress("waypoint " + std::to_string(target_ + 1) + " of " +
             std::to_string(config_.via_m.size()) + " reached at stop " +
             std::to_string(stop.index));
    result_.waypoints_reached = ++target_;
  }
}

void Mission::CalibrateMount(int k, sensors::Scan3D& scan) {
  if (k == 0) {
    Result<mapping::MountFromFloor> found = mapping::CalibrateMountFromFloor(scan, config_.mount);
    if (found) {
      calibrated_mount_ = found->mount;
      result_.mount_calibration = *found;
      const Eigen::Vector3d deg = found->correction_rpy_rad * 180.0 / kPi;
      const Eigen::Vector3d sigma = found->sigma_rpy_rad * 180.0 / kPi;
      char text[192];
      std::snprintf(text, sizeof(text),
                    "mount calibrated by the floor at the start: roll %+.2f, pitch %+.2f, yaw "
                    "%+.2f deg (+-%.2f, %.2f, %.2f) off nominal",
                    deg.x(), deg.y(), deg.z(), sigma.x(), sigma.y(), sigma.z());
      Progress(text);
    } else {
      result_.mount_calibration_note = found.error().message;
      Progress("mount not calibrated: " + found.error().message);
    }
  }
  if (calibrated_mount_) sensors::ReassembleScan(scan, config_.mount, *calibrated_mount_);
}

void Mission::UpdateElevation(StopRecord& stop) {
  const Eigen::Isometry3f T = stop.T_world_base.cast<float>();
  // With the lines set right, a line set right by the floor within the line pitch's radius is
  // right everywhere, but the floor beyond that radius is met by lines that were not (their
  // floor lies farther): the real rig's 0.9 deg lifts that floor by 6-16 cm at 4-10 m, over the
  // 0.089 m step, so it stays out of the elevation map the robot plans on.
  const double map_range_m =
      config_.set_lines_right
          ? std::min(config_.map_range_m, mapping::LinePitchConfig{}.ground.max_radius_m)
          : config_.map_range_m;
  const ElevationScan scan = ElevationScanOf(stop.scan, map_range_m, config_.mount,
                                              config_.beam_divergence_rad, config_.map_area.cell_m);
  std::vector<Eigen::Vector3f> near;  // map frame, within map_range_m of the laser
  near.reserve(scan.points_base.size());
  for (const Eigen::Vector3f& p : scan.points_base) near.push_back(T * p);
  if (!stop.elevation_from_odometry) {  // a registered view only
    const mapping::GridGeometry& g = config_.map_area;
    for (const sensors::ScanPoint& p : stop.scan.points) {
      if (p.range_m > map_range_m) continue;
      const Eigen::Vector3f at = T * Eigen::Vector3f(p.x, p.y, p.z);
      const mapping::CellIndex c = g.IndexOf(at.x(), at.y());
      if (!g.Contains(c)) continue;
      float& nearest = nearest_view_m_[g.Linear(c)];
      nearest = std::min(nearest, p.range_m);
    }
  }
  // At the odometry pose, the height comes from the map's ground where the scan overlaps it.
  if (stop.elevation_from_odometry) {
    constexpr double kMaxShift_m = 2.0;  // beyond: the map or the scan gone wrong, not drift
    const std::optional<HeightOffset> fit = FitHeightOffset(result_.elevation, near);
    if (fit && std::abs(fit->dz_m) <= kMaxShift_m) {
      stop.T_world_base.translation().z() -= fit->dz_m;
      // The points at the pose as corrected, as anyone rebuilding the map from the stop computes
      // them (a shift in float would differ from that in the last bit).
      const Eigen::Isometry3f T_fitted = stop.T_world_base.cast<float>();
      for (std::size_t i = 0; i < near.size(); ++i) near[i] = T_fitted * scan.points_base[i];
      stop.height_fit = fit;
    }
  }
  const Eigen::Vector3f laser =
      (stop.T_world_base * config_.mount.BaseToLaser(0.0)).translation().cast<float>();
  if (stop.elevation_from_odometry) {
    // Odometry slips by up to a metre on rugged ground: the scan only fills the map's unknown
    // cells. Blended into the ground the map has seen, a shifted view of it makes steps and
    // drops all over the overlap (the fake hazards that sealed the terrain runs' way).
    auto [view, filled] = FillUnknown(result_.elevation, near, laser);
    stop.elevation_cells_filled = filled;
    if (optimised_) optimised_->AddOdometryView(std::move(view));
    return;
  }
  if (optimised_) {
    UpdateOptimisedElevation(stop, scan);
    return;
  }
  result_.elevation.InsertScan(near.data(), near.size(), laser);
  // The laser cannot see under the robot, but the robot stands on that ground; only a registered
  // pose knows its height well enough (odometry's z drifts, and a wrong one makes a step around
  // the robot that traps it).
  std::vector<Eigen::Vector3f> ground;
  for (const Eigen::Vector3f& p : scan.ground_base) ground.push_back(T * p);
  result_.elevation.InsertPoints(ground.data(), ground.size());
}

void Mission::UpdateOptimisedElevation(const StopRecord& stop, const ElevationScan& scan) {
  // The graph's poses are rigid and every merged scan is inserted once: a failure is a bug.
  const auto bug = [](const Error& e) { throw std::logic_error("mission: " + e.message); };
  if (auto inserted = optimised_->Insert(stop.merge.scan_index, scan, stop.T_world_base);
      !inserted) {
    bug(inserted.error());
  }
  if (stop.merge.reposed) {
    std::vector<std::pair<std::size_t, Eigen::Isometry3d>> poses;
    for (const mapping::TrajectoryPose& p : builder_.trajectory()) {
      poses.emplace_back(p.scan_index, T_world_map_ * p.T_map_base);
    }
    if (auto moved = optimised_->Repose(poses); !moved) bug(moved.error());
  }
  result_.elevation = optimised_->Map();
}

void Mission::SetFinalPoses() {
  std::map<std::size_t, Eigen::Isometry3d> optimum;  // scan index -> T_world_base
  for (const mapping::TrajectoryPose& p : builder_.trajectory()) {
    optimum[p.scan_index] = T_world_map_ * p.T_map_base;
  }
  // A stop that did not register is no graph node: it moves with the last registered stop
  // before it (its odometry pose was propagated from that one).
  Eigen::Isometry3d correction = Eigen::Isometry3d::Identity();
  for (StopRecord& stop : result_.stops) {
    const auto it = stop.merge.merged ? optimum.find(stop.merge.scan_index) : optimum.end();
    if (it != optimum.end()) correction = it->second * stop.T_world_base.inverse();
    stop.T_world_base_final = it != optimum.end() ? it->second : correction * stop.T_world_base;
  }
}

// The robot may stand where the footprint rule forbids a path to go (a hazard seen late, drift):
// the nearest free cell it can reach in a straight line, crossing no step, slope or drop beyond
// the footprint it stands on.
std::optional<Eigen::Vector2d> EscapeCell(const planning::TraversabilityGrid& grid,
                                          const Eigen::Vector2d& from, double radius_m,
                                          double footprint_radius_m) {
  const mapping::GridGeometry& g = grid.geometry;
  const int reach = static_cast<int>(std::ceil(radius_m / g.cell_m));
  const mapping::CellIndex c = g.IndexOf(from.x(), from.y());
  std::optional<Eigen::Vector2d> best;
  double best_d = std::numeric_limits<double>::infinity();
  for (int j = c.j - reach; j <= c.j + reach; ++j) {
    for (int i = c.i - reach; i <= c.i + reach; ++i) {
      if (!g.Contains({i, j}) || !grid.Free(g.Linear({i, j}))) continue;
      const Eigen::Vector2d to = g.CenterOf({i, j});
      const double d = (to - from).norm();
      if (d >= best_d || d > radius_m) continue;
      bool clear = true;
      for (double t = 0; t <= 1.0 && clear; t += 0.5 * g.cell_m / std::max(d, g.cell_m)) {
        const Eigen::Vector2d p = from + t * (to - from);
        // What the robot stands on it has already crossed (a slope it backed down, a step it
        // straddles): only the ground beyond its footprint decides.
        if (t * d < footprint_radius_m) continue;
        const planning::Blocked b = grid.blocked[g.Linear(g.IndexOf(p.x(), p.y()))];
        clear = b == planning::Blocked::kFree || b == planning::Blocked::kNearHazard ||
                b == planning::Blocked::kUnknown;
      }
      if (clear) best = to, best_d = d;
    }
  }
  return best;
}

// A path from `here` on `grid`: out of a hazard margin first if the robot stands in one, and to
// the nearest free cell by a blocked goal (within kGoalApproach_m from afar, where the hazard may
// be a sparse view; within the goal tolerance from close by, which counts as arriving).
tl::expected<planning::Path, planning::NoPath> Mission::PlanOn(
    const planning::TraversabilityGrid& grid, const Eigen::Vector2d& here) {
  const sensors::ScopedTime timing(result_.stages[Stage::kPlanning]);
  auto path = planning::PlanPath(grid, here, Target(), config_.algorithm);
  if (!path && path.error().reason == planning::NoPath::Reason::kStartBlocked) {
    if (const auto escape =
            EscapeCell(grid, here, kEscapeRadius_m, config_.planner.robot.width_m / 2)) {
      path = planning::PlanPath(grid, *escape, Target(), config_.algorithm);
      if (path) {  // drive out to the free cell first
        path->waypoints.insert(path->waypoints.begin(),
                               planning::Waypoint{here.x(), here.y(), path->waypoints[0].z_m});
      }
    }
  }
  if (!path && path.error().reason == planning::NoPath::Reason::kGoalBlocked) {
    const bool far = (Target() - here).norm() > kGoalApproach_m;
    const double radius = far ? kGoalApproach_m : config_.goal_tolerance_m;
    if (const auto near = EscapeCell(grid, Target(), radius, 0.0)) {
      auto to_near = planning::PlanPath(grid, here, *near, config_.algorithm);
      if (to_near) path = std::move(to_near);
    }
  }
  return path;
}

void Mission::Plan(StopRecord& stop) {
  last_plan_stop_ = stop.index;
  sensors::Stopwatch watch;
  mapping::ComputeLayersInto(result_.elevation, config_.layers, layers_);
  for (const FeltHazard& f : felt_) MarkFelt(layers_, f);
  MarkRefutedGaps(layers_, refuted_gaps_);
  result_.stages[Stage::kMapUpdate] += watch.Read();
  const mapping::ElevationLayers& layers = layers_;
  stop.felt_hazards = static_cast<int>(felt_.size());
  const planning::PlannerConfig planner = MissionPlanner(config_);
  Traversability(layers, planner, grid_);
  // The bridged gaps this stop's laser saw from where its lines are denser than the cells, still
  // gaps: not ground the lines skipped (line_gaps.hpp). Only at a registered pose: at an
  // odometry pose the scan only filled the map's unknown cells, a metre off at worst.
  if (!stop.elevation_from_odometry) {
    const Eigen::Isometry3d laser_base = config_.mount.BaseToLaser(0.0);
    const Eigen::Isometry3d laser = stop.T_world_base * laser_base;
    const Eigen::Matrix3d R = stop.T_world_base.linear();
    const double radius_m =
        DenseLinesRadius(stop.scan, laser_base.translation().z(), config_.map_area.cell_m);
    if (RefuteBridges(grid_, layers_, laser.translation().head<2>(), std::atan2(R(1, 0), R(0, 0)),
                      NearestGroundAhead(stop.scan, config_.mount), radius_m, refuted_gaps_) > 0) {
      MarkRefutedGaps(layers_, refuted_gaps_);
      Traversability(layers, planner, grid_);
    }
  }
  const planning::TraversabilityGrid& grid = grid_;  // the relaxed grid when a recovery plans
  const Eigen::Vector2d here = stop.T_world_base.translation().head<2>();
  auto path = PlanOn(grid, here);
  // Recoveries, when the map cuts every way: plan through the cells it is least sure of, as
  // unknown. The robot drives only over what it has seen, stops short of them (never onto one)
  // and looks from closer; what is truly there stays in the map and ends the run honestly.
  const auto look_closer = [&](const std::function<bool(std::size_t)>& doubtful,
                               const std::string& what) {
    relaxed_layers_ = layers;
    std::vector<bool> doubt(layers.state.size(), false);
    std::size_t n = 0;
    for (std::size_t k = 0; k < layers.state.size(); ++k) {
      if (!doubtful(k)) continue;
      relaxed_layers_.state[k] = mapping::CellState::kUnknown;
      doubt[k] = true;
      ++n;
    }
    if (n == 0) return;
    planning::TraversabilityGrid& relaxed = relaxed_grid_;
    Traversability(relaxed_layers_, planner, relaxed);
    auto through = PlanOn(relaxed, here);
    if (!through) return;
    stop.plan_note = "no path: planning through " + what + " as unknown, to look from closer (" +
                     path.error().message + ")";
    stop.look_closer = true;
    stop.plan_to_doubt_m = 0;  // how far the robot may go before the first of those cells
    for (std::size_t i = 1; i < through->waypoints.size(); ++i) {
      const planning::Waypoint &v = through->waypoints[i - 1], &w = through->waypoints[i];
      if (doubt[relaxed.geometry.Linear(relaxed.geometry.IndexOf(w.x_m, w.y_m))]) break;
      stop.plan_to_doubt_m += std::hypot(w.x_m - v.x_m, w.y_m - v.y_m);
    }
    path = std::move(through);
    std::swap(grid_, relaxed_grid_);  // `grid` is the relaxed one from here on
  };
  // Drops are inferred from rays passing low; at range a small attitude error makes them where
  // there are none.
  if (!path) {
    look_closer([&](std::size_t k) { return layers.state[k] == mapping::CellState::kDrop; },
                "the inferred drops");
  }
  // A goal seen from afar on sparse points can look steep or stepped.
  if (!path && path.error().reason == planning::NoPath::Reason::kGoalBlocked &&
      (Target() - here).norm() > kGoalApproach_m) {
    look_closer(
        [&](std::size_t k) {
          if (layers.state[k] == mapping::CellState::kDrop) return true;  // as above, too
          return layers.state[k] != mapping::CellState::kUnknown &&
                 (layers.geometry.CenterOf(layers.geometry.FromLinear(k)) - Target()).norm() <
                     kGoalApproach_m;
        },
        "the inferred drops and the hazards seen around the goal");
  }
  // Far ground is seen on sparse points at a grazing angle: a few of them make a step or a slope
  // that closer scans do not confirm (the corridor's far end, distant hill sides).
  if (!path && (path.error().reason == planning::NoPath::Reason::kDisconnected ||
                path.error().reason == planning::NoPath::Reason::kGoalBlocked)) {
    look_closer(
        [&](std::size_t k) {
          if (layers.state[k] == mapping::CellState::kDrop) return true;
          return layers.state[k] != mapping::CellState::kUnknown &&
                 nearest_view_m_[k] > kFarDoubt_m;
        },
        "the inferred drops and everything never seen from closer than " +
            std::to_string(int(kFarDoubt_m)) + " m");
  }
  if (!path) {
    stop.plan_error = path.error().message;
    return;
  }
  const KnownStretch known = PlanKnownStretch(*path, grid);
  stop.plan_known_m = known.length_m;
  stop.plan_seen_to_end = known.to_the_end;
  stop.plan_clear_m = PlanClearStretch(*path, grid, config_.drift_per_m, config_.drive_per_stop_m);
  stop.plan = std::move(*path);
}

// Heading of the path just after arc length `arc_m` (looking one metre on).
double PathHeading(const planning::Path& path, double arc_m) {
  const std::vector<Eigen::Vector2d> upto = PathPrefix(path, arc_m);
  const std::vector<Eigen::Vector2d> beyond = PathPrefix(path, arc_m + 1.0);
  const Eigen::Vector2d d = beyond.back() - upto.back();
  if (d.norm() > 1e-6) return std::atan2(d.y(), d.x());
  const Eigen::Vector2d e = upto.back() - upto.front();
  return std::atan2(e.y(), e.x());
}

bool Mission::Drive(const StopRecord& stop) {
  const planning::Path& path = *stop.plan;
  // The metre driven after a stop that only turned is onto the blind zone just ahead of the
  // heading it turned to. A plan that starts elsewhere (the new scan moved it: behind the robot,
  // driven in reverse) starts in ground no scan saw, so the robot turns to face it first (office
  // seed 5 with the servo's 0.9 deg line pitch error and lines as recorded: turned south, planned
  // north, reversed the metre into the corridor's wall behind it, unseen, and climbed it to 48
  // deg).
  const bool turned_to_look_along =
      last_stop_turned_only_ &&
      std::abs(std::remainder(PathHeading(path, 0.0) - Yaw(stop.T_world_base), 2.0 * kPi)) <=
          kInView_rad;
  const DriveLength drive = PlanDriveLength(
      config_.drive_per_stop_m, config_.unknown_margin_m, stop.plan_known_m, stop.plan_seen_to_end,
      turned_to_look_along, stop.look_closer ? std::optional(stop.plan_to_doubt_m) : std::nullopt);
  const bool turn_only = drive.turn_only;
  const double length = turn_only ? drive.length_m : CutForDrift(drive.length_m, stop.plan_clear_m);
  if (stop.look_closer && !turn_only && length < MinDriveLength(config_.follower)) {
    // Looked from as close as it may go: the hazards stand, so there is no way on.
    result_.reason = "no path at stop " + std::to_string(stop.index) +
                     ": the hazards that block the way stay hazards seen from close by";
    return false;
  }
  last_stop_turned_only_ = turn_only;
  backed_off_ = false;
  if (!turn_only && !Follow(path, length)) return false;
  // After backing off, the next scan looks at the slope from where the robot stands.
  if (!backed_off_ && !FacePath(PathHeading(path, turn_only ? 0.0 : length))) return false;
  if (backed_off_) return Brake();
  if (!Brake()) return false;
  // Never scan standing steeply: back off the way it came (once) and mark what it stood on. The
  // tilt is read standing, once the base has braked: a base still moving reads a tilt it does not
  // stand at (terrain seed 19 rolled on from 18 to 23 deg in the half second after its drive).
  if (Tilt() > config_.scan_tilt_deg * kPi / 180) {
    Result<sensors::Odometry> odo = base_.ReadOdometry();
    if (!odo) {
      result_.reason = "base: " + odo.error().message;
      return false;
    }
    if (!BackOff(*odo, Tilt(), false)) return false;
    return Brake();
  }
  return true;
}

bool Mission::Brake() {
  Result<sensors::Odometry> stopped = DriveBase(0.0, 0.0, kStopTime_s);
  if (!stopped) result_.reason = "base: " + stopped.error().message;
  return stopped.has_value();
}

bool Mission::Rebase() {
  Result<sensors::Odometry> odo = base_.ReadOdometry();
  if (!odo) {
    result_.reason = "base: " + odo.error().message;
    return false;
  }
  T_world_map_ = T_world_base_ = Propagate(T_world_base_, odo_ref_, *odo, StillAttitude());
  odo_ref_ = *odo;
  return true;
}

bool Mission::FacePath(double yaw_rad) {
  Result<sensors::Odometry> odo = base_.ReadOdometry();
  if (!odo) {
    result_.reason = "base: " + odo.error().message;
    return false;
  }
  const double off_rad = std::remainder(yaw_rad - Yaw(Estimate(*odo)), 2.0 * kPi);
  return std::abs(off_rad) <= kInView_rad || TurnTo(yaw_rad);
}

bool Mission::TurnTo(double yaw_rad) {
  const double rate = config_.follower.max_yaw_rate_rps;
  // Stuck is no progress for stuck_timeout_s (kMinTurnProgress_rad closer to the heading), not a
  // turn that takes longer: at a configured 0.3 rad/s a half turn takes 11 s, and the 8 s total
  // this was ended every such turn "stuck".
  double progress_s = probes_.now_s(), closest_rad = std::numeric_limits<double>::infinity();
  while (true) {
    if (OverBudget()) return false;
    Result<sensors::Odometry> odo = base_.ReadOdometry();
    if (!odo) {
      result_.reason = "base: " + odo.error().message;
      return false;
    }
    const double error = std::remainder(yaw_rad - Yaw(Estimate(*odo)), 2.0 * kPi);
    if (std::abs(error) < kHeadingTolerance_rad) return true;
    if (std::abs(error) < closest_rad - kMinTurnProgress_rad) {
      closest_rad = std::abs(error);
      progress_s = probes_.now_s();
    } else if (probes_.now_s() - progress_s > config_.stuck_timeout_s) {
      result_.reason = "stuck: cannot turn to " + NumberText(yaw_rad * 180 / kPi) + " deg";
      return false;
    }
    const double omega = std::clamp(kTurnGain_per_s * error, -rate, rate);
    Result<sensors::Odometry> next = DriveBase(0.0, omega, config_.control_period_s);
    if (!next) {
      result_.reason = "base: " + next.error().message;
      return false;
    }
    Turned(*odo, *next, sampled_level_);
    if (!RecordSample(*next)) return false;
  }
}

void Mission::Odometer(const sensors::Odometry& from, const sensors::Odometry& to) {
  const double step_m = std::hypot(to.x_m - from.x_m, to.y_m - from.y_m);
  result_.odometry_distance_m += step_m;
  const bool level = Attitude() && Tilt() <= kLevelTilt_rad;
  if (level) level_distance_m_ += step_m;
  Turned(from, to, level);
}

void Mission::Turned(const sensors::Odometry& from, const sensors::Odometry& to, bool level) {
  if (!level) rough_turn_rad_ += std::abs(std::remainder(to.yaw_rad - from.yaw_rad, 2.0 * kPi));
}

bool Mission::RecordSample(const sensors::Odometry& odo) {
  TrajectorySample sample{probes_.now_s(), Estimate(odo), std::nullopt};
  if (probes_.true_pose) sample.T_world_base_true = probes_.true_pose();
  result_.trajectory.push_back(sample);
  trail_.Add(Eigen::Vector2d(odo.x_m, odo.y_m));
  if (!probes_.roll_pitch_rad) return true;
  const double tilt = Tilt();
  sampled_level_ = tilt <= kLevelTilt_rad;
  result_.max_tilt_rad = std::max(result_.max_tilt_rad, tilt);
  if (tilt <= config_.max_tilt_deg * kPi / 180) return true;
  result_.reason = "tipping over: tilt " + NumberText(tilt * 180 / kPi) + " deg";
  return false;
}

bool Mission::Follow(const planning::Path& path, double length_m) {
  const std::vector<Eigen::Vector2d> prefix = PathPrefix(path, length_m);
  const double prefix_m = PolylineLength(prefix);
  const double slope_grade = std::tan(config_.slope_tilt_deg * kPi / 180);
  const PathGrade grade(path);
  PurePursuit follower(prefix, config_.follower);
  sensors::Odometry odo = odo_ref_;
  if (Result<sensors::Odometry> now = base_.ReadOdometry(); now) odo = *now;
  Eigen::Vector2d progress_xy(odo.x_m, odo.y_m);
  double progress_yaw = odo.yaw_rad;
  double progress_s = probes_.now_s();
  while (true) {
    if (OverBudget()) return false;
    const Eigen::Isometry3d T_est = Estimate(odo);
    DriveCommand cmd =
        follower.Command(T_est.translation().x(), T_est.translation().y(), Yaw(T_est));
    if (cmd.done) return true;
    const bool reversing = follower.reversing();
    const double tilt = Tilt();
    if (tilt > config_.caution_tilt_deg * kPi / 180) return BackOff(odo, tilt, false, reversing);
    const double arc = prefix_m - follower.remaining_m();
    // A tilt the planned ground does not explain is something the robot ran onto. The ground
    // explains its grade along the path and its cells' tilt across it: on a side slope the path
    // is level and the robot rolls by the slope (terrain seed 7 rolled 15.7 deg on a 16 deg flank
    // it had planned along, "ran onto something", and the obstacle it marked closed the way).
    const double explained = std::max(std::atan(grade.Max(arc - 0.5, arc + 0.5)),
                                      grade.MaxTilt(grid_, arc - 0.5, arc + 0.5));
    if (tilt > explained + kUnexpectedTilt_rad) {
      return BackOff(odo, tilt, true, reversing);
    }
    // Speed and turn rate scale together, so the robot stays on the follower's arc. Turning fast
    // while driving fast makes the skid-steer P3-AT brake its inner wheels hard and a top-heavy
    // robot pitch over its front wheels: keep the centripetal acceleration v * omega small. On
    // slopes (ahead on the path, or under the robot) drive slower still.
    const auto scale = [&cmd](double s) {
      cmd.v_mps *= s;
      cmd.omega_rps *= s;
    };
    const double centripetal = std::abs(cmd.v_mps * cmd.omega_rps);
    if (centripetal > kMaxCentripetal_mps2) scale(std::sqrt(kMaxCentripetal_mps2 / centripetal));
    if (tilt > config_.slope_tilt_deg * kPi / 180 ||
        grade.Max(arc, arc + kSlopeLookahead_m) > slope_grade) {
      scale(std::min({1.0, config_.slope_speed_mps / std::max(std::abs(cmd.v_mps), 1e-9),
                      kSlopeYawRate_rps / std::max(std::abs(cmd.omega_rps), 1e-9)}));
    }
    Result<sensors::Odometry> next = DriveBase(cmd.v_mps, cmd.omega_rps, config_.control_period_s);
    if (!next) {
      result_.reason = "base: " + next.error().message;
      return false;
    }
    Odometer(odo, *next);
    odo = *next;
    if (!RecordSample(odo)) return false;
    // Turning on the spot is progress too: half a turn at the slope's yaw rate outlasts the
    // stuck timeout (terrain seed 196 was "stuck" turning round on a 7 deg flank).
    if ((Eigen::Vector2d(odo.x_m, odo.y_m) - progress_xy).norm() > kMinProgress_m ||
        std::abs(std::remainder(odo.yaw_rad - progress_yaw, 2.0 * kPi)) > kMinTurnProgress_rad) {
      progress_xy = Eigen::Vector2d(odo.x_m, odo.y_m);
      progress_yaw = odo.yaw_rad;
      progress_s = probes_.now_s();
    } else if (probes_.now_s() - progress_s > config_.stuck_timeout_s) {
      result_.reason = "stuck: no progress for " + NumberText(config_.stuck_timeout_s) + " s";
      return false;
    }
  }
}

// Backs straight out of a tilt beyond caution (forwards when it was reversing) and remembers the
// ground it was driving onto as too steep.
bool Mission::BackOff(const sensors::Odometry& odo, double tilt_rad, bool obstacle,
                      bool reversing) {
  const Eigen::Isometry3d T = Estimate(odo);
  const double heading = Yaw(T) + (reversing ? kPi : 0.0);  // the way it was going
  FeltHazard felt;
  felt.centre_m = T.translation().head<2>() +
                  kFeltAhead_m * Eigen::Vector2d(std::cos(heading), std::sin(heading));
  felt.heading_rad = heading;
  felt.tilt_rad = tilt_rad;
  felt.z_m = T.translation().z();
  felt.obstacle = obstacle;
  felt_.push_back(felt);
  backed_off_ = true;
  char line[160];
  std::snprintf(line, sizeof(line), "tilt %.1f deg at (%.2f, %.2f): backing off, %s",
                tilt_rad * 180 / kPi, T.translation().x(), T.translation().y(),
                obstacle ? (reversing ? "ran onto something behind" : "ran onto something ahead")
                         : (reversing ? "the ground behind is too steep"
                                      : "the ground ahead is too steep"));
  Progress(line);
  return DriveBack(odo, reversing);
}

bool Mission::DriveBack(const sensors::Odometry& odo, bool forwards) {
  const Eigen::Vector2d from(odo.x_m, odo.y_m);
  const double start_s = probes_.now_s();
  // Reversing blind over a rim or into a hollow can tilt it more than what it backs away from:
  // stop once it tilts kBackOffTiltRise_rad more, or past caution (from below caution).
  const double start_tilt = Tilt();
  const double stop_tilt = std::min(start_tilt + kBackOffTiltRise_rad,
                                    std::max(start_tilt, config_.caution_tilt_deg * kPi / 180));
  // The way it came, where the track holds enough of it; else straight back along the heading.
  std::optional<PurePursuit> retrace;
  if (std::vector<Eigen::Vector2d> way = trail_.WayBack(from, kBackOff_m);
      PolylineLength(way) >= kMinRetrace_m) {
    retrace.emplace(std::move(way), RetraceFollower(kBackOffSpeed_mps, kSlopeYawRate_rps));
  }
  sensors::Odometry now = odo;
  while (retrace || (Eigen::Vector2d(now.x_m, now.y_m) - from).norm() < kBackOff_m) {
    if (OverBudget()) return false;
    if (probes_.now_s() - start_s > config_.stuck_timeout_s) break;  // as far as it goes
    if (Tilt() > stop_tilt) break;
    DriveCommand cmd{forwards ? kBackOffSpeed_mps : -kBackOffSpeed_mps, 0.0, false};
    if (retrace) cmd = retrace->Command(now.x_m, now.y_m, now.yaw_rad);
    if (cmd.done) break;
    Result<sensors::Odometry> next = DriveBase(cmd.v_mps, cmd.omega_rps, config_.control_period_s);
    if (!next) {
      result_.reason = "base: " + next.error().message;
      return false;
    }
    Odometer(now, *next);
    now = *next;
    if (!RecordSample(now)) return false;
  }
  return true;
}

}  // namespace

planning::PlannerConfig MissionPlanner(const MissionConfig& config) {
  planning::PlannerConfig planner = config.planner;
  planner.robot.width_m += 2.0 * config.safety_margin_m;  // the follower cuts corners a little
  return planner;
}

MissionResult RunMission(sensors::ScanSource& source, sensors::MobileBase& base,
                         const Eigen::Isometry3d& T_world_start, const MissionConfig& config,
                         const MissionProbes& probes, const MissionObserver& observer) {
  if (!probes.now_s) throw std::invalid_argument("mission: a clock (probes.now_s) is required");
  config.follower.Validate();
  config.planner.Validate();
  config.registration.Validate();
  if (config.map_area.cell_count() == 0) throw std::invalid_argument("mission: empty map area");
  if (!(config.caution_tilt_deg > 0 && config.caution_tilt_deg < config.max_tilt_deg) ||
      !(config.slope_tilt_deg > 0 && config.slope_tilt_deg < config.caution_tilt_deg) ||
      !(config.scan_tilt_deg > 0 && config.scan_tilt_deg < config.caution_tilt_deg) ||
      !(config.slope_speed_mps > 0)) {
    throw std::invalid_argument(
        "mission: need 0 < slope_tilt_deg < caution_tilt_deg < max_tilt_deg, "
        "0 < scan_tilt_deg < caution_tilt_deg and slope_speed_mps > 0");
  }
  if (!(config.drive_per_stop_m > 0) || config.max_stops < 1 || !(config.goal_tolerance_m > 0)) {
    throw std::invalid_argument(
        "mission: drive_per_stop_m, max_stops, goal_tolerance_m must be > 0");
  }
  for (const Eigen::Vector2d& p : config.via_m) {
    if (!p.allFinite()) throw std::invalid_argument("mission: a waypoint (via_m) is not finite");
  }
  Mission mission(source, base, config, probes, observer);
  return mission.Run(T_world_start);
}

}  // namespace pitchlab::mission
