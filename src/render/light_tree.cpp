#include "render/light_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace dynbench::render {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();

double boundedRange(double range) { return range > 0 && std::isfinite(range) ? range : kInfinity; }
}  // namespace

void LightTree::build(std::span<const Light> lights) {
  nodes_.clear();
  boxes_.clear();
  leafOf_.clear();
  lightCount_ = lights.size();
  if (lights.empty()) return;
  nodes_.reserve(2 * lights.size());
  std::vector<std::uint32_t> order(lights.size());
  std::iota(order.begin(), order.end(), 0u);
  buildRange(order, lights, 0, order.size());
  leafOf_.assign(lights.size(), 0);
  for (std::size_t n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].count == 1) leafOf_[nodes_[n].first] = static_cast<std::uint32_t>(n);
  boxes_.resize(nodes_.size());
  for (std::size_t n = 0; n < nodes_.size(); ++n) {
    Box& box = boxes_[n];
    box.centre = 0.5 * (nodes_[n].lower + nodes_[n].upper);
    box.half = 0.5 * (nodes_[n].upper - nodes_[n].lower);
    box.radius2 = glm::dot(box.half, box.half);
  }
}

// Top-down, split at the median of the longest axis of the lights' positions: the lights of a node
// are then close together, which is what makes a node's bounds a good stand-in for its lights.
std::uint32_t LightTree::buildRange(std::vector<std::uint32_t>& order, std::span<const Light> lights, std::size_t begin, std::size_t end) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.lower = glm::dvec3(kInfinity);
  node.upper = glm::dvec3(-kInfinity);
  for (std::size_t k = begin; k < end; ++k) {
    const Light& l = lights[order[k]];
    node.lower = glm::min(node.lower, l.position);
    node.upper = glm::max(node.upper, l.position);
    node.power += l.power;
    node.range = std::max(node.range, boundedRange(l.range));
  }
  node.count = static_cast<std::uint32_t>(end - begin);
  if (node.count == 1) {
    node.first = order[begin];
    nodes_[index] = node;
    return index;
  }
  const glm::dvec3 extent = node.upper - node.lower;
  const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
  const std::size_t middle = begin + (end - begin) / 2;
  std::nth_element(order.begin() + static_cast<std::ptrdiff_t>(begin), order.begin() + static_cast<std::ptrdiff_t>(middle),
                   order.begin() + static_cast<std::ptrdiff_t>(end),
                   [&](std::uint32_t a, std::uint32_t b) { return lights[a].position[axis] < lights[b].position[axis]; });
  buildRange(order, lights, begin, middle);  // the first child follows its parent
  node.first = buildRange(order, lights, middle, end);
  nodes_[index] = node;
  return index;
}

