#include "maplight/nnls.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dynbench::maplight {

namespace {
// Solves G[P,P] z = h[P] by Cholesky with a tiny ridge for rank-deficient sets (columns that are
// numerically equal); false when the block is not positive definite even so.
bool solvePassive(const std::vector<double>& gram, const std::vector<double>& atb, std::size_t n, const std::vector<std::size_t>& passive,
                  std::vector<double>& z) {
  const std::size_t m = passive.size();
  std::vector<double> l(m * m, 0.0);
  double scale = 0.0;
  for (std::size_t i = 0; i < m; ++i) scale = std::max(scale, gram[passive[i] * n + passive[i]]);
  const double ridge = scale * 1e-12;
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j <= i; ++j) {
      double s = gram[passive[i] * n + passive[j]] + (i == j ? ridge : 0.0);
      for (std::size_t k = 0; k < j; ++k) s -= l[i * m + k] * l[j * m + k];
      if (i == j) {
        if (!(s > 0.0)) return false;
        l[i * m + i] = std::sqrt(s);
      } else {
        l[i * m + j] = s / l[j * m + j];
      }
    }
  z.assign(m, 0.0);
  for (std::size_t i = 0; i < m; ++i) {  // L y = h
    double s = atb[passive[i]];
    for (std::size_t k = 0; k < i; ++k) s -= l[i * m + k] * z[k];
    z[i] = s / l[i * m + i];
  }
  for (std::size_t i = m; i-- > 0;) {  // L^T z = y
    double s = z[i];
    for (std::size_t k = i + 1; k < m; ++k) s -= l[k * m + i] * z[k];
    z[i] = s / l[i * m + i];
  }
  return true;
}
}  // namespace

NnlsResult nnls(const std::vector<double>& gram, const std::vector<double>& atb, int maxIterations) {
  const std::size_t n = atb.size();
  NnlsResult result;
  result.x.assign(n, 0.0);
  if (maxIterations <= 0) maxIterations = static_cast<int>(3 * n + 30);
  std::vector<char> isPassive(n, 0);
  double scale = 0.0;
  for (std::size_t i = 0; i < n; ++i) scale = std::max(scale, std::abs(atb[i]));
  const double tolerance = 1e-12 * std::max(scale, 1e-300) * static_cast<double>(std::max<std::size_t>(n, 1));
  std::vector<double> w(n), z;
  while (result.iterations < maxIterations) {
    // the gradient's negative: w = A^T (b - A x)
    for (std::size_t i = 0; i < n; ++i) {
      double s = atb[i];
      for (std::size_t j = 0; j < n; ++j) s -= gram[i * n + j] * result.x[j];
      w[i] = s;
    }
    std::size_t best = n;
    for (std::size_t i = 0; i < n; ++i)
      if (!isPassive[i] && gram[i * n + i] > 0.0 && w[i] > tolerance && (best == n || w[i] > w[best])) best = i;
    if (best == n) {
      result.converged = true;
      return result;
    }
    isPassive[best] = 1;
    for (;;) {
      ++result.iterations;
      std::vector<std::size_t> passive;
      for (std::size_t i = 0; i < n; ++i)
        if (isPassive[i]) passive.push_back(i);
      if (!solvePassive(gram, atb, n, passive, z)) {
        isPassive[best] = 0;  // a column dependent on the set: leave it out
        result.converged = true;
        return result;
      }
      if (std::all_of(z.begin(), z.end(), [](double v) { return v > 0.0; })) {
        std::fill(result.x.begin(), result.x.end(), 0.0);
        for (std::size_t k = 0; k < passive.size(); ++k) result.x[passive[k]] = z[k];
        break;
      }
      // step from x towards z until the first passive variable reaches 0; it leaves the set
      double alpha = std::numeric_limits<double>::max();
      for (std::size_t k = 0; k < passive.size(); ++k)
        if (z[k] <= 0.0) alpha = std::min(alpha, result.x[passive[k]] / (result.x[passive[k]] - z[k]));
      for (std::size_t k = 0; k < passive.size(); ++k) {
        double& x = result.x[passive[k]];
        x += alpha * (z[k] - x);
        if (x <= 1e-15 * std::max(1.0, std::abs(z[k]))) {
          x = 0.0;
          isPassive[passive[k]] = 0;
        }
      }
      if (result.iterations >= maxIterations) return result;
    }
  }
  return result;
}

}  // namespace dynbench::maplight
