// The light tree's selection against what it promises: an unbiased estimate of the sum over every
// light (checked exactly, by enumerating every path down the tree, and by sampling), no light that
// can give light ever left out, none that cannot ever selected, and an exact sum (probability 1
// each) where no more lights than the budget can reach the point.
#include <algorithm>
#include <bit>
#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "render/light_tree.h"

namespace dynbench::render {
namespace {

std::vector<LightTree::Light> randomLights(int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> position(-10.0, 10.0), power(0.1, 50.0), range(1.0, 12.0);
  std::vector<LightTree::Light> lights;
  for (int k = 0; k < count; ++k)
    lights.push_back({{position(rng), position(rng), position(rng)}, power(rng), k % 3 == 0 ? 0.0 : range(rng)});
  return lights;
}

// Whether light l can give light at p with normal n (what the renderer would find non-zero).
bool canLight(const LightTree::Light& l, const glm::dvec3& p, const glm::dvec3& n) {
  const glm::dvec3 d = l.position - p;
  if (glm::dot(d, n) <= 0) return false;
  return !(l.range > 0) || glm::dot(d, d) < l.range * l.range;
}

// select() is a deterministic function of u, so the share of a fine grid of u that selects a light
// is its selection probability: it must equal the probability select() reports for it, and be
// non-zero for every light that can give light there.
TEST(LightTree, EveryLightThatCanGiveLightIsSelectedWithItsReportedProbability) {
  const auto lights = randomLights(300, 7);
  LightTree tree;
  tree.build(lights);
  ASSERT_EQ(tree.size(), lights.size());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-8.0, 8.0);
  const int grid = 1 << 16;
  for (int trial = 0; trial < 6; ++trial) {
    const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    const glm::dvec3 n = glm::normalize(glm::dvec3(coordinate(rng), coordinate(rng), coordinate(rng)));
    for (const int budget : {1, 4}) {
      std::map<std::uint32_t, double> measure, reported;
      std::vector<LightTree::Selected> selected;
      for (int k = 0; k < grid; ++k) {
        tree.select(p, n, (k + 0.5) / grid, budget, selected);
        EXPECT_LE(static_cast<int>(selected.size()), budget);
        for (const auto& s : selected) {
          ASSERT_TRUE(canLight(lights[s.light], p, n)) << "light " << s.light << " cannot light the point";
          ASSERT_GT(s.probability, 0.0);
          measure[s.light] += 1.0 / grid;
          reported[s.light] = s.probability;
        }
      }
      int reachable = 0;
      for (std::uint32_t l = 0; l < lights.size(); ++l) {
        if (!canLight(lights[l], p, n)) continue;
        ++reachable;
        // Probabilities far above 1/grid are resolved by the grid; each light must be found.
        ASSERT_TRUE(measure.count(l)) << "light " << l << " can light the point but is never selected (trial " << trial << ")";
        EXPECT_NEAR(measure[l], reported[l], 4.0 / grid + 1e-9) << "light " << l;
      }
      EXPECT_GT(reachable, 5);
    }
  }
}

TEST(LightTree, TheEstimateOfASumOverLightsIsUnbiased) {
  // E[sum over selected of w(l) / p(l)] = sum over lights that can light the point of w(l), for
  // any weights w: here each light's unshadowed irradiance times its range window.
  const auto lights = randomLights(500, 11);
  LightTree tree;
  tree.build(lights);
  const glm::dvec3 p(0.5, -1.0, 2.0), n(0.0, 1.0, 0.0);
  auto weight = [&](const LightTree::Light& l) {
    const glm::dvec3 d = l.position - p;
    const double d2 = glm::dot(d, d);
    double w = l.power * glm::dot(d, n) / std::sqrt(d2) / d2;
    if (l.range > 0) w *= std::max(0.0, 1.0 - (d2 * d2) / std::pow(l.range, 4));
    return w;
  };
  double exact = 0;
  for (const auto& l : lights)
    if (canLight(l, p, n)) exact += weight(l);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (const int budget : {1, 4, 16}) {
    const int samples = 200000;
    double sum = 0, sumSq = 0;
    std::vector<LightTree::Selected> selected;
    for (int k = 0; k < samples; ++k) {
      tree.select(p, n, uniform(rng), budget, selected);
      double estimate = 0;
      for (const auto& s : selected) estimate += weight(lights[s.light]) / s.probability;
      sum += estimate;
      sumSq += estimate * estimate;
    }
    const double mean = sum / samples, standardError = std::sqrt((sumSq / samples - mean * mean) / samples);
    EXPECT_NEAR(mean, exact, 5 * standardError + 1e-12 * exact) << "budget " << budget;
    std::printf("budget %2d: relative standard deviation of one estimate %.3f\n", budget, standardError * std::sqrt(samples) / exact);
  }
}

TEST(LightTree, FewLightsInReachAreAllSelectedWithProbabilityOne) {
  // Nine lights whose range covers the origin, 200 whose range ends before it.
  std::vector<LightTree::Light> lights;
  for (int k = 0; k < 9; ++k) lights.push_back({{std::cos(k) * 2.0, 1.0 + 0.1 * k, std::sin(k) * 2.0}, 1.0 + k, 5.0});
  for (int k = 0; k < 200; ++k) lights.push_back({{20.0 + 0.1 * k, 3.0, -4.0}, 100.0, 3.0});
  LightTree tree;
  tree.build(lights);
  std::vector<LightTree::Selected> selected;
  for (const double u : {0.0, 0.37, 0.999}) {
    tree.select({0, 0, 0}, {0, 1, 0}, u, 9, selected);
    ASSERT_EQ(selected.size(), 9u);
    std::vector<bool> seen(9, false);
    for (const auto& s : selected) {
      ASSERT_LT(s.light, 9u);
      EXPECT_EQ(s.probability, 1.0);
      seen[s.light] = true;
    }
    for (const bool b : seen) EXPECT_TRUE(b);
    // Below the floor (normal pointing down), none of them can light the point.
    tree.select({0, 0, 0}, {0, -1, 0}, u, 9, selected);
    EXPECT_TRUE(selected.empty());
  }
}

TEST(LightTree, ANodeOutOfRangeOrBehindThePlaneHasNoImportanceAndOthersHaveSome) {
  LightTree::Node node;
  node.lower = {4, 0, -1};
  node.upper = {6, 2, 1};
  node.power = 10;
  node.range = 3.0;
  node.count = 2;
  // Nearest point of the box is at distance 4 - 0.5 = 3.5 > 3.
  EXPECT_EQ(LightTree::importance(node, {0.5, 1, 0}, {1, 0, 0}), 0.0);
  EXPECT_GT(LightTree::importance(node, {1.5, 1, 0}, {1, 0, 0}), 0.0);
  // Facing away from the box: every point of it is behind the plane.
  EXPECT_EQ(LightTree::importance(node, {1.5, 1, 0}, {-1, 0, 0}), 0.0);
  // A plane that the box crosses: some of it is above.
  EXPECT_GT(LightTree::importance(node, {5, -1, 0}, {0, 1, 0}), 0.0);
  EXPECT_GT(LightTree::importance(node, {5, 1.9, 0}, {0, -1, 0}), 0.0);
  // One light: its irradiance (power cos / d^2) times its window.
  LightTree::Node leaf;
  leaf.lower = leaf.upper = {0, 2, 0};
  leaf.power = 8;
  leaf.range = 4;
  leaf.count = 1;
  const double d = std::sqrt(2.0 * 2.0 + 1.0), cosine = 2.0 / d, window = 1.0 - std::pow(d / 4.0, 4);
  EXPECT_NEAR(LightTree::importance(leaf, {1, 0, 0}, {0, 1, 0}), 8 * cosine * window / (d * d), 1e-12);
}

// select() as light_tree.h states it, one walk at a time with the scalar importance(): the cut
// (split the most important interior node while the budget holds its children that can light the
// point), then from each node of the cut a walk down by the children's importances (times the
// factors), remapping u at each step. The tree's own select() interleaves its walks and chooses a
// child without a branch; it must select exactly these lights with exactly these probabilities.
std::vector<LightTree::Selected> selectOneWalkAtATime(const LightTree& tree, const glm::dvec3& p, const glm::dvec3& n, double u, int budget,
                                                      const float* factors) {
  const auto nodes = tree.nodes();
  auto weigh = [&](std::uint32_t k) { return LightTree::importance(nodes[k], p, n) * (factors ? factors[k] : 1.0); };
  std::vector<LightTree::Selected> selected;
  if (!(weigh(0) > 0)) return selected;
  std::vector<std::pair<std::uint32_t, double>> cut = {{0u, weigh(0)}};
  while (true) {
    int best = -1;
    for (int k = 0; k < static_cast<int>(cut.size()); ++k)
      if (nodes[cut[k].first].count > 1 && (best < 0 || cut[k].second > cut[best].second)) best = k;
    if (best < 0) break;
    const std::uint32_t a = cut[best].first + 1, b = nodes[cut[best].first].first;
    const double ia = weigh(a), ib = weigh(b);
    if (static_cast<int>(cut.size()) - 1 + (ia > 0) + (ib > 0) > budget) break;
    cut[best] = cut.back();
    cut.pop_back();
    if (ia > 0) cut.push_back({a, ia});
    if (ib > 0) cut.push_back({b, ib});
  }
  for (const auto& [start, weight] : cut) {
    std::uint32_t k = start;
    double v = u, probability = 1.0;
    bool found = true;
    while (nodes[k].count > 1) {
      const std::uint32_t a = k + 1, b = nodes[k].first;
      const double ia = weigh(a), ib = weigh(b);
      if (!(ia + ib > 0)) {
        found = false;
        break;
      }
      const double pa = ia / (ia + ib);
      if (v < pa) {
        v = std::min(v / pa, 1.0 - 0x1p-53), probability *= pa, k = a;
      } else {
        v = std::min((v - pa) / (1.0 - pa), 1.0 - 0x1p-53), probability *= 1.0 - pa, k = b;
      }
    }
    if (found && probability > 0) selected.push_back({nodes[k].first, probability});
  }
  return selected;
}

TEST(LightTree, TheInterleavedWalksSelectWhatOneWalkAtATimeSelectsBitForBit) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> coordinate(-12.0, 12.0), uniform(0.0, 1.0);
  std::uniform_real_distribution<float> factor(0.1f, 1.0f);
  int compared = 0, several = 0;
  for (int trial = 0; trial < 12; ++trial) {
    auto lights = randomLights(50 + 40 * trial, 200 + static_cast<std::uint32_t>(trial));
    lights.push_back(lights[5]);  // coincident lights
    LightTree tree;
    tree.build(lights);
    std::vector<float> factors(tree.nodeCount());
    for (float& f : factors) f = factor(rng);
    std::vector<LightTree::Selected> selected;
    for (int k = 0; k < 300; ++k) {
      const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
      const glm::dvec3 n = k % 5 == 0 ? glm::dvec3(0, 1, 0) : glm::normalize(glm::dvec3(coordinate(rng), coordinate(rng), coordinate(rng)));
      const double u = k % 11 == 0 ? 0.0 : uniform(rng);
      const int budget = 1 + k % 8;
      const float* weights = k % 2 ? factors.data() : nullptr;
      tree.select(p, n, u, budget, selected, {.factors = weights});
      const auto expected = selectOneWalkAtATime(tree, p, n, u, budget, weights);
      ASSERT_EQ(selected.size(), expected.size()) << "trial " << trial << " point " << k;
      for (std::size_t s = 0; s < expected.size(); ++s) {
        EXPECT_EQ(selected[s].light, expected[s].light) << "trial " << trial << " point " << k << " walk " << s;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(selected[s].probability), std::bit_cast<std::uint64_t>(expected[s].probability))
            << "trial " << trial << " point " << k << " walk " << s;
      }
      ++compared;
      several += expected.size() > 1;
    }
  }
  EXPECT_EQ(compared, 3600);
  EXPECT_GT(several, 1000);  // most selections walk from several nodes at once
}

