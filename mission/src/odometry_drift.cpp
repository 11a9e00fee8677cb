#include "pitchlab/mission/odometry_drift.hpp"

#include <algorithm>
#include <cmath>

namespace pitchlab::mission {

OdometryDrift MeasureOdometryDrift(const std::vector<StopRecord>& stops) {
  std::vector<double> per_m;
  for (const StopRecord& s : stops) {
    if (s.index == 0 || !s.merge.merged || s.driven_m < kMinDriftDrive_m) continue;
    const Eigen::Vector3d off = s.T_world_base.translation() - s.T_world_base_odom.translation();
    per_m.push_back(off.head<2>().norm() / s.driven_m);
  }
  OdometryDrift d;
  d.drives = per_m.size();
  if (per_m.empty()) return d;
  std::sort(per_m.begin(), per_m.end());
  const auto rank = [&](double q) {  // nearest rank: the smallest value with q of them at or below
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(per_m.size())));
    return per_m[std::max<std::size_t>(k, 1) - 1];
  };
  d.median_per_m = rank(0.5);
  d.p90_per_m = rank(0.9);
  d.max_per_m = per_m.back();
  return d;
}

}  // namespace pitchlab::mission
