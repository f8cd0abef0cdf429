#include "discard/discard.h"

#include "core/json_fields.h"
#include "core/math.h"
#include "frames/radiance_change.h"
#include "frames/preview.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace dynbench::discard {
namespace {

using namespace reprojection;

}  // namespace

namespace {

// The variance of such a sum of independent pixels: sum of weight^2 x variance.
template <typename Taps>
double weightedVariance(const std::vector<float>& variance, const Taps& taps) {
  double s = 0.0;
  for (std::size_t k = 0; k < std::size(taps.weight); ++k) s += taps.weight[k] * taps.weight[k] * variance[taps.index[k]];
  return s;
}

}  // namespace

double sceneSize(const FeatureFrame& frame) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (std::size_t i = 0; i < frame.hit.size(); ++i) {
    if (frame.hit[i] <= 0) continue;
    lo = glm::min(lo, at3(frame.position, i));
    hi = glm::max(hi, at3(frame.position, i));
  }
  return lo.x <= hi.x ? glm::length(hi - lo) : 0.0;
}

Thresholds absoluteThresholds(const Thresholds& t, const FeatureFrame& current, double size) {
  Thresholds a = t;
  if (t.relativePosition && t.geometryTest == Thresholds::GeometryTest::kBilinear) a.position = t.position * size;
  if (!t.absoluteRadiance) {
    a.direct = t.direct * frames::meanLuminance(current.direct);
    a.indirect = t.indirect * frames::meanLuminance(current.indirect);
  }
  a.relativePosition = false;
  a.absoluteRadiance = true;
  return a;
}

Thresholds withPositionDefault(Thresholds thresholds, std::optional<double> position) {
  if (thresholds.relativePosition) thresholds.geometryTest = Thresholds::GeometryTest::kBilinear;
  const bool bilinear = thresholds.geometryTest == Thresholds::GeometryTest::kBilinear;
  thresholds.position = position.value_or(bilinear ? kBilinearPositionThreshold : Thresholds{}.position);
  return thresholds;
}

double uncertainLimit(Thresholds::RadianceTest test) {
  return test == Thresholds::RadianceTest::kPairs ? kUndecidedWarning : kNoisyWarning;
}

const char* radianceTestName(Thresholds::RadianceTest test) {
  switch (test) {
    case Thresholds::RadianceTest::kPairs: return "pairs";
    case Thresholds::RadianceTest::kExpected: return "expected";
    case Thresholds::RadianceTest::kNoiseAware: return "noise-aware";
    case Thresholds::RadianceTest::kPlain: return "plain";
  }
  return "?";
}

const std::vector<std::pair<std::string, Thresholds::RadianceTest>>& radianceTestsByName() {
  using Test = Thresholds::RadianceTest;
  static const std::vector<std::pair<std::string, Test>> tests = [] {
    std::vector<std::pair<std::string, Test>> out;
    for (const Test t : {Test::kPairs, Test::kExpected, Test::kNoiseAware, Test::kPlain}) out.emplace_back(radianceTestName(t), t);
    return out;
  }();
  return tests;
}

const char* geometryTestName(Thresholds::GeometryTest test) {
  return test == Thresholds::GeometryTest::kTaps ? "taps" : "bilinear";
}