// reachingLights: every light that can light the point (in front of its plane, within its range)
// and none other, in the tree's order, or false where more than the limit can; and select() with
// everyLightUpTo takes exactly those, each with probability 1, where there are few enough, and
// otherwise selects exactly as without it.
TEST(LightTree, EveryLightInReachIsTakenExactlyWhereFewReach) {
  const auto lights = randomLights(400, 31);
  LightTree tree;
  tree.build(lights);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> coordinate(-14.0, 14.0), uniform(0.0, 1.0);
  int few = 0, many = 0;
  std::vector<LightTree::Selected> reaching, selected, sampled;
  for (int k = 0; k < 400; ++k) {
    const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    const glm::dvec3 n = glm::normalize(glm::dvec3(coordinate(rng), coordinate(rng), coordinate(rng)));
    std::vector<std::uint32_t> expected;
    for (std::uint32_t l = 0; l < lights.size(); ++l)
      if (canLight(lights[l], p, n)) expected.push_back(l);
    ASSERT_TRUE(tree.reachingLights(p, n, 1000, reaching));
    std::vector<std::uint32_t> found;
    for (const auto& s : reaching) {
      EXPECT_EQ(s.probability, 1.0);
      found.push_back(s.light);
    }
    std::sort(found.begin(), found.end());
    ASSERT_EQ(found, expected) << "point " << k;
    const int count = static_cast<int>(expected.size());
    if (count > 0) EXPECT_FALSE(tree.reachingLights(p, n, count - 1, reaching)) << "one more than the limit";
    EXPECT_TRUE(tree.reachingLights(p, n, count, reaching));
    const double u = uniform(rng);
    const int limit = 24;
    tree.select(p, n, u, 4, selected, {.everyLightUpTo = limit});
    if (count <= limit) {
      ++few;
      ASSERT_EQ(selected.size(), expected.size());
      for (const auto& s : selected) EXPECT_EQ(s.probability, 1.0);
    } else {
      ++many;
      tree.select(p, n, u, 4, sampled);
      ASSERT_EQ(selected.size(), sampled.size());
      for (std::size_t s = 0; s < sampled.size(); ++s) {
        EXPECT_EQ(selected[s].light, sampled[s].light);
        EXPECT_EQ(selected[s].probability, sampled[s].probability);
      }
    }
  }
  EXPECT_GT(few, 40);
  EXPECT_GT(many, 40);
}