// Importance of a node's lights at point p with unit normal n (after pbrt-v4's LightBounds::
// Importance, for omnidirectional emitters): power / d^2 times a bound on the cosine at the
// surface and on the range window, where
//   - d^2 is the squared distance to the bounds' centre, but at least the squared half diagonal
//     (so a point among the lights does not make the estimate infinite);
//   - the cosine bound is cos(max(0, theta_n - theta_b)): theta_n the angle between n and the
//     centre's direction, theta_b the half angle the bounds' enclosing sphere subtends from p;
//   - the window bound is KHR_lights_punctual's window 1 - (d/range)^4 at the bounds' nearest
//     point with the largest range, an upper bound for every light below.
// Zero exactly where no light below can give light: every point of the bounds is below the
// surface's plane, or out of every light's range. For a single light it is its unshadowed
// luminance of irradiance (times its window).
double LightTree::importance(const Node& node, const glm::dvec3& p, const glm::dvec3& n) {
  const glm::dvec3 centre = 0.5 * (node.lower + node.upper), half = 0.5 * (node.upper - node.lower);
  const glm::dvec3 toCentre = centre - p;
  // Facing: the largest height of a point of the box above the surface's plane.
  if (glm::dot(toCentre, n) + glm::dot(half, glm::abs(n)) <= 0) return 0.0;
  double window = 1.0;
  if (std::isfinite(node.range)) {
    const glm::dvec3 nearest = glm::clamp(p, node.lower, node.upper);
    const glm::dvec3 gap = nearest - p;
    const double r2 = glm::dot(gap, gap) / (node.range * node.range);
    if (r2 >= 1.0) return 0.0;
    window = 1.0 - r2 * r2;
  }
  const double radius2 = glm::dot(half, half);
  const double distance2 = glm::dot(toCentre, toCentre);
  double cosBound = 1.0;
  if (distance2 > radius2) {
    const double distance = std::sqrt(distance2);
    const double cosN = glm::dot(toCentre, n) / distance;
    const double sinB2 = radius2 / distance2, cosB = std::sqrt(1.0 - sinB2);
    // cos(theta_n - theta_b) where theta_n > theta_b, else 1.
    if (cosN < cosB) cosBound = cosN * cosB + std::sqrt(std::max(0.0, 1.0 - cosN * cosN)) * std::sqrt(sinB2);
  }
  // Positive wherever the box reaches above the plane (the sphere holds the box); kept above zero
  // against rounding, so a light that can give light is never given probability zero.
  cosBound = std::max(cosBound, 1e-6);
  return node.power * cosBound * window / std::max({distance2, radius2, 1e-18});
}

