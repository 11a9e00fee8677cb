#include "pitchlab/sim/sim_line_scanner.hpp"

#include <cmath>

namespace pitchlab::sim {

SimLineScanner::SimLineScanner(Simulation& sim, sensors::RayCaster& caster,
                               const sensors::Lms200Config& config)
    : sim_(sim), caster_(caster), model_(config) {}

float SimLineScanner::cast_range_m() const {
  return static_cast<float>(model_.max_range_m() * 1.05);
}

// One ray per beam: direction = R_world_laser [cos(theta + offset), sin(theta + offset), 0].
void SimLineScanner::CastAt(const Eigen::Isometry3d& T_world_laser, double offset_rad,
                            std::vector<float>& out) {
  const int n = model_.readings();
  origins_.resize(3 * n);
  directions_.resize(3 * n);
  out.resize(n);
  const Eigen::Vector3d o = T_world_laser.translation();
  for (int i = 0; i < n; ++i) {
    const double theta = model_.angle_min_rad() + i * model_.angle_increment_rad() + offset_rad;
    const Eigen::Vector3d d =
        T_world_laser.linear() * Eigen::Vector3d(std::cos(theta), std::sin(theta), 0.0);
    for (int k = 0; k < 3; ++k) {
      origins_[3 * i + k] = static_cast<float>(o[k]);
      directions_[3 * i + k] = static_cast<float>(d[k]);
    }
  }
  caster_.Cast(origins_.data(), directions_.data(), n, cast_range_m(), out.data(), nullptr);
}

Result<sensors::LaserLine> SimLineScanner::NextLine(std::chrono::milliseconds timeout) {
  const double period_s = model_.line_period_s();
  if (period_s > timeout.count() / 1000.0) {
    return Fail(Error::Code::kTimeout, "a line takes " + std::to_string(period_s * 1000.0) +
                                           " ms, more than the " + std::to_string(timeout.count()) +
                                           " ms timeout");
  }
  caster_.Refresh();
  const Eigen::Isometry3d T_world_laser = sim_.T_world_laser();
  sensors::LaserLine line;
  line.stamp_s = sim_.time_s();
  CastAt(T_world_laser, 0.0, ranges_);
  const bool mixed = model_.config().mixed_pixels;
  if (mixed) {
    const double half_div = 0.5 * model_.config().beam_divergence_deg * M_PI / 180.0;
    CastAt(T_world_laser, -half_div, edge_lo_);
    CastAt(T_world_laser, +half_div, edge_hi_);
  }
  model_.Measure(ranges_.data(), mixed ? edge_lo_.data() : nullptr,
                 mixed ? edge_hi_.data() : nullptr, line);
  line.stamp_s = sim_.time_s();
  line.pitch_rad = 0.0;  // the caller fills it from the encoder
  sim_.StepFor(period_s);
  return line;
}

}  // namespace pitchlab::sim