// A box's reach list (leavesReachingBox) holds every light that can light some point of the box,
// and searching it (reachingLightsAmong) finds what the tree's walk finds, in its order, with the
// same answer at every limit; a box far from every range lists nothing.
TEST(LightTree, ABoxsReachListFindsWhatTheWalkFinds) {
  const auto lights = randomLights(300, 41);
  LightTree tree;
  tree.build(lights);
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> coordinate(-14.0, 14.0), unit(0.0, 1.0);
  std::vector<std::uint32_t> leaves;
  std::vector<LightTree::Selected> walked, listed;
  std::size_t shortest = lights.size(), compared = 0;
  for (int box = 0; box < 60; ++box) {
    const glm::dvec3 lower(coordinate(rng), coordinate(rng), coordinate(rng));
    const double size = 0.25 + 2.0 * unit(rng);
    tree.leavesReachingBox(lower, lower + size, leaves);
    shortest = std::min(shortest, leaves.size());
    ASSERT_TRUE(std::is_sorted(leaves.begin(), leaves.end())) << "the walk's depth-first order is the nodes' order";
    for (int k = 0; k < 40; ++k) {
      const glm::dvec3 p = lower + size * glm::dvec3(unit(rng), unit(rng), unit(rng));
      const glm::dvec3 n = glm::normalize(glm::dvec3(coordinate(rng), coordinate(rng), coordinate(rng)));
      for (const int limit : {1000, 8, 3}) {
        const bool walkedAll = tree.reachingLights(p, n, limit, walked);
        ASSERT_EQ(tree.reachingLightsAmong(leaves, p, n, limit, listed), walkedAll);
        if (!walkedAll) continue;
        ASSERT_EQ(listed.size(), walked.size()) << "box " << box << ", point " << k;
        for (std::size_t s = 0; s < walked.size(); ++s) ASSERT_EQ(listed[s].light, walked[s].light);
        ++compared;
      }
    }
  }
  std::size_t unbounded = 0;
  for (const auto& l : lights) unbounded += !(l.range > 0);
  EXPECT_GT(compared, 3000u);
  EXPECT_LT(shortest, unbounded + (lights.size() - unbounded) / 2) << "the lists leave out lights whose range ends short of the box";
  tree.leavesReachingBox(glm::dvec3(1000.0), glm::dvec3(1001.0), leaves);
  EXPECT_EQ(leaves.size(), unbounded) << "only the lights without a range reach a box far away";
}

