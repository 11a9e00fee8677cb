#pragma once
// The free-space evidence against poses near an accepted one, from both scans' views. Where fits
// cannot decide between two minima (registration.cpp, Undetermined), a pose that puts one scan's
// points where the other scan's beams passed is wrong, however well the rest fits.

#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "pitchlab/mapping/point_cloud.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "seen_space.hpp"

namespace pitchlab::mapping {

/// A pose is refuted when at least kRefuted of a scan's points lie where the other scan saw
/// through (SeenSpace) and kRefutedOverAt times as many as at `at` (which then is not
/// contradicted). Measured on registration_eval's pairs and the tests' corridor, the target's view
/// of the source: at the truth at most 0.11 % (thin poles and chair legs one scan's beams hit and
/// the other's pass); a street's probes 1 m along either way 1.9 % and 0.8 %; the bare corridor's
/// probes, where one way shows violations (up to 2 %: its far ends), show none the other way.
inline constexpr double kRefuted = 0.005;
inline constexpr int kRefutedOverAt = 10;

/// The free-space evidence at T_target_source, from both views (RegistrationResult::free_space);
/// a null view judges nothing.
RegistrationResult::FreeSpace FreeSpaceAt(const LazySeenSpace* target_seen,
                                          const PointCloud& source,
                                          const LazySeenSpace* source_seen,
                                          const PointCloud& target,
                                          const Eigen::Isometry3d& T_target_source);

/// Why the evidence `at` refutes its pose (kChangedViewShare, registration.hpp; and kRefuted), or
/// empty when it does not; `source_points`, `target_points`: the sizes of the clouds it was
/// counted over.
std::string FreeSpaceRefutation(const RegistrationResult::FreeSpace& at, std::size_t source_points,
                                std::size_t target_points);

class FreeSpaceCheck {
 public:
  /// `target_seen`: what the target's scan saw through, in the target frame, against the
  /// `source` points; `source_seen`: what the source's scan saw through, in the source frame,
  /// against the `target` points placed by the inverse pose. Either may be null (nothing known).
  /// Both ways, as free space is one-sided: a pose carrying the source too far towards a
  /// corridor's seen end puts its end wall behind the target's, where the target saw nothing, but
  /// the target's end wall then stands in front of the source's. registration_eval's terrain pair
  /// 169: the heading probe the target's view did not refute puts 1.2 % of the target's points
  /// (150 of 12094) where the source saw through, none at the feature alignment's winner.
  FreeSpaceCheck(const LazySeenSpace* target_seen, const PointCloud& source,
                 const LazySeenSpace* source_seen, const PointCloud& target,
                 const Eigen::Isometry3d& at)
      : target_seen_(target_seen),
        source_(source),
        source_seen_(source_seen),
        target_(target),
        at_(at),
        at_inverse_(at.inverse()) {}

  /// Whether free space refutes T_target_source, seen from either scan.
  bool Refutes(const Eigen::Isometry3d& T_target_source);

 private:
  const LazySeenSpace* target_seen_;
  const PointCloud& source_;
  const LazySeenSpace* source_seen_;
  const PointCloud& target_;
  Eigen::Isometry3d at_, at_inverse_;  // T_source_target at `at`, for the source's view
  std::optional<int> source_at_, target_at_;  // violations at `at`, counted at the first ask
};

}  // namespace pitchlab::mapping
