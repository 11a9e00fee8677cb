#pragma once
// The median of a sample, the upper one of an even count: what the mission's fits and scores
// report (one definition, so that two figures of a run agree).

#include <algorithm>
#include <cstddef>
#include <vector>

namespace pitchlab::mission {

/// The median of `v` (taken by value: reordered), the upper one of an even count; `v` must not be
/// empty.
inline double UpperMedian(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace pitchlab::mission