// Guide::keepFactors: where every light in reach is taken, a light whose leaf factor f is in
// (0, 1) is kept in a share f of the u's and divided by f, the others always, each with
// probability 1: over a fine grid of u the mean of sum c(l) / p(l) is the sum of c over every light
// in reach, whatever the lights' contributions (the roulette's numbers are the same u offset per
// light, so they are correlated; only each light's own share matters).
TEST(LightTree, OccludedLightsKeptByRouletteSumToEveryLight) {
  const auto lights = randomLights(200, 43);
  LightTree tree;
  tree.build(lights);
  const auto nodes = tree.nodes();
  std::vector<float> factors(nodes.size(), 1.0f);
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> coordinate(-14.0, 14.0), unit(0.0, 1.0);
  constexpr float kShares[] = {0.0f, 1.0f, 0.1f, 0.35f};
  for (std::size_t n = 0; n < nodes.size(); ++n)
    if (nodes[n].count == 1) factors[n] = kShares[nodes[n].first % 4];
  int tested = 0;
  std::vector<LightTree::Selected> selected;
  for (int k = 0; k < 200 && tested < 30; ++k) {
    const glm::dvec3 p(coordinate(rng), coordinate(rng), coordinate(rng));
    const glm::dvec3 n = glm::normalize(glm::dvec3(coordinate(rng), coordinate(rng), coordinate(rng)));
    double exact = 0.0;
    std::map<std::uint32_t, double> contribution;
    bool anyRoulette = false;
    for (std::uint32_t l = 0; l < lights.size(); ++l)
      if (canLight(lights[l], p, n)) {
        contribution[l] = 0.5 + unit(rng);
        exact += contribution[l];
        anyRoulette = anyRoulette || l % 4 >= 2;
      }
    if (!anyRoulette || contribution.size() > 30) continue;
    ++tested;
    constexpr int kGrid = 1 << 14;
    double sum = 0.0;
    std::map<std::uint32_t, int> kept;
    for (int g = 0; g < kGrid; ++g) {
      ASSERT_TRUE(tree.select(p, n, (g + 0.5) / kGrid, 4, selected, {.everyLightUpTo = 64, .keepFactors = factors.data()}));
      for (const auto& s : selected) {
        ASSERT_TRUE(contribution.count(s.light)) << "a light that cannot reach the point";
        const double f = kShares[s.light % 4];
        EXPECT_EQ(s.probability, f > 0 && f < 1 ? static_cast<double>(f) : 1.0);
        sum += contribution[s.light] / s.probability;
        ++kept[s.light];
      }
    }
    for (const auto& [l, c] : contribution) {
      const double f = kShares[l % 4];
      const double share = static_cast<double>(kept[l]) / kGrid;
      EXPECT_NEAR(share, f > 0 && f < 1 ? f : 1.0, 2.0 / kGrid) << "light " << l;
    }
    EXPECT_NEAR(sum / kGrid, exact, 1e-3 * exact) << "point " << k;
  }
  EXPECT_GE(tested, 20);
}