namespace {

constexpr double kZ95 = 1.959963984540054;  // the standard normal's 97.5th percentile

double standardNormalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// The probability that a change whose estimate is d (>= 0) with standard deviation sigma truly
// exceeds the threshold tau in size: P(|X| > tau), X ~ N(d, sigma^2), the normal approximation of
// the difference of two pixel means. sigma = 0 is the plain test.
double exceedanceProbability(double d, double sigma, double tau) {
  if (!(sigma > 0)) return d > tau ? 1.0 : 0.0;
  return standardNormalCdf((d - tau) / sigma) + standardNormalCdf((-d - tau) / sigma);
}

// Per-thread sums of one frame: counts of the deterministic columns and, for the radiance
// columns, the sum of p (expected count) and of p (1 - p) (its variance, independent pixels).
struct FrameSums {
  std::array<double, 5> count{};
  double directVariance = 0.0, indirectVariance = 0.0;
  double directNoisy = 0.0, indirectNoisy = 0.0;  // pixels whose noise exceeds half the threshold
  // kPairs, direct (0) and indirect (1): the column's bounds in pixels (changed; changed or
  // undecided), each widened by the decided pixels' chance of a wrong decision.
  std::array<double, 2> low{}, high{};
};

// One pixel's radiance-change pairs for a buffer (the frame's change.* channels).
frames::ChangeEstimate changeEstimate(const std::vector<float>& change, const std::vector<float>& pairs, std::size_t i) {
  return {change[3 * i], change[3 * i + 1], change[3 * i + 2], static_cast<int>(pairs[i])};  // mean, se, gathered, n
}

// A pixel under the pairs test (frames/radiance_change.h) at luminance threshold tau: adds its
// share of the column's estimate, its bounds and whether it is undecided; returns the probability
// that it changed (1 or 0 when decided). The chance that a decision is wrong is at most the looks'
// number times the normal tail beyond its margin (Bonferroni over the sequential test's looks);
// a decision on pairs with no spread (s = 0) is exact up to the unseen-change bound.
double pairsChange(const frames::ChangeEstimate& e, double tau, double& low, double& high, double& undecided, bool& isUndecided) {
  if (e.pairs == 0) return 0.0;  // no pair: the surface is new in frame i (the position column's)
  const frames::ChangeDecision decision = frames::decideChange(e, tau);
  const double margin = std::abs(std::abs(e.mean) - tau);
  const double wrong =
      e.standardError > 0 ? std::min(1.0, frames::changeLooks(e.pairs) * standardNormalCdf(-margin / e.standardError)) : 0.0;
  switch (decision) {
    case frames::ChangeDecision::kChanged:
      low += 1.0 - wrong;
      high += 1.0;
      return 1.0;
    case frames::ChangeDecision::kUnchanged:
      high += wrong;
      return 0.0;
    case frames::ChangeDecision::kUndecided: break;
  }
  high += 1.0;
  undecided += 1.0;
  isUndecided = true;
  return exceedanceProbability(std::abs(e.mean), e.standardError, tau);
}

// The rows' sums added in row order, so that the total does not depend on the schedule.
FrameSums addRows(const std::vector<FrameSums>& rows) {
  FrameSums total;
  for (const auto& row : rows) {
    for (std::size_t b = 0; b < 5; ++b) total.count[b] += row.count[b];
    total.directVariance += row.directVariance;
    total.indirectVariance += row.indirectVariance;
    total.directNoisy += row.directNoisy;
    total.indirectNoisy += row.indirectNoisy;
    for (std::size_t b = 0; b < 2; ++b) {
      total.low[b] += row.low[b];
      total.high[b] += row.high[b];
    }
  }
  return total;
}

// Eq. (3.4) over the frame's n pixels, as percentages, with the radiance columns' intervals: a
// 95 % sampling interval for the expected test, bounds for the pairs test.
FramePercentages framePercentages(const FrameSums& total, std::size_t n, const FeatureFrame& current, Thresholds::RadianceTest test, bool pairs) {
  const double scale = 100.0 / static_cast<double>(n);
  FramePercentages p{current.frame, current.time, total.count[0] * scale, total.count[1] * scale, total.count[2] * scale, total.count[3] * scale,
                     total.count[4] * scale, std::nullopt, std::nullopt};
  if (test == Thresholds::RadianceTest::kExpected) {
    // 95 %: the expected count +- 1.96 standard deviations of a sum of independent Bernoulli(p).
    auto interval = [&](double percent, double countVariance) {
      const double half = kZ95 * std::sqrt(countVariance) * scale;
      return Interval{std::max(0.0, percent - half), std::min(100.0, percent + half)};
    };
    p.directInterval = interval(p.direct, total.directVariance);
    p.indirectInterval = interval(p.indirect, total.indirectVariance);
    p.directNoisy = total.directNoisy * scale;
    p.indirectNoisy = total.indirectNoisy * scale;
  } else if (pairs) {
    // Bounds, not a sampling interval: the decided pixels as decided (each widened by its chance
    // of a wrong decision), the undecided ones either way.
    p.directInterval = Interval{std::max(0.0, total.low[0] * scale), std::min(100.0, total.high[0] * scale)};
    p.indirectInterval = Interval{std::max(0.0, total.low[1] * scale), std::min(100.0, total.high[1] * scale)};
    p.directNoisy = total.directNoisy * scale;
    p.indirectNoisy = total.indirectNoisy * scale;
  }
  return p;
}

}  // namespace

