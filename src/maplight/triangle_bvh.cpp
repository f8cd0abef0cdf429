#include "maplight/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

#include <glm/geometric.hpp>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace dynbench::maplight {

namespace {

constexpr std::size_t kLeafTriangles = 2;     // at most this many: always a leaf
constexpr std::size_t kMaxLeafTriangles = 16;  // more than this: never a leaf
constexpr std::size_t kBins = 16;
constexpr double kTraversalCost = 1.0;  // a box test against a triangle test, in the heuristic

// The traversal's stack holds at most one node a level, plus one. From kSahDepth down the splits
// halve (median), so no hierarchy of fewer than 2^60 triangles is deeper than kStackDepth.
constexpr std::size_t kSahDepth = 192;
constexpr std::size_t kStackDepth = 256;

// The bin of a centroid along one axis: (centroid - lo) * kBins / extent, clamped to [0, kBins).
std::size_t binOf(double centroid, double lo, double scale) {
  const double b = (centroid - lo) * scale;
  return b <= 0.0 ? 0 : std::min(kBins - 1, static_cast<std::size_t>(b));
}

// A direction component of 0 gets this reciprocal instead of infinity: (plane - origin) times it
// stays finite for any map coordinate (below 1e8), so no 0 x inf NaN reaches the slab test.
constexpr double kHugeReciprocal = 1e300;

double reciprocal(double d) { return d == 0.0 ? kHugeReciprocal : 1.0 / d; }

// Hits this close are the same distance (coincident faces; rounding differs by their vertices).
double tieTolerance(double t) { return 1e-9 * (1.0 + t); }

struct Box {
  glm::dvec3 lo{std::numeric_limits<double>::max()}, hi{-std::numeric_limits<double>::max()};
  void add(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void add(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  double area() const {
    if (!(hi.x >= lo.x)) return 0.0;
    const glm::dvec3 d = hi - lo;
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
};

}  // namespace

TriangleBvh::TriangleBvh(std::vector<BvhTriangle> triangles) {
  if (triangles.empty()) return;
  std::vector<glm::dvec3> centroids(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    centroids[i] = (triangles[i].position[0] + triangles[i].position[1] + triangles[i].position[2]) / 3.0;
  std::vector<std::uint32_t> order(triangles.size());
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * triangles.size() / kLeafTriangles + 1);
  build(order, 0, order.size(), centroids, triangles, 0);
  triangles_.reserve(triangles.size());
  prepared_.reserve(triangles.size());
  for (const std::uint32_t i : order) {
    const BvhTriangle& t = triangles[i];
    triangles_.push_back(t);
    prepared_.push_back({t.position[0], t.position[1] - t.position[0], t.position[2] - t.position[0]});
  }
}

// A binned surface area heuristic (Wald 2007, "On fast construction of SAH-based bounding volume
// hierarchies"): of 16 bins along each axis, the split whose children's areas times their
// triangle counts are least, if that beats a leaf. Every choice is fixed by IEEE arithmetic and
// ties go to the first axis and bin, so the hierarchy is the same on every machine.
std::uint32_t TriangleBvh::build(std::vector<std::uint32_t>& order, std::size_t begin, std::size_t end, const std::vector<glm::dvec3>& centroids,
                                 const std::vector<BvhTriangle>& triangles, std::size_t depth) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.emplace_back();
  Box box, centroidBox;
  for (std::size_t k = begin; k < end; ++k) {
    for (const glm::dvec3& p : triangles[order[k]].position) box.add(p);
    centroidBox.add(centroids[order[k]]);
  }
  // widened by a relative margin, so that the slab test's rounding never culls a box a ray grazes
  const glm::dvec3 margin = 1e-9 * (glm::abs(box.lo) + glm::abs(box.hi)) + 1e-9;
  nodes_[index].lo = box.lo - margin;
  nodes_[index].hi = box.hi + margin;
  const std::size_t count = end - begin;
  const auto makeLeaf = [&] {
    nodes_[index].first = static_cast<std::uint32_t>(begin);
    nodes_[index].count = static_cast<std::uint32_t>(count);
    return index;
  };
  if (count <= kLeafTriangles) return makeLeaf();
  const glm::dvec3 extent = centroidBox.hi - centroidBox.lo;
  int bestAxis = -1;
  std::size_t bestSplit = 0;
  double bestCost = static_cast<double>(count) * box.area();  // a leaf's
  for (int axis = 0; axis < 3 && depth < kSahDepth; ++axis) {
    if (!(extent[axis] > 0.0)) continue;
    const double scale = static_cast<double>(kBins) / extent[axis];
    std::array<Box, kBins> bins;
    std::array<std::size_t, kBins> counts{};
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t b = binOf(centroids[order[k]][axis], centroidBox.lo[axis], scale);
      ++counts[b];
      for (const glm::dvec3& p : triangles[order[k]].position) bins[b].add(p);
    }
    // areas and counts left of each split, then right of it
    std::array<double, kBins> leftCost{};
    Box left;
    std::size_t leftCount = 0;
    for (std::size_t b = 0; b + 1 < kBins; ++b) {
      left.add(bins[b]);
      leftCount += counts[b];
      leftCost[b] = leftCount ? static_cast<double>(leftCount) * left.area() : 0.0;
    }
    Box right;
    std::size_t rightCount = 0;
    for (std::size_t b = kBins - 1; b > 0; --b) {
      right.add(bins[b]);
      rightCount += counts[b];
      if (rightCount == 0 || rightCount == count) continue;
      const double cost = leftCost[b - 1] + static_cast<double>(rightCount) * right.area() + kTraversalCost * box.area();
      if (cost < bestCost || (cost == bestCost && bestAxis == axis && b - 1 < bestSplit)) {
        bestCost = cost;
        bestAxis = axis;
        bestSplit = b - 1;
      }
    }
  }
  std::size_t middle = begin;
  if (bestAxis >= 0) {
    const double scale = static_cast<double>(kBins) / extent[bestAxis];
    const auto boundary = std::stable_partition(order.begin() + static_cast<std::ptrdiff_t>(begin), order.begin() + static_cast<std::ptrdiff_t>(end),
                                                [&](std::uint32_t i) { return binOf(centroids[i][bestAxis], centroidBox.lo[bestAxis], scale) <= bestSplit; });
    middle = static_cast<std::size_t>(boundary - order.begin());
    nodes_[index].axis = static_cast<std::uint8_t>(bestAxis);
  } else if (count > kMaxLeafTriangles) {
    // a leaf would be cheaper, or the centroids coincide, or the hierarchy is deep, but the leaf
    // would be too large: halve it along the longest extent (ties by triangle index)
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    std::sort(order.begin() + static_cast<std::ptrdiff_t>(begin), order.begin() + static_cast<std::ptrdiff_t>(end), [&](std::uint32_t a, std::uint32_t b) {
      const double ca = centroids[a][axis], cb = centroids[b][axis];
      return ca < cb || (ca == cb && a < b);
    });
    middle = begin + count / 2;
    nodes_[index].axis = static_cast<std::uint8_t>(axis);
  } else {
    return makeLeaf();
  }
  build(order, begin, middle, centroids, triangles, depth + 1);
  nodes_[index].first = build(order, middle, end, centroids, triangles, depth + 1);
  return index;
}

// Möller and Trumbore (1997), "Fast, minimum storage ray-triangle intersection", in double; a hit
// where u >= 0, v >= 0, u + v <= 1 and tMin <= t <= tMax, either side.
bool TriangleBvh::crosses(std::uint32_t k, const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, double& u, double& v,
                          double& t) const {
  const Prepared& p = prepared_[k];
  const glm::dvec3 pv = glm::cross(direction, p.e2);
  const double det = glm::dot(p.e1, pv);
  if (det == 0.0) return false;  // parallel to the plane, or a degenerate triangle
  const double inv = 1.0 / det;
  const glm::dvec3 tv = origin - p.p0;
  u = glm::dot(tv, pv) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const glm::dvec3 qv = glm::cross(tv, p.e1);
  v = glm::dot(direction, qv) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  t = glm::dot(p.e2, qv) * inv;
  return !(t < tMin || t > tMax);  // (so written, a NaN distance counts as a crossing, as it always has)
}

template <bool kAnyHit>
bool TriangleBvh::trace(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, double& distance, std::uint32_t& triangle,
                        double& u, double& v) const {
  if (nodes_.empty()) return false;
  const glm::dvec3 inverse(reciprocal(direction.x), reciprocal(direction.y), reciprocal(direction.z));
  bool found = false;
  double best = tMax;
  double reach = tMax;  // how far a hit may lie: tMax, then the nearest hit so far and its ties
  std::uint32_t stack[kStackDepth];
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    // slab test (Kay and Kajiya 1986) against [tMin, reach]
    double t0 = tMin, t1 = reach;
    bool miss = false;
    for (int a = 0; a < 3 && !miss; ++a) {
      double near = (node.lo[a] - origin[a]) * inverse[a], far = (node.hi[a] - origin[a]) * inverse[a];
      if (near > far) std::swap(near, far);
      t0 = std::max(t0, near);
      t1 = std::min(t1, far);
      miss = t0 > t1;
    }
    if (miss) continue;
    if (node.count == 0) {
      // both children, the one nearer the ray's origin along the split axis first (pushed last)
      const std::uint32_t first = static_cast<std::uint32_t>(&node - nodes_.data()) + 1, second = node.first;
      const bool secondNearer = direction[node.axis] < 0.0;
      stack[top++] = secondNearer ? first : second;
      stack[top++] = secondNearer ? second : first;
      continue;
    }
    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
      double uu = 0.0, vv = 0.0, t = 0.0;
      if (!crosses(k, origin, direction, tMin, reach, uu, vv, t)) continue;
      if constexpr (kAnyHit) {
        triangle = k;
        return true;
      }
      // Two surfaces at the same distance (a wall's two coincident faces): the one facing the ray,
      // where Embree keeps whichever its traversal meets first.
      if (found && t >= best - tieTolerance(best) && !(facesRay(k, uu, vv, direction) && !facesRay(triangle, u, v, direction))) continue;
      found = true;
      reach = t + tieTolerance(t);
      best = t;
      triangle = k;
      u = uu;
      v = vv;
    }
  }
  distance = best;
  return found;
}