// The two-lane importance is importance() itself, bit for bit (a reference's bytes depend on it):
// over many nodes, points and normals, including points inside and on the boxes, lights that
// coincide (boxes of no extent), unbounded ranges, normals along an axis (facing exactly zero)
// and points at a range's edge.
TEST(LightTree, BothChildrensImportanceAtOnceIsTheScalarOneBitForBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 5);
  for (int trial = 0; trial < 20; ++trial) {
    auto lights = randomLights(40 + trial, 100 + static_cast<std::uint32_t>(trial));
    lights.push_back(lights[3]);  // two lights at one place
    lights.push_back(lights[4]);
    LightTree tree;
    tree.build(lights);
    const auto nodes = tree.nodes();
    for (int k = 0; k < 400; ++k) {
      glm::dvec3 p{10 * unit(rng), 10 * unit(rng), 10 * unit(rng)};
      const auto a = static_cast<std::uint32_t>(rng() % nodes.size()), b = static_cast<std::uint32_t>(rng() % nodes.size());
      switch (pick(rng)) {
        case 0: p = 0.5 * (nodes[a].lower + nodes[a].upper); break;  // the box's centre
        case 1: p = nodes[a].lower; break;                            // its corner
        case 2: p.x = nodes[b].upper.x; break;                        // on a face's plane
        default: break;
      }
      glm::dvec3 n = glm::normalize(glm::dvec3{unit(rng), unit(rng), unit(rng)});
      if (k % 7 == 0) n = {0, k % 2 ? 1.0 : -1.0, 0};
      double both[2];
      tree.importancePair(a, b, p, n, both);
      const double ia = LightTree::importance(nodes[a], p, n), ib = LightTree::importance(nodes[b], p, n);
      ASSERT_EQ(std::bit_cast<std::uint64_t>(both[0]), std::bit_cast<std::uint64_t>(ia)) << "node " << a << ": " << both[0] << " against " << ia;
      ASSERT_EQ(std::bit_cast<std::uint64_t>(both[1]), std::bit_cast<std::uint64_t>(ib)) << "node " << b << ": " << both[1] << " against " << ib;
    }
  }
  // At a light's range exactly: importance zero both ways.
  LightTree tree;
  const std::vector<LightTree::Light> one = {{{0, 2, 0}, 5.0, 2.0}, {{0, 3, 0}, 5.0, 0.0}};
  tree.build(one);
  double both[2];
  tree.importancePair(1, 2, {0, 0, 0}, {0, 1, 0}, both);
  EXPECT_EQ(both[0], LightTree::importance(tree.nodes()[1], {0, 0, 0}, {0, 1, 0}));
  EXPECT_EQ(both[1], LightTree::importance(tree.nodes()[2], {0, 0, 0}, {0, 1, 0}));
  EXPECT_EQ(std::min(both[0], both[1]), 0.0);
  EXPECT_GT(std::max(both[0], both[1]), 0.0);
}

}  // namespace
}  // namespace dynbench::render
