#pragma once
// Many point and spot lights without dropping any: a bounding volume hierarchy over the lights,
// each node bounding its lights' positions, power and reach, from which a shading point picks the
// lights that matter to it (Conty Estevez and Kulla, "Importance Sampling of Many Lights with
// Adaptive Tree Splitting", HPG 2018; pbrt-v4's BVHLightSampler).
//
// At a shading point, select() first splits the tree into a cut of at most `maxLights` nodes,
// most important first (a node whose lights cannot reach the point has importance zero and is
// left out: its lights contribute exactly nothing there), then walks down from each node of the
// cut to one light, choosing a child with probability proportional to its importance. Every light
// that can light the point has a non-zero probability, so the estimate
//   sum over selected lights of  contribution(light) / probability(light)
// is unbiased; where the cut reaches single lights (at most maxLights in reach) every probability
// is 1 and the sum is exact, with no noise.
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace dynbench::render {

// What LightTree::select may know of a shading point beyond its position and normal
// (LightVisibility's cell; every field optional).
struct LightGuide {
  // One per node, each >= 0 (LightVisibility::Cell::factors): each node's importance is
  // multiplied by its factor, so that the cut and the walk down follow what was learned; a light
  // keeps a non-zero probability wherever it can reach the point if its leaf's and its
  // ancestors' factors are positive, and is never selected where one is zero (the caller sums
  // such lights otherwise).
  const float* factors = nullptr;
  // > 0: where at most that many lights can light the point, every one of them with probability
  // 1 (the exact sum; no cut, no walk), found by LightTree::reachingLights; the cut and walks only where more
  // can. Which of the two a point takes depends on the point alone, so the estimate
  // stays unbiased. On v2's OpenArena frames (fit 9: every light ends at its envelope) no point
  // is reached by more than 16 lights, and 4 lights sampled from those left 180 times the
  // variance of direct light that evaluating them all leaves, at 0.6 times the time
  // (docs/feature-buffers.md, "Every light in reach").
  int everyLightUpTo = 0;
  // Where every light in reach is taken: one per node (LightVisibility::Cell::factors), a light
  // whose leaf's factor f is in (0, 1) (its light reached the cell's pilot points unoccluded and
  // never arrived) kept with probability f, u deciding (LightTree::keepWithLeafFactors), the
  // others always.
  const float* keepFactors = nullptr;
  // leavesReachingBox of a box holding the point, searched instead of the tree (the same lights
  // in the same order: LightTree::reachingLightsAmong).
  std::optional<std::span<const std::uint32_t>> reachLeaves;
};

class LightTree {
 public:
  // A light as the tree sees it: where it is, how much it emits and how far it reaches.
  struct Light {
    glm::dvec3 position{0.0};
    double power = 0.0;  // luminance of its intensity (candela), > 0
    double range = 0.0;  // distance beyond which it gives nothing; <= 0 or infinite: unbounded
  };
  struct Selected {
    std::uint32_t light = 0;   // index into the lights given to build()
    double probability = 1.0;  // of selecting it (in (0, 1])
  };

  void build(std::span<const Light> lights);
  bool empty() const { return nodes_.empty(); }
  std::size_t size() const { return lightCount_; }

  using Guide = LightGuide;

  // The lights for shading point `point` whose surface faces `normal` (unit; lights behind its
  // plane give nothing there: the BSDFs reflect only above the geometric surface), chosen with one
  // uniform number u in [0, 1). `selected` is cleared first. maxLights >= 1. Returns true where it
  // took every light in reach (Guide::everyLightUpTo; the caller then has the exact sum, or its
  // roulette by Guide::keepFactors).
  bool select(const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights, std::vector<Selected>& selected,
              const Guide& guide = {}) const;

  // The lights that can light the point (facing it and in range: reachesNode at every node down to
  // the light), in the tree's order, each with probability 1, into `selected` (cleared first);
  // false, stopping early, where more than `limit` can. A superset of the lights whose importance
  // there is above zero (rounding can make importance() zero where a light's range ends exactly at
  // the point; such a light gives nothing there), so the sum over them is the exact sum.
  bool reachingLights(const glm::dvec3& point, const glm::dvec3& normal, int limit, std::vector<Selected>& selected) const;
  // The leaves (node indices, in the order reachingLights visits them) of every light whose range
  // reaches some point of the box [lower, upper], whatever the normal: at every point of the box a
  // superset of the lights reachingLights finds. Cleared first.
  void leavesReachingBox(const glm::dvec3& lower, const glm::dvec3& upper, std::vector<std::uint32_t>& leaves) const;
  // reachingLights, testing only `leaves` (leavesReachingBox of a box holding the point) with the
  // leaf's own test: the same lights in the same order wherever rounding does not make an ancestor's
  // bound reject what its light's own test accepts, and either way every light that can light the
  // point. The walk was 8-11 % of a v2 reference frame (perf, calm and colos); a cell's list is
  // made once a frame (LightVisibility) and is a few lights long.
  bool reachingLightsAmong(std::span<const std::uint32_t> leaves, const glm::dvec3& point, const glm::dvec3& normal, int limit,
                           std::vector<Selected>& selected) const;

  // Every light whose importance at the point is above zero (the lights that can light it), in
  // the tree's order: `visit(light)`.
  template <class Visit>
  void forEachReaching(const glm::dvec3& point, const glm::dvec3& normal, Visit&& visit) const {
    walkDepthFirst([&](std::uint32_t n) { return importance(nodes_[n], point, normal) > 0; },
                   [&](std::uint32_t leaf) {
                     visit(nodes_[leaf].first);
                     return true;
                   });
  }
  // Node sums of per-light values: perNode[n] = the sum of perLight over the lights below node n.
  void sumOverNodes(std::span<const double> perLight, std::span<double> perNode) const;
  std::size_t nodeCount() const { return nodes_.size(); }

  // The importance select() gives a node or light at a point: an upper-bound-shaped estimate of
  // the light it sends there, zero only where it provably sends none. Exposed for tests.
  struct Node {
    glm::dvec3 lower{0.0}, upper{0.0};  // bounds of the lights' positions
    double power = 0.0;                 // sum of the lights' powers
    double range = 0.0;                 // the largest range (infinity when any light is unbounded)
    std::uint32_t first = 0;            // leaf: the light; interior: the second child (the first follows the node)
    std::uint32_t count = 0;            // lights below
  };
  static double importance(const Node& node, const glm::dvec3& point, const glm::dvec3& normal);
  std::span<const Node> nodes() const { return nodes_; }
  // importance() of two nodes (by index) at once, the same numbers bit for bit: the walks down and
  // the cut weigh both children of a node each step, and two lanes of SSE2 overlap the two chains
  // of square roots and divisions that are its cost (importance's share of a demo frame 10.9 %
  // as two calls, 9.1 % as one pair, `perf`). Exposed for tests.
  void importancePair(std::uint32_t a, std::uint32_t b, const glm::dvec3& point, const glm::dvec3& normal, double out[2]) const;

 private:
  // What importance() derives from a node's bounds, computed once at build() the same way.
  struct Box {
    glm::dvec3 centre{0.0}, half{0.0};
    double radius2 = 0.0;  // dot(half, half)
  };
  std::vector<Node> nodes_;  // depth first: an interior node's first child follows it
  std::vector<Box> boxes_;   // one per node
  std::vector<std::uint32_t> leafOf_;  // light -> its leaf node
  std::size_t lightCount_ = 0;

  // The tree depth first, the first child before the second, entering a node only where
  // `reaches(node)`: `leaf(node)` at each leaf entered, in that order (the lights' order every
  // search of the tree keeps); false from it stops the walk, and the walk returns false.
  template <class Reaches, class Leaf>
  bool walkDepthFirst(Reaches&& reaches, Leaf&& leaf) const {
    if (nodes_.empty() || !reaches(std::uint32_t{0})) return true;
    std::uint32_t stack[64];
    int size = 0;
    stack[size++] = 0;
    while (size > 0) {
      const std::uint32_t n = stack[--size];
      if (nodes_[n].count == 1) {
        if (!leaf(n)) return false;
        continue;
      }
      const std::uint32_t a = n + 1, b = nodes_[n].first;
      const bool reachesA = reaches(a), reachesB = reaches(b);
      if (reachesB) stack[size++] = b;  // visited after the first child
      if (reachesA) stack[size++] = a;
    }
    return true;
  }
  // Whether some light below node `n` can light the point: some point of the node's bounds is
  // above the surface's plane and within the largest range of its lights. No square root or
  // division: the test reachingLights makes at every node it visits.
  bool reachesNode(std::uint32_t n, const glm::dvec3& point, const glm::dvec3& normal) const;
  std::uint32_t buildRange(std::vector<std::uint32_t>& order, std::span<const Light> lights, std::size_t begin, std::size_t end);
  // A walk from a node of the cut down to one light, chosen by importance (times `factors`, if
  // given): the node it is at, its uniform number (remapped at each step), the probability of the
  // steps taken, and, if known, its first node's children's importances (times factors).
  struct Walk {
    std::uint32_t node = 0;
    double u = 0.0;
    double probability = 1.0;
    const double* firstImportances = nullptr;
    bool alive = true;  // false: no light below the node it reached can light the point
  };
  // Guide::keepFactors' roulette over the lights select() found in reach, in place.
  void keepWithLeafFactors(std::vector<Selected>& selected, double u, const float* factors) const;
  // Takes every walk down to a light, the walks' steps interleaved.
  void descendAll(Walk* walks, int count, const glm::dvec3& point, const glm::dvec3& normal, const float* factors) const;
};

}  // namespace dynbench::render