#if defined(__SSE2__)
namespace {
// Two lanes of doubles: importance()'s arithmetic, operation for operation (SSE2's additions,
// multiplications, divisions and square roots round as the scalar ones do, and nothing here fuses
// a multiply-add), so each lane holds exactly the scalar result.
struct Lanes {
  __m128d v;
  static Lanes of(double a, double b) { return {_mm_set_pd(b, a)}; }
  static Lanes all(double x) { return {_mm_set1_pd(x)}; }
  friend Lanes operator+(Lanes a, Lanes b) { return {_mm_add_pd(a.v, b.v)}; }
  friend Lanes operator-(Lanes a, Lanes b) { return {_mm_sub_pd(a.v, b.v)}; }
  friend Lanes operator*(Lanes a, Lanes b) { return {_mm_mul_pd(a.v, b.v)}; }
  friend Lanes operator/(Lanes a, Lanes b) { return {_mm_div_pd(a.v, b.v)}; }
};
Lanes sqrt(Lanes a) { return {_mm_sqrt_pd(a.v)}; }
// std::max(a, b) = b > a ? b : a and std::min(a, b) = b < a ? b : a, even for signed zeros (no
// NaN reaches a lane whose result is kept); maxpd(x, y) = x > y ? x : y, minpd likewise.
Lanes max(Lanes a, Lanes b) { return {_mm_max_pd(b.v, a.v)}; }
Lanes min(Lanes a, Lanes b) { return {_mm_min_pd(b.v, a.v)}; }
// cond ? a : b, lane by lane (cond from a comparison: all bits set or none).
Lanes choose(__m128d cond, Lanes a, Lanes b) { return {_mm_or_pd(_mm_and_pd(cond, a.v), _mm_andnot_pd(cond, b.v))}; }

struct Lanes3 {
  Lanes x, y, z;
};
Lanes3 of(const glm::dvec3& a, const glm::dvec3& b) { return {Lanes::of(a.x, b.x), Lanes::of(a.y, b.y), Lanes::of(a.z, b.z)}; }
Lanes3 all(const glm::dvec3& a) { return {Lanes::all(a.x), Lanes::all(a.y), Lanes::all(a.z)}; }
Lanes3 operator-(const Lanes3& a, const Lanes3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
// glm::dot's order: (x + y) + z.
Lanes dot(const Lanes3& a, const Lanes3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
}  // namespace
#endif

void LightTree::importancePair(std::uint32_t a, std::uint32_t b, const glm::dvec3& p, const glm::dvec3& n, double out[2]) const {
#if defined(__SSE2__)
  const Node &na = nodes_[a], &nb = nodes_[b];
  const Box &ba = boxes_[a], &bb = boxes_[b];
  const Lanes3 point = all(p), normal = all(n);
  const Lanes3 toCentre = of(ba.centre, bb.centre) - point, half = of(ba.half, bb.half);
  const Lanes3 absNormal = {Lanes::all(std::abs(n.x)), Lanes::all(std::abs(n.y)), Lanes::all(std::abs(n.z))};
  const Lanes facing = dot(toCentre, normal) + dot(half, absNormal);
  // The window: an infinite range gives r2 = 0 and window 1, as importance()'s skipped branch does.
  const Lanes3 lower = of(na.lower, nb.lower), upper = of(na.upper, nb.upper);
  const Lanes3 nearest = {min(max(point.x, lower.x), upper.x), min(max(point.y, lower.y), upper.y), min(max(point.z, lower.z), upper.z)};
  const Lanes3 gap = nearest - point;
  const Lanes range = Lanes::of(na.range, nb.range);
  const Lanes r2 = dot(gap, gap) / (range * range);
  const Lanes window = Lanes::all(1.0) - r2 * r2;
  const Lanes radius2 = Lanes::of(ba.radius2, bb.radius2);
  const Lanes distance2 = dot(toCentre, toCentre);
  const Lanes distance = sqrt(distance2);
  const Lanes cosN = dot(toCentre, normal) / distance;
  const Lanes sinB2 = radius2 / distance2, cosB = sqrt(Lanes::all(1.0) - sinB2);
  const Lanes bound = cosN * cosB + sqrt(max(Lanes::all(0.0), Lanes::all(1.0) - cosN * cosN)) * sqrt(sinB2);
  const __m128d narrower = _mm_and_pd(_mm_cmpgt_pd(distance2.v, radius2.v), _mm_cmplt_pd(cosN.v, cosB.v));
  const Lanes cosBound = max(choose(narrower, bound, Lanes::all(1.0)), Lanes::all(1e-6));
  const Lanes value = Lanes::of(na.power, nb.power) * cosBound * window / max(max(distance2, radius2), Lanes::all(1e-18));
  const __m128d gives = _mm_and_pd(_mm_cmpgt_pd(facing.v, _mm_setzero_pd()), _mm_cmplt_pd(r2.v, _mm_set1_pd(1.0)));
  _mm_storeu_pd(out, choose(gives, value, Lanes::all(0.0)).v);
#else
  out[0] = importance(nodes_[a], p, n);
  out[1] = importance(nodes_[b], p, n);
#endif
}

void LightTree::sumOverNodes(std::span<const double> perLight, std::span<double> perNode) const {
  // Depth first with the first child after its parent: children come after their parent, so a
  // pass from the last node back sums each node's children into it.
  for (std::size_t n = nodes_.size(); n-- > 0;)
    perNode[n] = nodes_[n].count == 1 ? perLight[nodes_[n].first] : perNode[n + 1] + perNode[nodes_[n].first];
}

// One step down for each walk still above a leaf, the walks interleaved: a walk's steps form one
// chain of square roots and divisions (importancePair, then the child's share), and the child it
// takes depends on u, so one walk at a time the core waited on each chain and then mispredicted
// which child half the time (perf on v2's oa_dm3 frame 108: the tree 37 % of a reference frame,
// its time on importancePair's sqrtpd and divpd). Interleaved and chosen without a branch, the
// walks' chains overlap. Each walk computes exactly the numbers it computed alone.
void LightTree::descendAll(Walk* walks, int count, const glm::dvec3& point, const glm::dvec3& normal, const float* factors) const {
  constexpr double kBelowOne = 1.0 - 0x1p-53;
  int active = 0;
  for (int k = 0; k < count; ++k) active += walks[k].alive && nodes_[walks[k].node].count > 1;
  while (active > 0) {
    active = 0;
    for (int k = 0; k < count; ++k) {
      Walk& w = walks[k];
      const Node& node = nodes_[w.node];
      if (!w.alive || node.count <= 1) continue;
      const std::uint32_t a = w.node + 1, b = node.first;
      double ia, ib;
      if (w.firstImportances) {  // the first level's, already weighed by select()
        ia = w.firstImportances[0], ib = w.firstImportances[1];
        w.firstImportances = nullptr;
      } else {
        double both[2];
        importancePair(a, b, point, normal, both);
        ia = both[0], ib = both[1];
        if (factors) ia *= factors[a], ib *= factors[b];
      }
      const double total = ia + ib;
      if (!(total > 0)) {  // neither child can light the point: the walk ends without a light
        w.alive = false;
        continue;
      }
      const double pa = ia / total;
      // Both remappings computed, one kept: the same values as a branch on u < pa gives.
      const double toFirst = std::min(w.u / pa, kBelowOne), toSecond = std::min((w.u - pa) / (1.0 - pa), kBelowOne);
      const bool first = w.u < pa;
      w.u = first ? toFirst : toSecond;
      w.probability *= first ? pa : 1.0 - pa;
      w.node = first ? a : b;
      active += nodes_[w.node].count > 1;
    }
  }
}

// Inlined into reachingLights, whose cost it is (perf on v2's calm frame 108: 11 % of the frame
// as a call per visited node).
[[gnu::always_inline]] inline bool LightTree::reachesNode(std::uint32_t n, const glm::dvec3& p, const glm::dvec3& normal) const {
  const Node& node = nodes_[n];
  const Box& box = boxes_[n];
  // importance()'s facing test, on the same precomputed centre and half extent.
  if (!(glm::dot(box.centre - p, normal) + glm::dot(box.half, glm::abs(normal)) > 0)) return false;
  if (!std::isfinite(node.range)) return true;
  const glm::dvec3 gap = glm::clamp(p, node.lower, node.upper) - p;
  // importance()'s window is zero where dot(gap, gap) / range^2 >= 1, which holds wherever this
  // is false (a quotient of at least 1 needs a dividend of at least the divisor).
  return glm::dot(gap, gap) < node.range * node.range;
}

bool LightTree::reachingLights(const glm::dvec3& point, const glm::dvec3& normal, int limit, std::vector<Selected>& selected) const {
  selected.clear();
  return walkDepthFirst([&](std::uint32_t n) { return reachesNode(n, point, normal); },
                        [&](std::uint32_t leaf) {
                          if (static_cast<int>(selected.size()) == limit) return false;
                          selected.push_back({nodes_[leaf].first, 1.0});
                          return true;
                        });
}

void LightTree::leavesReachingBox(const glm::dvec3& lower, const glm::dvec3& upper, std::vector<std::uint32_t>& leaves) const {
  leaves.clear();
  // A node reaches the box where the gap between its bounds and the box is shorter than its
  // largest range.
  walkDepthFirst(
      [&](std::uint32_t n) {
        const Node& node = nodes_[n];
        if (!std::isfinite(node.range)) return true;
        const glm::dvec3 gap = glm::max(glm::max(lower - node.upper, node.lower - upper), glm::dvec3(0.0));
        return glm::dot(gap, gap) < node.range * node.range;
      },
      [&](std::uint32_t leaf) {
        leaves.push_back(leaf);
        return true;
      });
}

bool LightTree::reachingLightsAmong(std::span<const std::uint32_t> leaves, const glm::dvec3& point, const glm::dvec3& normal, int limit,
                                    std::vector<Selected>& selected) const {
  selected.clear();
  for (const std::uint32_t n : leaves)
    if (reachesNode(n, point, normal)) {
      if (static_cast<int>(selected.size()) == limit) return false;
      selected.push_back({nodes_[n].first, 1.0});
    }
  return true;
}

void LightTree::keepWithLeafFactors(std::vector<Selected>& selected, double u, const float* factors) const {
  // u is not used by the exact sum, so it is independent of which lights reach the point; each
  // light's own number u + k phi (mod 1), phi the golden ratio's conjugate, is uniform, and is all
  // that light's expectation depends on (the lights' numbers are correlated with one another, which
  // the sum's expectation does not see).
  constexpr double kPhi = 0.6180339887498949;
  std::size_t kept = 0;
  for (const Selected& s : selected) {
    const double f = factors[leafOf_[s.light]];
    const double q = f > 0 && f < 1 ? f : 1.0;
    const double v = u + kPhi * static_cast<double>(s.light);
    if (q < 1.0 && !(v - std::floor(v) < q)) continue;
    selected[kept++] = {s.light, q};
  }
  selected.resize(kept);
}

bool LightTree::select(const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights, std::vector<Selected>& selected,
                       const Guide& guide) const {
  const int everyLightUpTo = guide.everyLightUpTo;
  if (everyLightUpTo > 0 && (guide.reachLeaves ? reachingLightsAmong(*guide.reachLeaves, point, normal, everyLightUpTo, selected)
                                               : reachingLights(point, normal, everyLightUpTo, selected))) {
    if (guide.keepFactors) keepWithLeafFactors(selected, u, guide.keepFactors);
    return true;
  }
  const float* factors = guide.factors;
  selected.clear();
  if (nodes_.empty()) return false;
  // The cut: nodes that together hold every light that can reach the point, each to be sampled
  // once. Splitting is decided by the point alone (never by u), so each light's probability is
  // well defined and the estimate unbiased; the most important interior node is split first.
  constexpr int kMaxCut = 64;
  const int budget = std::clamp(maxLights, 1, kMaxCut);
  std::array<std::uint32_t, kMaxCut> cut;
  std::array<double, kMaxCut> weight;
  int size = 0;
  const double rootImportance = importance(nodes_[0], point, normal) * (factors ? factors[0] : 1.0);
  if (!(rootImportance > 0)) return false;
  cut[0] = 0;
  weight[0] = rootImportance;
  size = 1;
  // When the budget stops the split, the children's importances of the node it would have split,
  // which the walk down from that node needs first (the same numbers, not computed twice).
  int stoppedAt = -1;
  double stopped[2];
  while (true) {
    int best = -1;
    for (int k = 0; k < size; ++k)
      if (nodes_[cut[k]].count > 1 && (best < 0 || weight[k] > weight[best])) best = k;
    if (best < 0) break;  // only single lights left
    const std::uint32_t n = cut[best], a = n + 1, b = nodes_[n].first;
    double both[2];
    importancePair(a, b, point, normal, both);
    double ia = both[0], ib = both[1];
    if (factors) ia *= factors[a], ib *= factors[b];
    const int children = (ia > 0) + (ib > 0);
    if (size - 1 + children > budget) {
      stoppedAt = best;
      stopped[0] = ia, stopped[1] = ib;
      break;
    }
    // Replace the node with its children that can light the point.
    cut[best] = cut[size - 1];
    weight[best] = weight[size - 1];
    --size;
    if (ia > 0) cut[size] = a, weight[size++] = ia;
    if (ib > 0) cut[size] = b, weight[size++] = ib;
  }
  std::array<Walk, kMaxCut> walks;
  for (int k = 0; k < size; ++k) walks[k] = {cut[k], u, 1.0, k == stoppedAt ? stopped : nullptr, true};
  descendAll(walks.data(), size, point, normal, factors);
  for (int k = 0; k < size; ++k)
    if (walks[k].alive && walks[k].probability > 0) selected.push_back({nodes_[walks[k].node].first, walks[k].probability});
  return false;
}

}  // namespace dynbench::render
