#include "metrics/rank_correlation.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace dynbench::metrics {

std::vector<double> ranks(const std::vector<double>& values) {
  const std::size_t n = values.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return values[a] < values[b]; });
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    while (j + 1 < n && values[order[j + 1]] == values[order[i]]) ++j;
    const double mean = 0.5 * static_cast<double>(i + j) + 1.0;  // ranks i+1 .. j+1
    for (std::size_t k = i; k <= j; ++k) r[order[k]] = mean;
    i = j + 1;
  }
  return r;
}

std::optional<double> spearman(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.size() < 3) return std::nullopt;
  const std::vector<double> rx = ranks(x), ry = ranks(y);
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(rx.begin(), rx.end(), 0.0) / n, my = std::accumulate(ry.begin(), ry.end(), 0.0) / n;
  double sxy = 0, sxx = 0, syy = 0;
  for (std::size_t i = 0; i < rx.size(); ++i) {
    sxy += (rx[i] - mx) * (ry[i] - my);
    sxx += (rx[i] - mx) * (rx[i] - mx);
    syy += (ry[i] - my) * (ry[i] - my);
  }
  if (sxx <= 0 || syy <= 0) return std::nullopt;
  return std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
}

RankCorrelation rankCorrelation(const std::vector<double>& x, const std::vector<double>& y, int resamples, double level, std::uint64_t seed) {
  RankCorrelation result;
  result.rho = spearman(x, y);
  if (!result.rho || resamples < 1) return result;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, x.size() - 1);
  std::vector<double> rhos, bx(x.size()), by(y.size());
  rhos.reserve(static_cast<std::size_t>(resamples));
  for (int r = 0; r < resamples; ++r) {
    for (std::size_t i = 0; i < x.size(); ++i) {
      const std::size_t k = pick(rng);
      bx[i] = x[k], by[i] = y[k];
    }
    if (auto rho = spearman(bx, by)) rhos.push_back(*rho);
  }
  result.resamples = static_cast<int>(rhos.size());
  if (rhos.empty()) return result;
  std::sort(rhos.begin(), rhos.end());
  // Percentile p of the sorted resamples, interpolated linearly between order statistics.
  auto percentile = [&](double p) {
    const double at = p * static_cast<double>(rhos.size() - 1);
    const auto k = static_cast<std::size_t>(std::floor(at));
    const double t = at - static_cast<double>(k);
    return k + 1 < rhos.size() ? rhos[k] + t * (rhos[k + 1] - rhos[k]) : rhos[k];
  };
  result.low = percentile(0.5 * (1.0 - level));
  result.high = percentile(1.0 - 0.5 * (1.0 - level));
  return result;
}

double signTestOneSided(int successes, int trials) {
  if (trials <= 0 || successes <= 0) return 1.0;
  if (successes > trials) return 0.0;
  // In logs: C(n, k) / 2^n underflows nothing for n <= 1000.
  double p = 0.0;
  for (int k = successes; k <= trials; ++k)
    p += std::exp(std::lgamma(trials + 1.0) - std::lgamma(k + 1.0) - std::lgamma(trials - k + 1.0) - trials * std::log(2.0));
  return std::min(1.0, p);
}

}  // namespace dynbench::metrics
