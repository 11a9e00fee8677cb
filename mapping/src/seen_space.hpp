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

/// How far in front of the seen surface a point must lie to violate free space.
struct SeenMargins {
  /// Nearer the sensor than this nothing is judged: the pitching mirror's offset from `sensor`
  /// (up to 9 cm on the LMS200 mount) turns a ray by more than a bin there [m].
  float min_range_m = 1.5f;
  /// Noise and the mirror's offset along the ray [m] ...
  float margin_m = 0.1f;
  /// ... plus this fraction of the range: a surface's depth across a bin at a glance [1].
  float margin_fraction = 0.03f;
};

class SeenSpace {
 public:
  /// The range image of `scan` (one scan, in its own frame) about `sensor` [m], in bins of
  /// `bin_deg` of azimuth and elevation.
  SeenSpace(const PointCloud& scan, const Eigen::Vector3f& sensor, double bin_deg,
            const SeenMargins& margins = {});

  /// How many points of `cloud`, placed by `T_scan_cloud`, lie in space the scan saw through: at
  /// least min_range_m from the sensor and nearer than every return of their bin and its eight
  /// neighbours by more than margin_m + margin_fraction x their range. A bin without a return
  /// (outside the field of view, no echo) says nothing, nor does any bin next to one.
  int Violations(const PointCloud& cloud, const Eigen::Isometry3d& T_scan_cloud) const {
    return Count(cloud, T_scan_cloud).violations;
  }

  /// What Violations counts, and how many of the points the scan's view could judge at all (at
  /// least min_range_m away, in a bin whose eight neighbours all hold a return): the share of the
  /// common view a pose contradicts, whatever the overlap.
  struct Tally {
    int violations = 0;
    int judged = 0;
  };
  Tally Count(const PointCloud& cloud, const Eigen::Isometry3d& T_scan_cloud) const;

 private:
  /// The bin of direction `d` (row: elevation, col: azimuth); false for a zero or non-finite `d`.
  bool Bin(const Eigen::Vector3f& d, int& row, int& col) const;

  Eigen::Vector3f sensor_;
  SeenMargins margins_;
  float bin_rad_;
  int rows_, cols_;
  std::vector<float> nearest_;  // per bin, the nearest return's range [m]; +inf: none
};

/// A SeenSpace built at the first ask and kept: most registrations never need one, a few ask
/// several times (the feature winner's probes, then a guess's).
class LazySeenSpace {
 public:
  LazySeenSpace(const PointCloud& scan, const Eigen::Vector3f& sensor, double bin_deg,
                const SeenMargins& margins)
      : scan_(scan), sensor_(sensor), bin_deg_(bin_deg), margins_(margins) {}
  const SeenSpace& Get() const {
    if (!built_) built_.emplace(scan_, sensor_, bin_deg_, margins_);
    return *built_;
  }

 private:
  const PointCloud& scan_;
  Eigen::Vector3f sensor_;
  double bin_deg_;
  SeenMargins margins_;
  mutable std::optional<SeenSpace> built_;
};

}  // namespace pitchlab::mapping
