#include "free_space_check.hpp"

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

}  // namespace pitchlab::mapping
