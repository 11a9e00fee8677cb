#include "free_space_check.hpp"

#include <cmath>
#include <sstream>

namespace pitchlab::mapping {
namespace {
// Whether `points`, placed by `T` into the seen scan's frame, violate its free space enough: at
// least kRefuted of them, and kRefutedOverAt times as many as placed by `at` (counted once).
bool RefutedBy(const LazySeenSpace& seen, const PointCloud& points, const Eigen::Isometry3d& T,
               const Eigen::Isometry3d& at, std::optional<int>& at_violations) {
  if (points.empty()) return false;
  const SeenSpace& space = seen.Get();
  if (!at_violations) at_violations = space.Violations(points, at);
  const int v = space.Violations(points, T);
  return v >= kRefuted * static_cast<double>(points.size()) && v >= kRefutedOverAt * *at_violations;
}
}  // namespace

bool FreeSpaceCheck::Refutes(const Eigen::Isometry3d& T_target_source) {
  if (target_seen_ && RefutedBy(*target_seen_, source_, T_target_source, at_, source_at_)) {
    return true;
  }
  return source_seen_ &&
         RefutedBy(*source_seen_, target_, T_target_source.inverse(), at_inverse_, target_at_);
}

RegistrationResult::FreeSpace FreeSpaceAt(const LazySeenSpace* target_seen,
                                          const PointCloud& source,
                                          const LazySeenSpace* source_seen,
                                          const PointCloud& target,
                                          const Eigen::Isometry3d& T_target_source) {
  const auto share = [](const SeenSpace::Tally& t) {
    return t.judged > 0 ? static_cast<double>(t.violations) / t.judged : 0.0;
  };
  RegistrationResult::FreeSpace out;
  if (target_seen && !source.empty()) {
    const SeenSpace::Tally t = target_seen->Get().Count(source, T_target_source);
    out.source_judged = t.judged;
    out.source_violating = share(t);
  }
  if (source_seen && !target.empty()) {
    const SeenSpace::Tally t = source_seen->Get().Count(target, T_target_source.inverse());
    out.target_judged = t.judged;
    out.target_violating = share(t);
  }
  return out;
}

std::string FreeSpaceRefutation(const RegistrationResult::FreeSpace& at, std::size_t source_points,
                                std::size_t target_points) {
  const auto refuted = [](double share, int judged, std::size_t points) {
    return share > kChangedViewShare &&
           std::lround(share * judged) >= kRefuted * static_cast<double>(points);
  };
  const bool source = refuted(at.source_violating, at.source_judged, source_points);
  if (!source && !refuted(at.target_violating, at.target_judged, target_points)) return {};
  std::ostringstream os;
  os.precision(3);
  os << "free space: " << 100 * (source ? at.source_violating : at.target_violating) << " % of the "
     << (source ? "source's" : "target's") << " points the " << (source ? "target's" : "source's")
     << " scan could judge lie where its beams passed (limit " << 100 * kChangedViewShare
     << " %): a wrong pose, or a scene that changed between the scans";
  return os.str();
}

}  // namespace pitchlab::mapping
