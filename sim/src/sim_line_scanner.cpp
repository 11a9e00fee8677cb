#include "pitchlab/sim/sim_line_scanner.hpp"

#include <cmath>
#include <exception>
#include <stdexcept>
#include <string>
#include <utility>

#include "pitchlab/sensors/allowed_cores.hpp"
#include "serial_worker.hpp"

namespace pitchlab::sim {

SimLineScanner::SimLineScanner(Simulation& sim, sensors::RayCaster& caster,
                               const sensors::Lms200Config& config)
    : sim_(sim),
      caster_(caster),
      model_(config),
      sweeps_(sensors::InterlacedSweeps(model_.angle_increment_rad())) {}

float SimLineScanner::cast_range_m() const {
  return static_cast<float>(model_.max_range_m() * 1.05);
}

// One ray per beam: direction = R_world_laser [cos(theta + offset), sin(theta + offset), 0], tipped
// out of the scan plane by `tip_rad` (towards the laser's +z).
// The beams' directions in the laser frame depend only on (offset, tip), of which a line uses at
// most seven: each set is computed once, and every line only rotates it.
const std::vector<Eigen::Vector3d>& SimLineScanner::BeamDirections(double offset_rad,
                                                                   double tip_rad) {
  for (const BeamSet& set : beam_sets_) {
    if (set.offset_rad == offset_rad && set.tip_rad == tip_rad) return set.laser;
  }
  BeamSet set{offset_rad, tip_rad, {}};
  const int n = model_.readings();
  set.laser.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double theta = model_.angle_min_rad() + i * model_.angle_increment_rad() + offset_rad;
    set.laser.emplace_back(std::cos(tip_rad) * std::cos(theta), std::cos(tip_rad) * std::sin(theta),
                           std::sin(tip_rad));
  }
  beam_sets_.push_back(std::move(set));
  return beam_sets_.back().laser;
}

void SimLineScanner::CastAt(const Eigen::Isometry3d& T_world_laser, double offset_rad,
                            std::vector<float>& out, double tip_rad) {
  const int n = model_.readings();
  origins_.resize(3 * n);
  directions_.resize(3 * n);
  out.resize(n);
  const Eigen::Vector3d o = T_world_laser.translation();
  const std::vector<Eigen::Vector3d>& beams = BeamDirections(offset_rad, tip_rad);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = T_world_laser.linear() * beams[i];
    for (int k = 0; k < 3; ++k) {
      origins_[3 * i + k] = static_cast<float>(o[k]);
      directions_[3 * i + k] = static_cast<float>(d[k]);
    }
  }
  caster_.Cast(origins_.data(), directions_.data(), n, cast_range_m(), out.data(), nullptr);
}

// The surface normal at each beam's hit from two more rays a tenth of a beam step away, one along
// the scan line and one across it: the three hits span the surface (the ray caster reports no
// normal, so the hit points must give it). Each of the two is cast on both sides, and the side
// whose hit lies nearer the beam's own in range is taken: within a tenth of a step of an edge one
// side leaves the surface (a door jamb's face, 0.1 m wide, seen from 9 m with the room behind it),
// and a normal spanned by a hit on the wall behind called the jamb's face grazed: its returns got
// the 85 deg footprint noise, up to 0.3 m, and landed in the doorway. A beam whose neighbours
// missed on both sides counts as meeting its surface head on.
void SimLineScanner::CastIncidence(const Eigen::Isometry3d& T_world_laser) {
  const int n = model_.readings();
  const double delta = 0.1 * model_.angle_increment_rad();
  CastAt(T_world_laser, delta, along_);
  CastAt(T_world_laser, -delta, along_back_);
  CastAt(T_world_laser, 0.0, across_, delta);
  CastAt(T_world_laser, 0.0, across_back_, -delta);
  cos_incidence_.assign(n, 1.0f);
  // The side (+1 or -1) whose hit is finite and nearer `r` in range; 0 when both missed.
  const auto side = [](float r, float plus, float minus) {
    if (!std::isfinite(plus)) return std::isfinite(minus) ? -1 : 0;
    if (!std::isfinite(minus)) return 1;
    return std::abs(plus - r) <= std::abs(minus - r) ? 1 : -1;
  };
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(ranges_[i])) continue;
    const int s_along = side(ranges_[i], along_[i], along_back_[i]);
    const int s_across = side(ranges_[i], across_[i], across_back_[i]);
    if (s_along == 0 || s_across == 0) continue;
    const double theta = model_.angle_min_rad() + i * model_.angle_increment_rad();
    const double da = s_along * delta, dc = s_across * delta;
    // In the laser frame (the incidence does not depend on the frame).
    const Eigen::Vector3d d0(std::cos(theta), std::sin(theta), 0.0);
    const Eigen::Vector3d d1(std::cos(theta + da), std::sin(theta + da), 0.0);
    const Eigen::Vector3d d2(std::cos(dc) * std::cos(theta), std::cos(dc) * std::sin(theta),
                             std::sin(dc));
    const Eigen::Vector3d p0 = ranges_[i] * d0;
    const float r_along = s_along > 0 ? along_[i] : along_back_[i];
    const float r_across = s_across > 0 ? across_[i] : across_back_[i];
    const Eigen::Vector3d normal = (r_along * d1 - p0).cross(r_across * d2 - p0);
    if (normal.norm() <= 0.0) continue;
    cos_incidence_[i] = static_cast<float>(std::abs(normal.normalized().dot(d0)));
  }
}

