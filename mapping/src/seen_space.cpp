#include "seen_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pitchlab::mapping {
namespace {
constexpr float kPi = 3.14159265358979323846f;
constexpr float kNone = std::numeric_limits<float>::infinity();
}  // namespace

SeenSpace::SeenSpace(const PointCloud& scan, const Eigen::Vector3f& sensor, double bin_deg,
                     const SeenMargins& margins)
    : sensor_(sensor),
      margins_(margins),
      bin_rad_(static_cast<float>(bin_deg) * kPi / 180.0f),
      rows_(static_cast<int>(std::ceil(kPi / bin_rad_))),
      cols_(static_cast<int>(std::ceil(2 * kPi / bin_rad_))),
      nearest_(static_cast<std::size_t>(rows_) * cols_, kNone) {
  for (const Eigen::Vector3f& p : scan) {
    const Eigen::Vector3f d = p - sensor_;
    int row = 0, col = 0;
    if (!Bin(d, row, col)) continue;
    float& nearest = nearest_[static_cast<std::size_t>(row) * cols_ + col];
    nearest = std::min(nearest, d.norm());
  }
}

bool SeenSpace::Bin(const Eigen::Vector3f& d, int& row, int& col) const {
  const float r = d.norm();
  if (!(r > 0) || !std::isfinite(r)) return false;
  const float elevation = std::asin(std::clamp(d.z() / r, -1.0f, 1.0f)) + 0.5f * kPi;
  const float azimuth = std::atan2(d.y(), d.x()) + kPi;
  row = std::min(rows_ - 1, static_cast<int>(elevation / bin_rad_));
  col = std::min(cols_ - 1, static_cast<int>(azimuth / bin_rad_));
  return true;
}

SeenSpace::Tally SeenSpace::Count(const PointCloud& cloud,
                                  const Eigen::Isometry3d& T_scan_cloud) const {
  const Eigen::Isometry3f T = T_scan_cloud.cast<float>();
  Tally tally;
  for (const Eigen::Vector3f& p : cloud) {
    const Eigen::Vector3f d = T * p - sensor_;
    const float r = d.norm();
    int row = 0, col = 0;
    // The poles' rows have no neighbours above or below: they say nothing.
    if (r < margins_.min_range_m || !Bin(d, row, col) || row == 0 || row == rows_ - 1) continue;
    float nearest = kNone;
    bool seen = true;
    for (int dr = -1; dr <= 1 && seen; ++dr) {
      for (int dc = -1; dc <= 1 && seen; ++dc) {
        const int c = (col + dc + cols_) % cols_;  // azimuth wraps around
        const float n = nearest_[static_cast<std::size_t>(row + dr) * cols_ + c];
        seen = n != kNone;
        nearest = std::min(nearest, n);
      }
    }
    if (!seen) continue;
    ++tally.judged;
    if (r < nearest - margins_.margin_m - margins_.margin_fraction * r) ++tally.violations;
  }
  return tally;
}

}  // namespace pitchlab::mapping
