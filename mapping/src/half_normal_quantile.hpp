#pragma once
// The q-quantile of |x| for x ~ N(0, 1): a robust fit's sigma from a quantile of its distances.

#include <cmath>

namespace pitchlab::mapping {

/// The z with erf(z / sqrt 2) = q, for q in (0, 1) (bisection to double precision).
inline double HalfNormalQuantile(double q) {
  double lo = 0, hi = 10;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (std::erf(mid / std::sqrt(2.0)) < q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace pitchlab::mapping
