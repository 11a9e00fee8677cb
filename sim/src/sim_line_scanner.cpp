#include "pitchlab/sim/sim_line_scanner.hpp"

#include <cmath>

namespace pitchlab::sim {

SimLineScanner::SimLineScanner(Simulation& sim, sensors::RayCaster& caster,
                               const sensors::Lms200Config& config)
    : sim_(sim), caster_(caster), model_(config) {}

float SimLineScanner::cast_range_m() const {
  return static_cast<float>(model_.max_range_m() * 1.05);
}

// One ray per beam: direction = R_world_laser [cos(theta + offset), sin(theta + offset), 0], tipped
// out of the scan plane by `tip_rad` (towards the laser's +z).
void SimLineScanner::CastAt(const Eigen::Isometry3d& T_world_laser, double offset_rad,
                            std::vector<float>& out, double tip_rad) {
  const int n = model_.readings();
  origins_.resize(3 * n);
  directions_.resize(3 * n);
  out.resize(n);
  const Eigen::Vector3d o = T_world_laser.translation();
  for (int i = 0; i < n; ++i) {
    const double theta = model_.angle_min_rad() + i * model_.angle_increment_rad() + offset_rad;
    const Eigen::Vector3d d =
        T_world_laser.linear() * Eigen::Vector3d(std::cos(tip_rad) * std::cos(theta),
                                                 std::cos(tip_rad) * std::sin(theta),
                                                 std::sin(tip_rad));
    for (int k = 0; k < 3; ++k) {
      origins_[3 * i + k] = static_cast<float>(o[k]);
      directions_[3 * i + k] = static_cast<float>(d[k]);
    }
  }
  caster_.Cast(origins_.data(), directions_.data(), n, cast_range_m(), out.data(), nullptr);
}

// The surface normal at each beam's hit from two more rays a tenth of a beam step away, one along
// the scan line and one across it: the three hits span the surface. A tenth of a step keeps all
// three on one surface except within a tenth of a step of an edge (the ray caster reports no
// normal, so the hit points must give it). A beam whose neighbours missed counts as meeting its
// surface head on.
void SimLineScanner::CastIncidence(const Eigen::Isometry3d& T_world_laser) {
  const int n = model_.readings();
  const double delta = 0.1 * model_.angle_increment_rad();
  CastAt(T_world_laser, delta, along_);
  CastAt(T_world_laser, 0.0, across_, delta);
  cos_incidence_.assign(n, 1.0f);
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(ranges_[i]) || !std::isfinite(along_[i]) || !std::isfinite(across_[i])) {
      continue;
    }
    const double theta = model_.angle_min_rad() + i * model_.angle_increment_rad();
    // In the laser frame (the incidence does not depend on the frame).
    const Eigen::Vector3d d0(std::cos(theta), std::sin(theta), 0.0);
    const Eigen::Vector3d d1(std::cos(theta + delta), std::sin(theta + delta), 0.0);
    const Eigen::Vector3d d2(std::cos(delta) * std::cos(theta), std::cos(delta) * std::sin(theta),
                             std::sin(delta));
    const Eigen::Vector3d p0 = ranges_[i] * d0;
    const Eigen::Vector3d normal = (along_[i] * d1 - p0).cross(across_[i] * d2 - p0);
    if (normal.norm() <= 0.0) continue;
    cos_incidence_[i] = static_cast<float>(std::abs(normal.normalized().dot(d0)));
  }
}

Result<sensors::LaserLine> SimLineScanner::NextLine(std::chrono::milliseconds timeout) {
  const double period_s = model_.line_period_s();
  if (period_s > timeout.count() / 1000.0) {
    return Fail(Error::Code::kTimeout, "a line takes " + std::to_string(period_s * 1000.0) +
                                           " ms, more than the " + std::to_string(timeout.count()) +
                                           " ms timeout");
  }
  sensors::LaserLine line;
  {
    const sensors::ScopedTime timing(line_time_);
    caster_.Refresh();
    const Eigen::Isometry3d T_world_laser = sim_.T_world_laser();
    CastAt(T_world_laser, 0.0, ranges_);
    const bool mixed = model_.config().mixed_pixels;
    if (mixed) {
      const double half_div = 0.5 * model_.config().beam_divergence_deg * M_PI / 180.0;
      CastAt(T_world_laser, -half_div, edge_lo_);
      CastAt(T_world_laser, +half_div, edge_hi_);
    }
    const bool incidence = model_.config().UsesIncidence();
    if (incidence) CastIncidence(T_world_laser);
    model_.Measure(ranges_.data(), mixed ? edge_lo_.data() : nullptr,
                   mixed ? edge_hi_.data() : nullptr, line,
                   incidence ? cos_incidence_.data() : nullptr);
  }
  line.stamp_s = sim_.time_s();
  line.pitch_rad = 0.0;  // the caller fills it from the encoder
  sim_.StepFor(period_s);
  return line;
}

}  // namespace pitchlab::sim
