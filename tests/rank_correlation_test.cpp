// Spearman's rank correlation and its bootstrap interval (metrics/rank_correlation.h): known answers.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "metrics/rank_correlation.h"

namespace dynbench::metrics {
namespace {

TEST(RankCorrelation, TiesGetTheMeanOfTheirRanks) {
  const auto r = ranks({10, 20, 20, 5, 20});
  ASSERT_EQ(r.size(), 5u);
  EXPECT_DOUBLE_EQ(r[3], 1.0);  // 5 is the smallest
  EXPECT_DOUBLE_EQ(r[0], 2.0);
  EXPECT_DOUBLE_EQ(r[1], 4.0);  // the three 20s share ranks 3, 4, 5
  EXPECT_DOUBLE_EQ(r[2], 4.0);
  EXPECT_DOUBLE_EQ(r[4], 4.0);
}

TEST(RankCorrelation, SpearmanMatchesTheTextbookExample) {
  // IQ against hours of television a week for ten people (the example in Wikipedia's "Spearman's
  // rank correlation coefficient", after Myers & Well): sum of d^2 = 194, rho = 1 - 6 x 194 /
  // (10 x 99) = -29/165.
  const std::vector<double> iq{106, 100, 86, 101, 99, 103, 97, 113, 112, 110}, tv{7, 27, 2, 50, 28, 29, 20, 12, 6, 17};
  const auto rho = spearman(iq, tv);
  ASSERT_TRUE(rho);
  EXPECT_NEAR(*rho, -29.0 / 165.0, 1e-12);
  // Any monotone map of either sample leaves rho as it is; reversing one flips its sign.
  std::vector<double> cubed, negated;
  for (double v : tv) cubed.push_back(v * v * v), negated.push_back(-v);
  EXPECT_NEAR(*spearman(iq, cubed), -29.0 / 165.0, 1e-12);
  EXPECT_NEAR(*spearman(iq, negated), 29.0 / 165.0, 1e-12);
  // With ties, rho is Pearson's of the mean ranks: x ranks (1, 2.5, 2.5, 4), y ranks (1, 2, 3, 4);
  // about their means, sum xy = 4.5, sum xx = 4.5, sum yy = 5: rho = 4.5 / sqrt(22.5) = 3 / sqrt(10).
  EXPECT_NEAR(*spearman({1, 2, 2, 3}, {1, 2, 3, 4}), 3.0 / std::sqrt(10.0), 1e-12);
  // Undefined: too few pairs, unequal lengths, a constant sample.
  EXPECT_FALSE(spearman({1, 2}, {1, 2}));
  EXPECT_FALSE(spearman({1, 2, 3}, {1, 2}));
  EXPECT_FALSE(spearman({1, 2, 3}, {4, 4, 4}));
}

TEST(RankCorrelation, BootstrapIntervalHasTheExpectedWidthAndIsSeeded) {
  // A monotone relation: every resample with two distinct values ranks the same, rho = 1.
  std::vector<double> x, y;
  for (int i = 0; i < 12; ++i) x.push_back(i), y.push_back(std::exp(0.3 * i));
  const auto perfect = rankCorrelation(x, y);
  ASSERT_TRUE(perfect.rho && perfect.low && perfect.high);
  EXPECT_DOUBLE_EQ(*perfect.rho, 1.0);
  EXPECT_DOUBLE_EQ(*perfect.low, 1.0);
  EXPECT_DOUBLE_EQ(*perfect.high, 1.0);
  // Independent samples of 200: rho near 0, and the 95 % interval about 2 x 1.96 / sqrt(199) = 0.28
  // wide (rho's standard error under independence is 1 / sqrt(n - 1)), containing 0.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::vector<double> a, b;
  for (int i = 0; i < 200; ++i) a.push_back(normal(rng)), b.push_back(normal(rng));
  const auto independent = rankCorrelation(a, b);
  ASSERT_TRUE(independent.rho && independent.low && independent.high);
  EXPECT_LT(*independent.low, 0.0);
  EXPECT_GT(*independent.high, 0.0);
  EXPECT_NEAR(*independent.high - *independent.low, 0.28, 0.06);
  EXPECT_EQ(independent.resamples, 2000);
  // The same inputs and seed give the same interval; another seed, a slightly different one.
  const auto again = rankCorrelation(a, b);
  EXPECT_EQ(*again.low, *independent.low);
  EXPECT_EQ(*again.high, *independent.high);
  const auto other = rankCorrelation(a, b, 2000, 0.95, 2);
  EXPECT_NE(*other.low, *independent.low);
  EXPECT_NEAR(*other.low, *independent.low, 0.03);
  // A strong relation with noise: rho high, its interval inside (0, 1] and around it.
  std::vector<double> c;
  for (int i = 0; i < 200; ++i) c.push_back(a[static_cast<std::size_t>(i)] + 0.3 * b[static_cast<std::size_t>(i)]);
  const auto strong = rankCorrelation(a, c);
  EXPECT_GT(*strong.rho, 0.9);
  EXPECT_LT(*strong.low, *strong.rho);
  EXPECT_GT(*strong.high, *strong.rho);
  EXPECT_GT(*strong.low, 0.85);
}

// Known answers: the binomial tail at p = 1/2 by hand (suite v1's within-match counts, docs/suite.md).
TEST(SignTest, OneSidedTailOfAFairCoin) {
  EXPECT_NEAR(signTestOneSided(8, 9), 10.0 / 512.0, 1e-12);   // C(9,8) + C(9,9) over 2^9: 0.0195
  EXPECT_NEAR(signTestOneSided(7, 9), 46.0 / 512.0, 1e-12);   // 36 + 9 + 1: 0.0898
  EXPECT_NEAR(signTestOneSided(9, 9), 1.0 / 512.0, 1e-12);
  EXPECT_NEAR(signTestOneSided(10, 20), 616666.0 / 1048576.0, 1e-12);  // half of 20 flips or more: (2^20 + C(20,10)) / 2^21
  EXPECT_DOUBLE_EQ(signTestOneSided(0, 5), 1.0);
  EXPECT_DOUBLE_EQ(signTestOneSided(6, 5), 0.0);
}

}  // namespace
}  // namespace dynbench::metrics
