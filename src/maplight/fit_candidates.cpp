#include "maplight/fit_candidates.h"

#include <algorithm>
#include <array>
#include <numeric>

#include <tbb/parallel_for.h>

namespace dynbench::maplight {

namespace {

// Units between a candidate light and every surface. Lightmap texels are 16 units apart (q3map2's
// default sample size), so a light nearer than two of them can fit a few texels' values with a hot
// spot between them that the held-out texels show up (oa_bases3 at 16 units: variance explained
// on held-out texels fell below 0).
constexpr double kCandidateClearance = 32.0;

}  // namespace

bool inOpenSpace(const glm::dvec3& p, const Occluders& occluders) {
  static const std::vector<glm::dvec3> directions = [] {
    std::vector<glm::dvec3> d;
    for (int a = 0; a < 3; ++a)
      for (int s : {-1, 1}) {
        glm::dvec3 axis(0.0);
        axis[a] = s;
        d.push_back(axis);
      }
    for (int x : {-1, 1})
      for (int y : {-1, 1})
        for (int z : {-1, 1}) d.push_back(glm::normalize(glm::dvec3(x, y, z)));
    return d;
  }();
  for (const glm::dvec3& d : directions) {
    const BvhHit hit = occluders.all.intersect(p, d, kTraceMargin);
    if (!hit.hit) return false;
    if (hit.group == 1) continue;  // the sky
    // the surface's own side: its vertex normals (the BSP's), not a winding convention
    if (hit.distance < kCandidateClearance || glm::dot(hit.shadingNormal, d) > 0) return false;
  }
  return true;
}

std::vector<glm::dvec3> openSpaceLattice(const Bsp& bsp, const Occluders& occluders, int maxCandidates, std::size_t& spacing) {
  const glm::dvec3 lo = glm::dvec3(bsp.models[0].mins) + kMinimumDistance, hi = glm::dvec3(bsp.models[0].maxs) - kMinimumDistance;
  const glm::dvec3 size = glm::max(hi - lo, glm::dvec3(1.0));
  const auto open = [&](const glm::dvec3& p) { return inOpenSpace(p, occluders); };
  // Off the map's grid by a fraction of a unit: brushes lie on whole (mostly 8- and 16-unit)
  // coordinates, so a lattice on them sends its axis and diagonal rays along walls' planes and
  // edges, where whether a ray hits is decided by rounding (half a million such rays on oa_dm1:
  // 14,155 hit differently in Embree and in triangle_bvh.h; none once off the grid).
  const glm::dvec3 offGrid(0.37, 0.23, 0.11);
  // Coarsen the lattice until the open points are few enough (deterministic: spacing in 8-unit steps).
  for (double step = 32.0;; step += 8.0) {
    const glm::ivec3 n = glm::ivec3(glm::floor(size / step)) + 1;
    const std::size_t total = static_cast<std::size_t>(n.x) * n.y * n.z;
    if (total > static_cast<std::size_t>(maxCandidates) * 20) continue;
    std::vector<char> isOpen(total, 0);
    tbb::parallel_for(std::size_t(0), total, [&](std::size_t k) {
      const int x = static_cast<int>(k % n.x), y = static_cast<int>((k / n.x) % n.y), z = static_cast<int>(k / (static_cast<std::size_t>(n.x) * n.y));
      isOpen[k] = open(lo + offGrid + glm::dvec3(x, y, z) * step) ? 1 : 0;
    });
    const auto count = static_cast<std::size_t>(std::count(isOpen.begin(), isOpen.end(), 1));
    if (count > static_cast<std::size_t>(maxCandidates)) continue;
    std::vector<glm::dvec3> points;
    for (std::size_t k = 0; k < total; ++k)
      if (isOpen[k]) {
        const int x = static_cast<int>(k % n.x), y = static_cast<int>((k / n.x) % n.y), z = static_cast<int>(k / (static_cast<std::size_t>(n.x) * n.y));
        points.push_back(lo + offGrid + glm::dvec3(x, y, z) * step);
      }
    spacing = static_cast<std::size_t>(step);
    return points;
  }
}

std::vector<glm::dvec3> hotSpotCandidates(const std::vector<Sample>& samples, const std::vector<double>& residual, const Occluders& occluders,
                                          std::size_t maxPeaks) {
  constexpr double kPeakSeparation = 48.0;  // units: three texels
  constexpr std::array kDistances{32.0, 48.0, 64.0, 96.0, 128.0};
  std::vector<std::size_t> order(samples.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return residual[a] > residual[b]; });
  std::vector<std::size_t> peaks;
  for (std::size_t i : order) {
    if (residual[i] < 0.25 * kFullLight || peaks.size() >= maxPeaks) break;
    const bool nearBrighter = std::any_of(peaks.begin(), peaks.end(), [&](std::size_t p) {
      return glm::length(samples[p].position - samples[i].position) < kPeakSeparation;
    });
    if (!nearBrighter) peaks.push_back(i);
  }
  std::vector<glm::dvec3> trials;
  for (std::size_t p : peaks)
    for (double d : kDistances) trials.push_back(samples[p].position + d * samples[p].normal);
  std::vector<char> open(trials.size(), 0);
  tbb::parallel_for(std::size_t(0), trials.size(), [&](std::size_t t) { open[t] = inOpenSpace(trials[t], occluders) ? 1 : 0; });
  std::vector<glm::dvec3> candidates;
  for (std::size_t t = 0; t < trials.size(); ++t)
    if (open[t]) candidates.push_back(trials[t]);
  return candidates;
}

}  // namespace dynbench::maplight
