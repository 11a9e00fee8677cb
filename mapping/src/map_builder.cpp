#include "pitchlab/mapping/map_builder.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "loop_closer.hpp"
#include "pitchlab/mapping/parallel_for.hpp"
#include "pitchlab/mapping/cloud_statistics.hpp"
#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {
namespace {

// `T` with its rotation made exactly orthonormal (the nearest unit quaternion's). Each scan's
// prior is relative to the last merged pose, and ICP from it composes that pose's inverse back
// onto it: a rotation R(I + S) came back as R(I + 2S), and the rounding error doubled with every
// merge (office seed 146 reached 4e-7 after 33 merges, and its TUM trajectory was refused).
Eigen::Isometry3d Orthonormal(Eigen::Isometry3d T) {
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return T;
}

}  // namespace

void LoopClosureConfig::Validate() const {
  const auto fail = [](const std::string& field, double value, const std::string& rule) {
    throw std::invalid_argument("map.loop_closure." + field + " = " + NumberText(value) + ": " +
                                rule);
  };
  if (!(std::isfinite(candidates.max_distance_m) && candidates.max_distance_m > 0)) {
    fail("candidates.max_distance_m", candidates.max_distance_m, "must be finite and > 0");
  }
  if (!(candidates.probability > 0 && candidates.probability < 1)) {
    fail("candidates.probability", candidates.probability, "must lie in (0, 1)");
  }
  if (!(std::isfinite(candidates.min_travel_m) && candidates.min_travel_m >= 0)) {
    fail("candidates.min_travel_m", candidates.min_travel_m, "must be finite and >= 0");
  }
  if (max_registrations < 1) fail("max_registrations", max_registrations, "must be >= 1");
  if (!(std::isfinite(scan_voxel_m) && scan_voxel_m > 0)) {
    fail("scan_voxel_m", scan_voxel_m, "must be finite and > 0");
  }
  if (!(information_scale > 0 && information_scale <= 1)) {
    fail("information_scale", information_scale, "must lie in (0, 1]");
  }
  graph.Validate();
}

void MapConfig::Validate() const {
  if (!(map_voxel_m > 0)) {
    throw std::invalid_argument("map.map_voxel_m = " + NumberText(map_voxel_m) +
                                ": must be > 0");
  }
  if (!(local_map_radius_m > 0)) {
    throw std::invalid_argument("map.local_map_radius_m = " + NumberText(local_map_radius_m) +
                                ": must be > 0");
  }
  registration.Validate();
  if (loop_closure.enabled) loop_closure.Validate();
}

namespace {
const MapConfig& Validated(const MapConfig& config) {
  config.Validate();
  return config;
}
}  // namespace

MapBuilder::MapBuilder(const MapConfig& config)
    : config_(Validated(config)),
      map_(config.map_voxel_m, config.loop_closure.enabled),
      loops_(config.loop_closure.enabled
                 ? std::make_unique<LoopCloser>(config.loop_closure, config.registration,
                                                config.sensor_base)
                 : nullptr) {}

MapBuilder::~MapBuilder() = default;
MapBuilder::MapBuilder(MapBuilder&&) noexcept = default;
MapBuilder& MapBuilder::operator=(MapBuilder&&) noexcept = default;

PointCloud MapBuilder::MapCloud() const { return map_.Cloud(); }

LoopClosureCounts MapBuilder::loop_closures() const {
  return loops_ ? loops_->counts() : LoopClosureCounts{};
}

std::vector<LoopClosure> MapBuilder::accepted_loops() const {
  return loops_ ? loops_->accepted() : std::vector<LoopClosure>{};
}

// The merged scan joins the pose graph and the loop search runs; when the graph's optimum moved
// earlier poses, the trajectory and the map cloud follow it.
Result<void> MapBuilder::CloseLoops(const PointCloud& cloud_base, MergeStep& step) {
  Result<void> added = trajectory_.size() == 1
                           ? loops_->AddFirst(cloud_base, step.scan_index)
                           : loops_->AddMerged(cloud_base, step.scan_index, step.T_map_base,
                                               step.registration, step);
  if (!added) return added;
  // The graph keeps rotations as quaternions: a pose read back differs from the one composed by
  // ~1e-16. 1e-9 (m, and rad in the rotation's entries) is far below anything a scan measures
  // and far above that round-off: a pose that moved less has not moved.
  constexpr double kRoundOff = 1e-9;
  const std::vector<Eigen::Isometry3d> poses = loops_->Poses();
  for (std::size_t i = 0; i < poses.size() && !step.reposed; ++i) {
    step.reposed =
        (poses[i].matrix() - trajectory_[i].T_map_base.matrix()).cwiseAbs().maxCoeff() > kRoundOff;
  }
  if (!step.reposed) return {};
  for (std::size_t i = 0; i < poses.size(); ++i) trajectory_[i].T_map_base = poses[i];
  next_target_.reset();
  return map_.Repose(poses);
}

