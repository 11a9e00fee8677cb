#pragma once
// The chi-square distribution's CDF and quantile, for the pose graph's gates (a loop edge's test,
// the loop candidates' bound). Private to mapping.

namespace pitchlab::mapping {

/// P(X <= x) for X chi-square with `dof` degrees of freedom (1 <= dof <= 64, x >= 0) [1].
double ChiSquareCdf(int dof, double x);

/// The x with ChiSquareCdf(dof, x) == probability (1 <= dof <= 64, 0 < probability < 1), to 1e-9
/// relative. Both throw std::invalid_argument on arguments out of range.
double ChiSquareQuantile(int dof, double probability);

}  // namespace pitchlab::mapping