void SimLineScanner::CastBeams(const Eigen::Isometry3d& T_world_laser) {
  CastAt(T_world_laser, 0.0, ranges_);
  if (model_.config().mixed_pixels) {
    const double half_div = 0.5 * model_.config().beam_divergence_deg * M_PI / 180.0;
    CastAt(T_world_laser, -half_div, edge_lo_);
    CastAt(T_world_laser, +half_div, edge_hi_);
  }
  if (model_.config().UsesIncidence()) CastIncidence(T_world_laser);
}

void SimLineScanner::set_sweep_lag_rad(double lag_rad) {
  if (!(lag_rad >= 0.0 && std::isfinite(lag_rad))) {
    throw std::invalid_argument("SimLineScanner: sweep lag " + std::to_string(lag_rad) +
                                " rad, want >= 0");
  }
  sweep_lag_rad_ = lag_rad;
}

void SimLineScanner::MakeLine(const Eigen::Isometry3d& T_world_laser, sensors::LaserLine& line) {
  const bool mixed = model_.config().mixed_pixels;
  const bool incidence = model_.config().UsesIncidence();
  CastBeams(T_world_laser);
  // Reading i is in sweep i mod sweeps_ (sensors::InterlacedSweeps); sweep k is cast k lags down.
  if (sweep_lag_rad_ > 0.0 && sweeps_ >= 2) {
    line_ranges_ = ranges_, line_lo_ = edge_lo_, line_hi_ = edge_hi_, line_cos_ = cos_incidence_;
    for (int k = 1; k < sweeps_; ++k) {
      // Further down: about the laser's y, which points left (REP-103), nose down is positive.
      CastBeams(T_world_laser * Eigen::AngleAxisd(k * sweep_lag_rad_, Eigen::Vector3d::UnitY()));
      for (std::size_t i = static_cast<std::size_t>(k); i < ranges_.size(); i += sweeps_) {
        line_ranges_[i] = ranges_[i];
        if (mixed) line_lo_[i] = edge_lo_[i], line_hi_[i] = edge_hi_[i];
        if (incidence) line_cos_[i] = cos_incidence_[i];
      }
    }
    ranges_.swap(line_ranges_), edge_lo_.swap(line_lo_), edge_hi_.swap(line_hi_);
    cos_incidence_.swap(line_cos_);
  }
  model_.Measure(ranges_.data(), mixed ? edge_lo_.data() : nullptr,
                 mixed ? edge_hi_.data() : nullptr, line,
                 incidence ? cos_incidence_.data() : nullptr);
}

SimLineScanner::~SimLineScanner() = default;

// The casting thread pays where the caster needs no Refresh between lines and a second core runs
// it: a line's rays took as long as its physics (terrain seed 1: 0.86 s of casting, 0.46 s of
// stepping through lines and 0.46 s of the axis's moves between them). Measured over eight runs
// each: the scan waits 0.72 -> 0.28 s for casting, its physics, sharing the cores, 0.76 -> 0.91 s
// (benchmarks/README.md, session 31).
void SimLineScanner::BeginSweep() {
  in_sweep_ = false;
  if (!caster_.Static() || sensors::AllowedCores() < 2) return;
  if (!worker_) worker_ = std::make_unique<SerialWorker>();
  swept_.clear();
  sweep_cpu0_s_ = worker_->cpu_s();
  in_sweep_ = true;
}

void SimLineScanner::EndSweep(std::vector<sensors::LaserLine>* lines) {
  if (!in_sweep_) return;
  in_sweep_ = false;
  const sensors::Stopwatch watch;  // the wait: the casting the physics did not hide
  std::exception_ptr failure;
  try {
    worker_->Wait();
  } catch (...) {
    failure = std::current_exception();
  }
  line_time_ += {watch.Read().wall_s, worker_->cpu_s() - sweep_cpu0_s_};
  if (failure) {
    swept_.clear();
    if (lines) std::rethrow_exception(failure);
    return;  // a failed scan's lines are dropped, and so is what went wrong making them
  }
  if (lines) {
    if (lines->size() != swept_.size()) {
      throw std::logic_error("SimLineScanner::EndSweep: " + std::to_string(lines->size()) +
                             " lines given for a sweep of " + std::to_string(swept_.size()));
    }
    for (std::size_t i = 0; i < swept_.size(); ++i) {
      sensors::LaserLine& line = (*lines)[i];
      swept_[i].stamp_s = line.stamp_s;
      swept_[i].pitch_rad = line.pitch_rad;
      line = std::move(swept_[i]);
    }
  }
  swept_.clear();
}

Result<sensors::LaserLine> SimLineScanner::NextLine(std::chrono::milliseconds timeout) {
  const double period_s = model_.line_period_s();
  if (period_s > timeout.count() / 1000.0) {
    return Fail(Error::Code::kTimeout, "a line takes " + std::to_string(period_s * 1000.0) +
                                           " ms, more than the " + std::to_string(timeout.count()) +
                                           " ms timeout");
  }
  sensors::LaserLine line;
  if (in_sweep_) {
    // Posted, not waited for: the worker casts while the physics below steps on.
    const Eigen::Isometry3d T_world_laser = sim_.T_world_laser();
    worker_->Post([this, T_world_laser] {
      sensors::LaserLine& made = swept_.emplace_back();
      MakeLine(T_world_laser, made);
    });
  } else {
    const sensors::ScopedTime timing(line_time_);
    caster_.Refresh();
    MakeLine(sim_.T_world_laser(), line);
  }
  line.stamp_s = sim_.time_s();
  line.pitch_rad = 0.0;  // the caller fills it from the encoder
  sim_.StepFor(period_s);
  return line;
}

}  // namespace pitchlab::sim
