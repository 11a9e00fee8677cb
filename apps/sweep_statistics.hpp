#pragma once
// Whether two sweeps differ: the change of a metric's median between two sets of runs, with a
// bootstrap interval and a permutation test, and Fisher's exact test for success counts. A sweep
// of one world shares its start and goal, so a code change moves every route: runs of the same
// seed are not pairs, and a median's change means something only against what resampling the
// same runs gives (benchmarks/README.md, "Session 28").

#include <cstdint>
#include <vector>

namespace pitchlab::apps {

/// The median (the mean of the two middle values of an even count), as the bench table reports;
/// NaN for no values.
double Median(std::vector<double> values);

/// How the median of `b` differs from that of `a`.
struct MedianChange {
  double median_a = 0, median_b = 0;
  double change = 0;         ///< median_b - median_a
  double low = 0, high = 0;  ///< 95 % percentile bootstrap interval of the change
  double p_value = 1;        ///< two-sided permutation test of the change (no difference)
};

/// Draws `resamples` bootstrap pairs (each side resampled with replacement on its own) and as
/// many random relabellings of the pooled runs, from a generator seeded with `seed`: the same
/// inputs give the same answer. The p-value counts relabellings whose |change| reaches the
/// observed one, (count + 1) / (resamples + 1), so it is never 0. Throws std::invalid_argument
/// when either side is empty or resamples < 1.
MedianChange CompareMedians(const std::vector<double>& a, const std::vector<double>& b,
                            int resamples = 10000, std::uint64_t seed = 1);

/// Two-sided Fisher exact test of success counts (`a_ok` of `a_n` runs against `b_ok` of `b_n`):
/// the probability, with both margins fixed, of tables no more likely than the one observed.
/// Throws std::invalid_argument on counts outside 0 <= ok <= n.
double FisherExactTwoSided(int a_ok, int a_n, int b_ok, int b_n);

}  // namespace pitchlab::apps
