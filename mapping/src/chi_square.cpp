#include "chi_square.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {

namespace {

// Regularised lower incomplete gamma P(a, y) by its power series
//   P(a, y) = y^a e^-y / Gamma(a + 1) * sum_n y^n / ((a + 1) ... (a + n)),
// whose terms are all positive (no cancellation). The terms peak near n = y and have fallen below
// double precision within a few times sqrt(y) beyond it: 10000 terms cover y up to ~9000.
double LowerGammaRegularised(double a, double y) {
  if (y <= 0) return 0;
  double term = 1, sum = 1;
  for (int n = 1; n < 10000 && term > 1e-17 * sum; ++n) {
    term *= y / (a + n);
    sum += term;
  }
  const double log_prefactor = a * std::log(y) - y - std::lgamma(a + 1);
  return std::min(1.0, std::exp(log_prefactor) * sum);
}

// The series above sums y = x / 2 up to ~9000, and the quantile's bracket reaches x = 256 dof.
void CheckDof(int dof) {
  if (dof < 1 || dof > 64) {
    throw std::invalid_argument("chi-square: dof = " + std::to_string(dof) + ": must lie in 1..64");
  }
}

}  // namespace

double ChiSquareCdf(int dof, double x) {
  CheckDof(dof);
  if (!(x >= 0)) return 0;
  return LowerGammaRegularised(0.5 * dof, 0.5 * x);
}

double ChiSquareQuantile(int dof, double probability) {
  CheckDof(dof);
  if (!(probability > 0 && probability < 1)) {
    throw std::invalid_argument("chi-square quantile: probability = " +
                                NumberText(probability) + ": must lie in (0, 1)");
  }
  double lo = 0, hi = dof;  // the CDF is increasing: bracket, then bisect
  for (int doublings = 0; ChiSquareCdf(dof, hi) < probability; ++doublings) {
    // hi = 256 dof lies ~180 sqrt(dof) standard deviations above the mean (dof, sd sqrt(2 dof)):
    // no probability short of 1 in double precision needs more.
    if (doublings == 8) {
      throw std::invalid_argument("chi-square quantile: probability = " +
                                  NumberText(probability) + " is too close to 1");
    }
    hi *= 2;
  }
  while (hi - lo > 1e-10 * hi) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareCdf(dof, mid) < probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace pitchlab::mapping
