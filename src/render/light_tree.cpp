#include "render/light_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace dynbench::render {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();

double boundedRange(double range) { return range > 0 && std::isfinite(range) ? range : kInfinity; }
}  // namespace

void LightTree::build(std::span<const Light> lights) {
  nodes_.clear();
  lightCount_ = lights.size();
  if (lights.empty()) return;
  nodes_.reserve(2 * lights.size());
  std::vector<std::uint32_t> order(lights.size());
  std::iota(order.begin(), order.end(), 0u);
  buildRange(order, lights, 0, order.size());
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

void LightTree::sumOverNodes(std::span<const double> perLight, std::span<double> perNode) const {
  // Depth first with the first child after its parent: children come after their parent, so a
  // pass from the last node back sums each node's children into it.
  for (std::size_t n = nodes_.size(); n-- > 0;)
    perNode[n] = nodes_[n].count == 1 ? perLight[nodes_[n].first] : perNode[n + 1] + perNode[nodes_[n].first];
}

bool LightTree::descend(std::uint32_t n, const glm::dvec3& point, const glm::dvec3& normal, double u, Selected& out, const float* factors) const {
  double probability = 1.0;
  while (nodes_[n].count > 1) {
    const std::uint32_t a = n + 1, b = nodes_[n].first;
    double ia = importance(nodes_[a], point, normal), ib = importance(nodes_[b], point, normal);
    if (factors) ia *= factors[a], ib *= factors[b];
    const double total = ia + ib;
    if (!(total > 0)) return false;  // neither child can light the point
    const double pa = ia / total;
    if (u < pa) {
      u = std::min(u / pa, 1.0 - 0x1p-53);
      probability *= pa;
      n = a;
    } else {
      u = std::min((u - pa) / (1.0 - pa), 1.0 - 0x1p-53);
      probability *= 1.0 - pa;
      n = b;
    }
  }
  out.light = nodes_[n].first;
  out.probability = probability;
  return probability > 0;
}

void LightTree::select(const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights, std::vector<Selected>& selected,
                       const float* factors) const {
  selected.clear();
  if (nodes_.empty()) return;
  // The cut: nodes that together hold every light that can reach the point, each to be sampled
  // once. Splitting is decided by the point alone (never by u), so each light's probability is
  // well defined and the estimate unbiased; the most important interior node is split first.
  constexpr int kMaxCut = 64;
  const int budget = std::clamp(maxLights, 1, kMaxCut);
  std::array<std::uint32_t, kMaxCut> cut;
  std::array<double, kMaxCut> weight;
  int size = 0;
  const double rootImportance = importance(nodes_[0], point, normal) * (factors ? factors[0] : 1.0);
  if (!(rootImportance > 0)) return;
  cut[0] = 0;
  weight[0] = rootImportance;
  size = 1;
  while (true) {
    int best = -1;
    for (int k = 0; k < size; ++k)
      if (nodes_[cut[k]].count > 1 && (best < 0 || weight[k] > weight[best])) best = k;
    if (best < 0) break;  // only single lights left
    const std::uint32_t n = cut[best], a = n + 1, b = nodes_[n].first;
    double ia = importance(nodes_[a], point, normal), ib = importance(nodes_[b], point, normal);
    if (factors) ia *= factors[a], ib *= factors[b];
    const int children = (ia > 0) + (ib > 0);
    if (size - 1 + children > budget) break;
    // Replace the node with its children that can light the point.
    cut[best] = cut[size - 1];
    weight[best] = weight[size - 1];
    --size;
    if (ia > 0) cut[size] = a, weight[size++] = ia;
    if (ib > 0) cut[size] = b, weight[size++] = ib;
  }
  for (int k = 0; k < size; ++k) {
    Selected s;
    if (descend(cut[k], point, normal, u, s, factors)) selected.push_back(s);
  }
}

}  // namespace dynbench::render