glm::dvec3 TriangleBvh::shadingNormal(std::uint32_t triangle, double u, double v) const {
  const BvhTriangle& t = triangles_[triangle];
  glm::dvec3 n = (1.0 - u - v) * t.normal[0] + u * t.normal[1] + v * t.normal[2];
  if (glm::dot(n, n) == 0.0) n = glm::cross(prepared_[triangle].e1, prepared_[triangle].e2);
  return glm::dot(n, n) > 0.0 ? n / std::sqrt(glm::dot(n, n)) : n;
}

bool TriangleBvh::facesRay(std::uint32_t triangle, double u, double v, const glm::dvec3& direction) const {
  return glm::dot(shadingNormal(triangle, u, v), direction) < 0.0;
}

bool TriangleBvh::anyHit(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, std::uint32_t& triangle) const {
#if defined(__SSE2__)
  if (nodes_.empty()) return false;
  const glm::dvec3 inverse(reciprocal(direction.x), reciprocal(direction.y), reciprocal(direction.z));
  // The slab test of trace() on two boxes, a lane each: bit 0 where a's box is met in [tMin, tMax],
  // bit 1 where b's is. std::min(x, y) is minpd(y, x) and std::max(x, y) is maxpd(y, x), and
  // nothing here is NaN (the reciprocals are finite), so each lane's numbers are trace()'s.
  const auto boxes = [&](const Node& a, const Node& b) {
    __m128d t0 = _mm_set1_pd(tMin), t1 = _mm_set1_pd(tMax);
    for (int axis = 0; axis < 3; ++axis) {
      const __m128d o = _mm_set1_pd(origin[axis]), inv = _mm_set1_pd(inverse[axis]);
      const __m128d near = _mm_mul_pd(_mm_sub_pd(_mm_set_pd(b.lo[axis], a.lo[axis]), o), inv);
      const __m128d far = _mm_mul_pd(_mm_sub_pd(_mm_set_pd(b.hi[axis], a.hi[axis]), o), inv);
      // trace(): if (near > far) swap, so near becomes std::min(near, far), far std::max(far, near)
      const __m128d entry = _mm_min_pd(far, near), exit = _mm_max_pd(near, far);
      t0 = _mm_max_pd(entry, t0);  // std::max(t0, entry)
      t1 = _mm_min_pd(exit, t1);   // std::min(t1, exit)
    }
    return _mm_movemask_pd(_mm_cmple_pd(t0, t1));  // not (t0 > t1): met
  };
  if (!(boxes(nodes_[0], nodes_[0]) & 1)) return false;
  std::uint32_t stack[kStackDepth];
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t index = stack[--top];
    const Node& node = nodes_[index];  // its box is met
    if (node.count == 0) {
      const std::uint32_t first = index + 1, second = node.first;
      const int met = boxes(nodes_[first], nodes_[second]);
      // the child nearer the ray's origin along the split axis is taken first (pushed last)
      if (direction[node.axis] < 0.0) {
        if (met & 1) stack[top++] = first;
        if (met & 2) stack[top++] = second;
      } else {
        if (met & 2) stack[top++] = second;
        if (met & 1) stack[top++] = first;
      }
      continue;
    }
    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
      double u = 0.0, v = 0.0, t = 0.0;
      if (crosses(k, origin, direction, tMin, tMax, u, v, t)) {
        triangle = k;
        return true;
      }
    }
  }
  return false;
