#pragma once
// Whether a difficulty measure predicts a method's error over a suite's datasets: Spearman's rank
// correlation with a bootstrap interval (issue 37, docs/suite.md). Written here rather than taken
// from a library: Debian's C++ statistics libraries (GSL's gsl_stats_spearman) give the
// coefficient but no resampling, and the bootstrap has to resample pairs with their ties, which is
// a dozen lines over the same ranking.
#include <cstdint>
#include <optional>
#include <vector>

namespace dynbench::metrics {

// The ranks of `values` (1 = smallest), ties getting the mean of the ranks they span.
std::vector<double> ranks(const std::vector<double>& values);

// Spearman's rho: Pearson's correlation of the two samples' ranks (ties at mean ranks), in
// [-1, 1]. nullopt for fewer than 3 pairs, different lengths, or a sample whose values are all
// equal (no ranking).
std::optional<double> spearman(const std::vector<double>& x, const std::vector<double>& y);

struct RankCorrelation {
  std::optional<double> rho;              // over all pairs
  std::optional<double> low, high;        // the bootstrap percentile interval
  int resamples = 0;                      // resamples whose rho was defined
};
// rho and its percentile bootstrap interval at `level` (0.95: the 2.5th and 97.5th percentiles of
// rho over `resamples` resamplings of the n pairs with replacement; Efron & Tibshirani 1993,
// ch. 13). Resamples with an undefined rho (every x or every y equal) are left out. Seeded, so the
// same inputs give the same interval.
RankCorrelation rankCorrelation(const std::vector<double>& x, const std::vector<double>& y, int resamples = 2000, double level = 0.95,
                                std::uint64_t seed = 1);

// The one-sided sign test: the probability of at least `successes` of `trials` fair coin flips,
// P(X >= k) for X ~ Binomial(n, 1/2) (Conover 1999, §3.4). Exact: a sum of binomial coefficients
// over 2^n (n <= 1000). Written here for the same reason as the rest of this file.
double signTestOneSided(int successes, int trials);

}  // namespace dynbench::metrics
