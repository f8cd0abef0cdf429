#pragma once
// Non-negative least squares, min |A x - b|^2 subject to x >= 0, by Lawson and Hanson's active-set
// algorithm (Solving Least Squares Problems, 1974, ch. 23, algorithm NNLS) on the normal equations:
// the light fit keeps A^T A and A^T b for at most a few hundred columns, so the small dense solve
// is written here rather than pulling in a linear-algebra package for one routine (Debian's
// Eigen 3.4 has no NNLS). tests/maplight_test.cpp checks a hand-derived answer and, on random
// problems, the Karush-Kuhn-Tucker conditions that make a solution the optimum.
#include <vector>

namespace dynbench::maplight {

struct NnlsResult {
  std::vector<double> x;
  int iterations = 0;
  bool converged = false;
};

// gram: n x n, row-major (A^T A); atb: A^T b. Columns with a zero diagonal stay 0.
NnlsResult nnls(const std::vector<double>& gram, const std::vector<double>& atb, int maxIterations = 0);

}  // namespace dynbench::maplight
