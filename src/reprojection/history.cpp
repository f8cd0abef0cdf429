#include "reprojection/history.h"

#include <cmath>

namespace dynbench::reprojection {
bool onTangentPlane(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& q, double viewDepth, const SurfaceThresholds& t) {
  return std::abs(glm::dot(n, q - p)) <= t.position * std::abs(viewDepth);
}

HistoryTest testHistory(const glm::dvec3& p, const glm::dvec3& n, double viewDepth, const FeatureFrame& previous, const BilinearTaps& taps,
                        const SurfaceThresholds& t) {
  HistoryTest result;
  result.history = taps;
  if (t.test == GeometryTest::kBilinear) {
    // Position and normal history of a surface cannot come from the background.
    bool historyMissesGeometry = false;
    for (int k = 0; k < 4; ++k)
      if (taps.weight[k] > 0 && previous.hit[taps.index[k]] <= 0) historyMissesGeometry = true;
    result.position = !historyMissesGeometry && glm::length(p - sample3(previous.position, taps)) <= t.position;
    result.normal = !historyMissesGeometry && glm::length(n - sample3(previous.normal, taps)) <= t.normal;
    result.consistent = result.position && result.normal;
    return result;
  }
  // Per tap: is the tap's point within position x Z of the current point's tangent plane (NRD's
  // relative plane distance), and is its normal within the normal threshold? Position (normal)
  // has history when some tap passes its test: each test on its own, as the thesis's columns are.
  // The normal has history when a single tap's matches, or the interpolation of the same-surface
  // taps' normals does: across a crease the taps of both faces lie near the tangent plane and
  // their mean normal is neither face's, but a tap of the pixel's own face matches; on a curved
  // surface a pixel wide or less, neighbouring taps differ by more than the threshold and none
  // matches a point between them, but their interpolation does (to second order in the turn
  // across a pixel), as the surface's normal there was in the previous frame. Radiance is read
  // from the taps of the same surface, renormalised (all the taps on geometry where none is:
  // another surface, whose comparison then fails as it should).
  BilinearTaps same{}, onGeometry{};
  double sameWeight = 0.0, geometryWeight = 0.0;
  bool sameNormal = false;
  glm::dvec3 sameNormalSum(0.0);
  for (int k = 0; k < 4; ++k) {
    same.index[k] = onGeometry.index[k] = taps.index[k];
    same.weight[k] = onGeometry.weight[k] = 0.0;
    if (!(taps.weight[k] > 0) || previous.hit[taps.index[k]] <= 0) continue;
    onGeometry.weight[k] = taps.weight[k];
    geometryWeight += taps.weight[k];
    const bool normalMatches = glm::length(n - at3(previous.normal, taps.index[k])) <= t.normal;
    result.normal |= normalMatches;
    if (onTangentPlane(p, n, at3(previous.position, taps.index[k]), viewDepth, t)) {
      same.weight[k] = taps.weight[k];
      sameWeight += taps.weight[k];
      sameNormal |= normalMatches;
      sameNormalSum += taps.weight[k] * at3(previous.normal, taps.index[k]);
    }
  }
  if (sameWeight > 0 && !sameNormal && glm::length(sameNormalSum) > 0) {
    sameNormal = glm::length(n - glm::normalize(sameNormalSum)) <= t.normal;
    result.normal |= sameNormal;
  }
  result.position = sameWeight > 0;
  result.consistent = result.position && sameNormal;
  const double total = result.position ? sameWeight : geometryWeight;
  if (total <= 0) return result;  // every tap is background: no history of a surface
  BilinearTaps& read = result.history;
  read = result.position ? same : onGeometry;
  for (double& w : read.weight) w /= total;
  return result;
}

HistoryLookup::HistoryLookup(const FeatureFrame& current, const FeatureFrame& previous, const SurfaceThresholds& absolute, bool useMotion)
    : current_(current), previous_(previous), absolute_(absolute), useMotion_(useMotion), currentProjector_(current.camera), previousProjector_(previous.camera) {}

std::optional<BilinearTaps> HistoryLookup::operator()(int px, int py) const {
  const FeatureFrame &current = current_, &previous = previous_;
  const std::size_t i = static_cast<std::size_t>(py) * current.width + px;
  const glm::dvec2 sample(px + 0.5 + current.camera.jitter.x, py + 0.5 + current.camera.jitter.y);
  const bool hit = current.hit[i] > 0;
  const glm::dvec3 p(hit ? glm::dvec3(current.position[3 * i], current.position[3 * i + 1], current.position[3 * i + 2]) : glm::dvec3(0.0));
  std::optional<glm::dvec2> q;
  if (!hit) {
    q = previousProjector_.direction(currentProjector_.pixelDirection(sample.x, sample.y));
  } else if (useMotion_ && !current.motion.empty()) {
    const glm::dvec2 motion(current.motion[2 * i], current.motion[2 * i + 1]);
    if (std::abs(motion.x) < 1e8 && std::abs(motion.y) < 1e8) q = sample + motion;  // -1e9: behind the previous camera
  } else {
    q = previousProjector_.point(p);
  }
  if (!q || q->x < 0 || q->y < 0 || q->x > previous.width || q->y > previous.height) return std::nullopt;
  // The previous frame's buffers are at its samples: centre + its jitter.
  const BilinearTaps taps =
      bilinearTaps(q->x - previous.camera.jitter.x, q->y - previous.camera.jitter.y, previous.width, previous.height);
  if (!hit) {
    // The background's history is the background.
    for (int k = 0; k < 4; ++k)
      if (taps.weight[k] > 0 && previous.hit[taps.index[k]] > 0) return std::nullopt;
    return taps;
  }
  // A surface's: the taps the discard's geometry test keeps (testHistory).
  const glm::dvec3 n(current.normal[3 * i], current.normal[3 * i + 1], current.normal[3 * i + 2]);
  const double viewDepth = -(current.camera.view * glm::dvec4(p, 1.0)).z;
  const HistoryTest test = testHistory(p, n, viewDepth, previous, taps, absolute_);
  if (!test.consistent) return std::nullopt;
  return test.history;
}

}  // namespace dynbench::reprojection