void MapBuilder::PrepareNext() {
  if (trajectory_.empty() || next_target_) return;
  const SerialLoops alone;
  auto target = std::make_unique<RegistrationTarget>(
      map_.Around(trajectory_.back().T_map_base, config_.local_map_radius_m), config_.sensor_base);
  target->Prepare(config_.registration);
  next_target_ = std::move(target);
}

Result<MergeStep> MapBuilder::Add(const PointCloud& cloud_base,
                                  const std::optional<Eigen::Isometry3d>& odometry_T_map_base,
                                  const std::optional<GuessUncertainty>& odometry_uncertainty,
                                  const std::optional<MeasuredTilt>& measured_tilt) {
  MergeStep step;
  step.scan_index = scans_seen_++;
  if (trajectory_.empty()) {  // the first scan defines the map frame
    std::size_t bad = 0;
    for (const Eigen::Vector3f& p : cloud_base) bad += p.allFinite() ? 0 : 1;
    if (cloud_base.empty()) return Fail(Error::Code::kInvalidArgument, "first scan is empty");
    if (bad > 0) {
      return Fail(Error::Code::kInvalidArgument, "first scan has " + std::to_string(bad) +
                                                     " points that are not finite (NaN/inf)");
    }
    // One map, one scale: its first scan resolves the registration's length_scale (when auto) for
    // every later scan. A scan measured alone can read a decade off: a P3-DX stopped 0.3 m from a
    // wall (corridor seed 1, stop 2) measured R = 0.32 m and n = 0.03 mm (the LMS200's centimetre
    // steps on one flat surface leave a small patch no residual) and resolved to 0.1, every gate
    // shrunk tenfold: "0 % of source points within 0.016 m".
    if (std::isnan(config_.registration.length_scale)) {
      const CloudStatistics first =
          MeasureCloud(cloud_base, config_.sensor_base.value_or(Eigen::Vector3f::Zero()));
      config_.registration.length_scale = config_.registration.Resolve(first, first).length_scale;
    }
    map_.Add(cloud_base, Eigen::Isometry3d::Identity());
    next_target_.reset();
    last_scan_ = cloud_base;
    trajectory_.push_back({step.scan_index, Eigen::Isometry3d::Identity()});
    step.merged = true;
    step.registration.success = true;
    step.registration.outcome = RegistrationOutcome::kSuccess;
    step.registration.reason = "first scan: defines the map frame";
    if (loops_) {
      if (Result<void> closed = CloseLoops(cloud_base, step); !closed) {
        return tl::make_unexpected(closed.error());
      }
    }
    return step;
  }
  const Eigen::Isometry3d T_map_last = trajectory_.back().T_map_base;
  RegistrationPrior prior;
  if (odometry_T_map_base) prior.odometry = T_map_last.inverse() * *odometry_T_map_base;
  prior.odometry_uncertainty = odometry_uncertainty;
  if (odometry_T_map_base && measured_tilt) {  // registration works in the last scan's frame
    prior.tilt = measured_tilt;
    prior.tilt->up_target = T_map_last.linear().transpose() * measured_tilt->up_target;
  }
  prior.previous_motion = last_motion_ ? *last_motion_ : Eigen::Isometry3d::Identity();
  prior.target_scan = &last_scan_;  // the map was seen from many places; free space from one
  prior.source_sensor = prior.target_sensor = config_.sensor_base;  // target: the last base_link
  // The target: the map around the last pose, as PrepareNext made it or made here.
  if (!next_target_) {
    next_target_ = std::make_unique<RegistrationTarget>(
        map_.Around(T_map_last, config_.local_map_radius_m), config_.sensor_base);
  }
  Result<RegistrationResult> r = Register(*next_target_, cloud_base, prior, config_.registration);
  if (!r) return tl::make_unexpected(r.error());
  step.registration = *r;
  if (!r->success) return step;  // reported, never merged: the map and its target stay
  step.T_map_base = Orthonormal(T_map_last * r->T_target_source);
  map_.Add(cloud_base, step.T_map_base);
  next_target_.reset();
  trajectory_.push_back({step.scan_index, step.T_map_base});
  last_scan_ = cloud_base;
  last_motion_ = r->T_target_source;
  step.merged = true;
  if (loops_) {
    if (Result<void> closed = CloseLoops(cloud_base, step); !closed) {
      return tl::make_unexpected(closed.error());
    }
  }
  return step;
}

}  // namespace pitchlab::mapping
