#include "pitchlab/mission/loop_closure_metrics.hpp"

#include <map>
#include <stdexcept>
#include <string>

#include "pitchlab/mapping/trajectory_metrics.hpp"

namespace pitchlab::mission {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// The stop whose scan MapBuilder merged as `scan_index`.
const StopRecord& MergedStop(const std::map<std::size_t, const StopRecord*>& by_scan,
                             std::size_t scan_index) {
  const auto it = by_scan.find(scan_index);
  if (it == by_scan.end()) {
    throw std::logic_error("loop closure metrics: no merged stop holds scan " +
                           std::to_string(scan_index));
  }
  return *it->second;
}

}  // namespace

nlohmann::json LoopClosureJson(const MissionResult& result) {
  std::map<std::size_t, const StopRecord*> by_scan;
  for (const StopRecord& s : result.stops) {
    if (s.merge.merged) by_scan[s.merge.scan_index] = &s;
  }
  nlohmann::json edges = nlohmann::json::array();
  std::size_t wrong = 0;
  bool scored = true;
  for (const mapping::LoopClosure& loop : result.loop_closures) {
    const StopRecord& from = MergedStop(by_scan, loop.from_scan_index);
    const StopRecord& to = MergedStop(by_scan, loop.to_scan_index);
    nlohmann::json e = {
        {"from_stop", from.index}, {"to_stop", to.index}, {"chi2_increase", loop.chi2_increase}};
    if (from.T_world_base_true && to.T_world_base_true) {
      const Eigen::Isometry3d T_true = from.T_world_base_true->inverse() * *to.T_world_base_true;
      const Eigen::Isometry3d d = T_true.inverse() * loop.T_from_to;
      const bool is_wrong = mapping::IsWrongLoopClosure(loop.T_from_to, T_true);
      wrong += is_wrong;
      e["translation_error_m"] = d.translation().norm();
      e["rotation_error_deg"] = Eigen::AngleAxisd(d.linear()).angle() * kRadToDeg;
      e["wrong"] = is_wrong;
    } else {
      scored = false;
      e["translation_error_m"] = e["rotation_error_deg"] = e["wrong"] = nullptr;
    }
    edges.push_back(e);
  }
  const mapping::LoopClosureCounts& c = result.loop_counts;
  return {{"registered", c.registered},
          {"registration_failed", c.registration_failed},
          {"accepted", c.accepted},
          {"rejected", c.rejected},
          {"wrong", scored ? nlohmann::json(wrong) : nlohmann::json()},
          {"edges", edges}};
}

}  // namespace pitchlab::mission