#else
  double distance = 0.0, u = 0.0, v = 0.0;
  return trace<true>(origin, direction, tMin, tMax, distance, triangle, u, v);
#endif
}

bool TriangleBvh::occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax) const {
  std::uint32_t triangle = 0;
  return anyHit(origin, direction, tMin, tMax, triangle);
}

bool TriangleBvh::occludedOneBoxAtATime(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax) const {
  double distance = 0.0, u = 0.0, v = 0.0;
  std::uint32_t triangle = 0;
  return trace<true>(origin, direction, tMin, tMax, distance, triangle, u, v);
}

bool TriangleBvh::occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, std::uint32_t& lastBlocker) const {
  double u = 0.0, v = 0.0, t = 0.0;
  if (lastBlocker < prepared_.size() && crosses(lastBlocker, origin, direction, tMin, tMax, u, v, t)) return true;
  std::uint32_t triangle = kNoBlocker;
  const bool blocked = anyHit(origin, direction, tMin, tMax, triangle);
  if (blocked) lastBlocker = triangle;
  return blocked;
}

BvhHit TriangleBvh::intersect(const glm::dvec3& origin, const glm::dvec3& direction, double tMin) const {
  BvhHit hit;
  double distance = 0.0, u = 0.0, v = 0.0;
  std::uint32_t triangle = 0;
  if (!trace<false>(origin, direction, tMin, std::numeric_limits<double>::max(), distance, triangle, u, v)) return hit;
  hit.hit = true;
  hit.distance = distance;
  hit.group = triangles_[triangle].group;
  hit.shadingNormal = shadingNormal(triangle, u, v);
  return hit;
}

}  // namespace dynbench::maplight
