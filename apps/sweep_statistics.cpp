#include "sweep_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

namespace pitchlab::apps {
namespace {

// The median of `values` in place (reordered).
double MedianInPlace(std::vector<double>& values) {
  const std::size_t n = values.size();
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (n % 2) return *mid;
  const double upper = *mid;
  return 0.5 * (*std::max_element(values.begin(), mid) + upper);
}

// The q-quantile of sorted `v` by linear interpolation between order statistics.
double Quantile(const std::vector<double>& v, double q) {
  const double at = q * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(at));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (at - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

// log C(n, k).
double LogChoose(int n, int k) {
  return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0);
}

}  // namespace

double Median(std::vector<double> values) { return MedianInPlace(values); }

MedianChange CompareMedians(const std::vector<double>& a, const std::vector<double>& b,
                            int resamples, std::uint64_t seed) {
  if (a.empty() || b.empty()) {
    throw std::invalid_argument("CompareMedians: both sides need at least one value");
  }
  if (resamples < 1) throw std::invalid_argument("CompareMedians: resamples must be >= 1");
  MedianChange m;
  m.median_a = Median(a);
  m.median_b = Median(b);
  m.change = m.median_b - m.median_a;
  std::mt19937_64 rng(seed);
  std::vector<double> ra(a.size()), rb(b.size());
  std::vector<double> changes(static_cast<std::size_t>(resamples));
  std::uniform_int_distribution<std::size_t> pick_a(0, a.size() - 1), pick_b(0, b.size() - 1);
  for (double& c : changes) {
    for (double& x : ra) x = a[pick_a(rng)];
    for (double& x : rb) x = b[pick_b(rng)];
    c = MedianInPlace(rb) - MedianInPlace(ra);
  }
  std::sort(changes.begin(), changes.end());
  m.low = Quantile(changes, 0.025);
  m.high = Quantile(changes, 0.975);
  // Relabellings: the pooled runs shuffled, the first a.size() called a. A change equal to the
  // observed one up to rounding counts as reaching it (identical sides give p = 1).
  std::vector<double> pooled(a);
  pooled.insert(pooled.end(), b.begin(), b.end());
  const double observed = std::abs(m.change) * (1 - 1e-12);
  int reached = 0;
  for (int r = 0; r < resamples; ++r) {
    std::shuffle(pooled.begin(), pooled.end(), rng);
    ra.assign(pooled.begin(), pooled.begin() + static_cast<std::ptrdiff_t>(a.size()));
    rb.assign(pooled.begin() + static_cast<std::ptrdiff_t>(a.size()), pooled.end());
    reached += std::abs(MedianInPlace(rb) - MedianInPlace(ra)) >= observed;
  }
  m.p_value = (reached + 1.0) / (resamples + 1.0);
  return m;
}

double FisherExactTwoSided(int a_ok, int a_n, int b_ok, int b_n) {
  if (a_n < 0 || b_n < 0 || a_ok < 0 || b_ok < 0 || a_ok > a_n || b_ok > b_n) {
    throw std::invalid_argument("FisherExactTwoSided: counts " + std::to_string(a_ok) + "/" +
                                std::to_string(a_n) + " and " + std::to_string(b_ok) + "/" +
                                std::to_string(b_n) + " are not 0 <= ok <= n");
  }
  const int n = a_n + b_n, ok = a_ok + b_ok;
  // P(a_ok = k) with the margins fixed: hypergeometric.
  const auto log_p = [&](int k) {
    return LogChoose(a_n, k) + LogChoose(b_n, ok - k) - LogChoose(n, ok);
  };
  const double observed = log_p(a_ok);
  double p = 0;
  for (int k = std::max(0, ok - b_n); k <= std::min(a_n, ok); ++k) {
    const double lk = log_p(k);
    // Tables as likely as the observed one up to rounding count with it.
    if (lk <= observed + 1e-7) p += std::exp(lk);
  }
  return std::min(1.0, p);
}

}  // namespace pitchlab::apps
