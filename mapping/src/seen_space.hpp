#pragma once
// What one scan saw through: its range image about the sensor. A point that another scan, placed
// by some pose, puts nearer the sensor than the surface this scan saw in that direction lies in
// space this scan's beams crossed: a free-space violation (Huber and Hebert, "Fully automatic
// registration of multiple 3D data sets", 2003). The pose that put it there is wrong, however
// well the rest fits; registration asks this where fits cannot decide.

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"

namespace pitchlab::mapping {

class SeenSpace {
 public:
  /// The range image of `scan` (one scan, in its own frame) about `sensor` [m], in bins of
  /// `bin_deg` of azimuth and elevation.
  SeenSpace(const PointCloud& scan, const Eigen::Vector3f& sensor, double bin_deg);

  /// How many points of `cloud`, placed by `T_scan_cloud`, lie in space the scan saw through: at
  /// least kMinRange_m from the sensor and nearer than every return of their bin and its eight
  /// neighbours by more than kMargin_m + kMarginFraction x their range. A bin without a return
  /// (outside the field of view, no echo) says nothing, nor does any bin next to one.
  int Violations(const PointCloud& cloud, const Eigen::Isometry3d& T_scan_cloud) const;

  /// Nearer, the pitching mirror's offset from `sensor` (up to 9 cm) turns a ray by more than a
  /// bin.
  static constexpr float kMinRange_m = 1.5f;
  /// Noise, the mirror's offset along the ray, and a surface's depth across a bin at a glance.
  static constexpr float kMargin_m = 0.1f;
  static constexpr float kMarginFraction = 0.03f;

 private:
  /// The bin of direction `d` (row: elevation, col: azimuth); false for a zero or non-finite `d`.
  bool Bin(const Eigen::Vector3f& d, int& row, int& col) const;

  Eigen::Vector3f sensor_;
  float bin_rad_;
  int rows_, cols_;
  std::vector<float> nearest_;  // per bin, the nearest return's range [m]; +inf: none
};

/// A SeenSpace built at the first ask and kept: most registrations never need one, a few ask
/// several times (the feature winner's probes, then a guess's).
class LazySeenSpace {
 public:
  LazySeenSpace(const PointCloud& scan, const Eigen::Vector3f& sensor, double bin_deg)
      : scan_(scan), sensor_(sensor), bin_deg_(bin_deg) {}
  const SeenSpace& Get() const {
    if (!built_) built_.emplace(scan_, sensor_, bin_deg_);
    return *built_;
  }

 private:
  const PointCloud& scan_;
  Eigen::Vector3f sensor_;
  double bin_deg_;
  mutable std::optional<SeenSpace> built_;
};

}  // namespace pitchlab::mapping