DiscardResult discardFrame(const FeatureFrame& current, const FeatureFrame& previous, const Thresholds& t) {
  using Test = Thresholds::RadianceTest;
  DiscardResult result;
  const int w = current.width, h = current.height;
  const auto n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  result.mask.assign(n, 0);
  const bool variance = current.hasVariance() && previous.hasVariance();
  // The pairs test on a frame without pairs is the expected test (discardFolder refuses such
  // folders; a caller comparing two frames directly gets the image-against-image answer).
  const bool pairs = t.radianceTest == Test::kPairs && current.hasChanges();
  const Test test = t.radianceTest == Test::kPairs && !pairs ? Test::kExpected : t.radianceTest;
  constexpr double kGrey = frames::kGreyDistance;
  // Eq. (3.3) on the thesis's pixel-index coordinates (pixel i at x = i): outside [0, w - 1].
  // A pixel that reprojects onto an edge pixel's centre stays inside despite rounding: buffers store
  // float positions, about 1e-7 relative, i.e. up to a few 1e-6 px; the slack is 1e-3 px.
  constexpr double kEdge = 1e-3;
  auto outside = [&](const glm::dvec2& q) {
    const double x = q.x - 0.5, y = q.y - 0.5;
    return x < -kEdge || x > previous.width - 1 + kEdge || y < -kEdge || y > previous.height - 1 + kEdge;
  };
  const Projector currentProjector(current.camera), previousProjector(previous.camera);
  // Rows in parallel (TBB); each row's sums are added in row order at the end, so the result does
  // not depend on the schedule.
  std::vector<FrameSums> rowSums(static_cast<std::size_t>(h));
  tbb::parallel_for(0, h, [&](int py) {
    FrameSums& row = rowSums[static_cast<std::size_t>(py)];
    for (int px = 0; px < w; ++px) {
      const std::size_t i = static_cast<std::size_t>(py) * static_cast<std::size_t>(w) + static_cast<std::size_t>(px);
      unsigned char bits = 0;
      if (current.hit[i] <= 0) {
        // Background: the environment at infinity; its history is only lost at the frustum edge.
        const auto q = previousProjector.direction(currentProjector.pixelDirection(px + 0.5, py + 0.5));
        if (!q || outside(*q)) bits |= kFrustum;
      } else {
        const glm::dvec3 p = at3(current.position, i);
        const auto q = previousProjector.point(p);
        if (!q || outside(*q)) {
          bits |= kFrustum;
        } else {
          // A jittered frame's buffers hold its samples at centre + jitter (render --jitter).
          const BilinearTaps taps = bilinearTaps(q->x - previous.camera.jitter.x, q->y - previous.camera.jitter.y, previous.width, previous.height);
          const double viewDepth = -(current.camera.view * glm::dvec4(p, 1.0)).z;
          const glm::dvec3 normal = at3(current.normal, i);
          const HistoryTest history = testHistory(p, normal, viewDepth, previous, taps, t.surface());
          if (!history.position) bits |= kPosition;
          if (!history.normal) bits |= kNormal;
          // The radiance history: in the taps test, where the 4 x 4 taps around the point are all
          // the same surface, the Catmull-Rom cubic of them (as TAA reads its history): the bilinear
          // sample is a blur, which at a shadow or texture edge a pixel or two wide differs from the
          // edge itself by more than the threshold, a band that halves with the pixel's size.
          const bool tapsTest = t.geometryTest == Thresholds::GeometryTest::kTaps;
          const CubicTaps cubicTaps = tapsTest && history.position
                                          ? catmullRomTaps(q->x - previous.camera.jitter.x, q->y - previous.camera.jitter.y, previous.width, previous.height)
                                          : CubicTaps{};
          bool cubic = tapsTest && history.position && cubicTaps.inside;
          for (std::size_t k = 0; k < 16 && cubic; ++k)
            cubic = previous.hit[cubicTaps.index[k]] > 0 && onTangentPlane(p, normal, at3(previous.position, cubicTaps.index[k]), viewDepth, t.surface());
          // At an edge (the surface has history but its 4 x 4 taps are not all of it) the
          // pixel-filtered radiance mixes surfaces in both frames, in proportions that move with
          // the edge: there the history is the range of the 2 x 2 taps around the point (TAA's
          // neighbourhood clamp, read backwards) and the change is how far the pixel lies outside
          // it. Otherwise a band a pixel or two wide along every silhouette counts as a change of
          // lighting, a share that halves with the pixel's size (docs/metrics.md).
          const bool edge = tapsTest && history.position && !cubic;
          // The probability (0 or 1 for the deterministic tests) that the radiance changed.
          auto radianceChange = [&](const std::vector<float>& now, const std::vector<float>& before, double threshold,
                                    const std::vector<float>& varNow, const std::vector<float>& varBefore, double& noisy) {
            const glm::dvec3 a = at3(now, i), b = cubic ? sample3(before, cubicTaps) : sample3(before, history.history);
            const double d = glm::length(a - b);
            // At an edge, the threshold grows by the history's distance from the range's nearest
            // point to the pixel (on the thresholds' scale), so that what is compared is the
            // pixel's distance outside the range.
            if (edge) {
              double low = 1e300, high = -1e300;
              for (const std::size_t tap : taps.index) {
                const double y = luminance(at3(before, tap));
                low = std::min(low, y);
                high = std::max(high, y);
              }
              threshold += kGrey * std::abs(luminance(b) - std::clamp(luminance(a), low, high));
            }
            // Variance of the difference: the pixel's plus the history sample's, sum of w_k^2 var_k
            // (independent pixels).
            double var = 0.0;
            if (variance && test != Test::kPlain)
              var = varNow[i] + (cubic ? weightedVariance(varBefore, cubicTaps) : weightedVariance(varBefore, history.history));
            switch (test) {
              case Test::kPlain: return d > threshold ? 1.0 : 0.0;
              case Test::kNoiseAware:
                return d > threshold && std::abs(luminance(a) - luminance(b)) > t.noiseSigmas * std::sqrt(var) ? 1.0 : 0.0;
              case Test::kExpected: break;
              case Test::kPairs: break;  // a frame with pairs decides its radiance from them; here as kExpected
            }
            // The expected test compares luminance, the quantity whose variance the renderer
            // records: its difference is an unbiased estimate, where the RGB distance of two noisy
            // pixels is biased up by their noise. On the thresholds' scale it is the RGB distance
            // of a grey change of that luminance, sqrt(3) |dY| (noise scaled alike), so both tests
            // agree on grey changes without noise.
            // Undetermined: noise above half the threshold leaves the outcome to chance (a pixel
            // whose true change is 0 counts 2 Phi(-2) = 5 % or more in expectation).
            if (kGrey * std::sqrt(var) > 0.5 * threshold) noisy += 1.0;
            return exceedanceProbability(kGrey * std::abs(luminance(a) - luminance(b)), kGrey * std::sqrt(var), threshold);
          };
          bool undecidedDirect = false, undecidedIndirect = false;
          const double pd =
              pairs ? pairsChange(changeEstimate(current.directChange, current.changePairs, i), t.direct / kGrey, row.low[0], row.high[0],
                                  row.directNoisy, undecidedDirect)
                    : radianceChange(current.direct, previous.direct, t.direct, current.directVariance, previous.directVariance, row.directNoisy);
          const double pi = pairs ? pairsChange(changeEstimate(current.indirectChange, current.changePairs, i), t.indirect / kGrey, row.low[1],
                                                row.high[1], row.indirectNoisy, undecidedIndirect)
                                  : radianceChange(current.indirect, previous.indirect, t.indirect, current.indirectVariance,
                                                   previous.indirectVariance, row.indirectNoisy);
          row.count[3] += pd;
          row.count[4] += pi;
          row.directVariance += pd * (1.0 - pd);
          row.indirectVariance += pi * (1.0 - pi);
          // The mask shows the more likely outcome; an undecided pair test, as undecided.
          if (pd > 0.5 && !undecidedDirect) bits |= kDirect;
          if (pi > 0.5 && !undecidedIndirect) bits |= kIndirect;
          if (undecidedDirect || undecidedIndirect) bits |= kUndecided;
        }
      }
      result.mask[i] = bits;
      for (int b = 0; b < 3; ++b)
        if (bits & (1u << b)) row.count[static_cast<std::size_t>(b)] += 1.0;
    }
  });
  result.percentages = framePercentages(addRows(rowSums), n, current, test, pairs);
  return result;
}

}  // namespace dynbench::discard
