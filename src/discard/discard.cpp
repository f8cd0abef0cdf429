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

glm::dvec3 at3(const std::vector<float>& b, std::size_t i) { return {b[3 * i], b[3 * i + 1], b[3 * i + 2]}; }

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
  FrameSums total;
  for (const auto& row : rowSums) {
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
  const double scale = 100.0 / static_cast<double>(n);  // Eq. (3.4), as a percentage
  auto& p = result.percentages;
  p = {current.frame, current.time, total.count[0] * scale, total.count[1] * scale, total.count[2] * scale, total.count[3] * scale,
       total.count[4] * scale, std::nullopt, std::nullopt};
  if (test == Test::kExpected) {
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
  return result;
}

}  // namespace dynbench::discard

namespace dynbench::discard {

Expected<DiscardRun> discardFolder(const std::filesystem::path& dir, const Thresholds& thresholds, const MaskSink& masks,
                                   const DiscardProgress& progress, bool cutsInMean) {
  auto entries = frames::listFrames(dir);
  if (!entries) return std::unexpected(entries.error());
  if (entries->size() < 2) return fail(ErrorCode::kInvalidData, "{}: needs at least two frames (found {})", dir.string(), entries->size());
  DiscardRun run;
  run.thresholds = thresholds;
  bool warnedNoVariance = false;
  std::optional<FeatureFrame> previous;
  for (std::size_t k = 0; k < entries->size(); ++k) {
    auto frame = frames::readFrame((*entries)[k]);
    if (!frame) return std::unexpected(frame.error());
    if (k == 0) {
      run.width = frame->width;
      run.height = frame->height;
      run.sceneSize = sceneSize(*frame);
      if (thresholds.relativePosition && thresholds.geometryTest == Thresholds::GeometryTest::kBilinear && run.sceneSize <= 0)
        return fail(ErrorCode::kInvalidData, "{}: --relative-position needs geometry in the first frame to size the scene",
                    (*entries)[k].image.string());
    } else if (frame->width != run.width || frame->height != run.height) {
      return fail(ErrorCode::kInvalidData, "{}: is {}x{}, but the frames before it are {}x{}", (*entries)[k].image.string(), frame->width,
                  frame->height, run.width, run.height);
    }
    // The pairs test reads frame i's pairs (against i - 1): every frame but the first needs them.
    if (thresholds.radianceTest == Thresholds::RadianceTest::kPairs && k > 0 && !frame->hasChanges())
      return fail(ErrorCode::kInvalidData,
                  "{}: no radiance-change pairs (channels change.direct.*, change.indirect.*, change.pairs), which the default radiance "
                  "test reads; render with dynbench render --converge or --pairs (embree engine), or pass --radiance-test expected for "
                  "the image-against-image test",
                  (*entries)[k].image.string());
    if (thresholds.radianceTest == Thresholds::RadianceTest::kNoiseAware && !frame->hasVariance())
      return fail(ErrorCode::kInvalidData, "{}: --noise-aware needs the direct.var and indirect.var channels", (*entries)[k].image.string());
    if (thresholds.radianceTest == Thresholds::RadianceTest::kExpected && !frame->hasVariance() && !warnedNoVariance) {
      run.warnings.push_back(fmt::format("{}: no direct.var / indirect.var channels: the radiance columns treat the frames as noise-free "
                                         "(their intervals are 0 wide); render with dynbench for variances",
                                         (*entries)[k].image.string()));
      warnedNoVariance = true;
    }
    if (previous) {
      if (previous->frame + 1 != frame->frame) {
        run.warnings.push_back(fmt::format("frames {} and {} are not consecutive: pair skipped", previous->frame, frame->frame));
      } else {
        DiscardResult r = discardFrame(*frame, *previous, absoluteThresholds(thresholds, *frame, run.sceneSize));
        r.percentages.cut = frame->cut;
        run.cutPairs += frame->cut ? 1 : 0;
        run.frames.push_back(r.percentages);
        if (masks)
          if (auto ok = masks(*frame, r); !ok) return std::unexpected(ok.error());
      }
    }
    previous = std::move(*frame);
    if (progress) progress(k + 1, entries->size());
  }
  if (run.frames.empty()) return fail(ErrorCode::kInvalidData, "{}: no two consecutive frames to compare", dir.string());
  run.cutsInMean = cutsInMean;
  // The pairs Eq. (3.5) averages over: all, or those that are not cuts.
  std::vector<const FramePercentages*> averaged;
  for (const auto& f : run.frames)
    if (cutsInMean || !f.cut) averaged.push_back(&f);
  if (averaged.empty())
    return fail(ErrorCode::kInvalidData, "{}: every frame pair is a camera cut; nothing to average (--include-cuts averages them)", dir.string());
  if (run.cutPairs > 0)
    run.warnings.push_back(fmt::format("{} of {} frame pairs are camera cuts; the mean {}", run.cutPairs, run.frames.size(),
                                       cutsInMean ? "includes them" : "leaves them out (--include-cuts keeps them)"));
  run.mean.frame = -1;
  for (const FramePercentages* p : averaged) {
    const auto& f = *p;
    run.mean.frustum += f.frustum;
    run.mean.position += f.position;
    run.mean.normal += f.normal;
    run.mean.direct += f.direct;
    run.mean.indirect += f.indirect;
  }
  const double n = static_cast<double>(averaged.size());  // Eq. (3.5)
  for (double* v : {&run.mean.frustum, &run.mean.position, &run.mean.normal, &run.mean.direct, &run.mean.indirect}) *v /= n;
  // The uncertain pixels' shares (the pairs test's undecided, the expected test's noisy; 0 for the others).
  for (const FramePercentages* f : averaged) {
    run.mean.directNoisy += f->directNoisy / n;
    run.mean.indirectNoisy += f->indirectNoisy / n;
  }
  if (thresholds.radianceTest == Thresholds::RadianceTest::kPairs) {
    // Bounds average as the columns do.
    auto meanBounds = [&](std::optional<Interval> FramePercentages::*member) {
      Interval mean;
      for (const FramePercentages* f : averaged) {
        mean.low += (f->*member)->low / n;
        mean.high += (f->*member)->high / n;
      }
      return mean;
    };
    run.mean.directInterval = meanBounds(&FramePercentages::directInterval);
    run.mean.indirectInterval = meanBounds(&FramePercentages::indirectInterval);
    for (const auto& [name, undecided] : {std::pair{"direct", run.mean.directNoisy}, {"indirect", run.mean.indirectNoisy}})
      if (undecided > kUndecidedWarning)
        run.warnings.push_back(fmt::format("the {} radiance column is uncertain: {:.2f} % of the pixels stayed undecided at the render's "
                                           "pair cap (render with a higher --max-pairs)",
                                           name, undecided));
  } else if (thresholds.radianceTest == Thresholds::RadianceTest::kExpected) {
    // The mean of independent frame estimates: half-widths add in quadrature, over n.
    auto meanInterval = [&](double mean, std::optional<Interval> FramePercentages::*member) {
      double sumSq = 0.0;
      for (const FramePercentages* f : averaged) sumSq += std::pow((f->*member)->halfWidth(), 2);
      const double half = std::sqrt(sumSq) / n;
      return Interval{std::max(0.0, mean - half), std::min(100.0, mean + half)};
    };
    run.mean.directInterval = meanInterval(run.mean.direct, &FramePercentages::directInterval);
    run.mean.indirectInterval = meanInterval(run.mean.indirect, &FramePercentages::indirectInterval);
    // The interval covers the count's chance, not the bias noise gives the expected test: say
    // when a column is mostly noise.
    for (const auto& [name, noisy] : {std::pair{"direct", run.mean.directNoisy}, {"indirect", run.mean.indirectNoisy}})
      if (noisy > kNoisyWarning)
        run.warnings.push_back(fmt::format("the {} radiance column is uncertain: the noise of {:.1f} % of the pixels exceeds half the "
                                           "threshold, and noise alone counts as change there (render with --converge, a lower "
                                           "--tolerance or a higher --max-spp)",
                                           name, noisy));
  }
  return run;
}

std::vector<float> maskImage(const FeatureFrame& frame, const std::vector<unsigned char>& mask) {
  static const glm::dvec3 colours[6] = {{1, 0.1, 0.1}, {1, 0.9, 0.1}, {0.2, 0.4, 1}, {1, 0.2, 1}, {0.1, 1, 1}, {0.85, 0.85, 0.85}};
  const std::size_t n = mask.size();
  const frames::PreviewToneMap toneMap(frame);
  std::vector<float> rgb(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    glm::dvec3 c = toneMap(frame, i) * 0.45;  // dimmed, so the reasons' colours stand out
    for (int b = 0; b < 6; ++b)
      if (mask[i] & (1u << b)) {
        c = 0.3 * c + 0.7 * colours[b];
        break;
      }
    for (int k = 0; k < 3; ++k) rgb[3 * i + static_cast<std::size_t>(k)] = static_cast<float>(c[k]);
  }
  return rgb;
}

namespace {

nlohmann::json percentagesJson(const FramePercentages& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& column : kTable67Columns) j[column.key] = p.*column.member;
  if (p.directInterval && p.indirectInterval)
    for (const auto& column : kTable67Columns) {
      if (!column.interval) continue;
      const Interval& interval = *(p.*column.interval);
      j["interval"][column.key] = {interval.low, interval.high};
      j["noisy"][column.key] = p.*column.noisy;
    }
  return j;
}

}  // namespace

std::string discardJson(const DiscardRun& run, const std::string& framesDir) {
  const auto& t = run.thresholds;
  nlohmann::json j;
  j["frames_dir"] = framesDir;
  j["width"] = run.width;
  j["height"] = run.height;
  j["scene_size"] = run.sceneSize;
  j["thresholds"] = {{"geometry_test", geometryTestName(t.geometryTest)},
                     {"position", t.position},       {"relative_position", t.relativePosition}, {"normal", t.normal},
                     {"direct", t.direct},           {"indirect", t.indirect},                 {"absolute_radiance", t.absoluteRadiance},
                     {"radiance_test", radianceTestName(t.radianceTest)}, {"noise_sigmas", t.noiseSigmas}};
  j["mean"] = percentagesJson(run.mean);
  j["cut_pairs"] = run.cutPairs;
  j["cuts_in_mean"] = run.cutsInMean;
  j["frames"] = nlohmann::json::array();
  for (const auto& f : run.frames) {
    auto row = percentagesJson(f);
    row["frame"] = f.frame;
    row["time"] = f.time;
    if (f.cut) row["cut"] = true;
    j["frames"].push_back(row);
  }
  j["warnings"] = run.warnings;
  return j.dump(2) + "\n";
}

namespace {

Expected<FramePercentages> readPercentages(const JsonFields& f, const std::string& base) {
  FramePercentages p;
  for (const auto& column : kTable67Columns) {
    auto v = f.number(base + "/" + column.key);
    if (!v) return std::unexpected(v.error());
    p.*column.member = *v;
  }
  // The radiance columns' intervals (files of the other radiance tests and of earlier versions have
  // none) and uncertain shares (files of earlier versions have none): both optional.
  for (const auto& column : kTable67Columns) {
    if (!column.interval) continue;
    if (f.has(base + "/interval")) {
      const std::string pointer = base + "/interval/" + column.key;
      auto low = f.number(pointer + "/0");
      if (!low) return std::unexpected(low.error());
      auto high = f.number(pointer + "/1");
      if (!high) return std::unexpected(high.error());
      p.*column.interval = Interval{*low, *high};
    }
    const std::string pointer = base + "/noisy/" + column.key;
    if (!f.has(pointer)) continue;
    auto v = f.number(pointer);
    if (!v) return std::unexpected(v.error());
    p.*column.noisy = *v;
  }
  return p;
}

}  // namespace

Expected<DiscardRun> readDiscardJson(const std::filesystem::path& path) {
  auto j = readJsonFile(path);
  if (!j) return std::unexpected(j.error());
  const JsonFields f(*j, path);
  DiscardRun run;
  for (auto [key, target] : {std::pair{"/width", &run.width}, {"/height", &run.height}}) {
    auto v = f.integer(key);
    if (!v) return std::unexpected(v.error());
    *target = static_cast<int>(*v);
  }
  // The radiance test: optional (files of earlier versions have none, and were the expected test's).
  run.thresholds.radianceTest = Thresholds::RadianceTest::kExpected;
  if (f.has("/thresholds/radiance_test")) {
    auto name = f.string("/thresholds/radiance_test");
    if (!name) return std::unexpected(name.error());
    bool known = false;
    for (const auto test : {Thresholds::RadianceTest::kPairs, Thresholds::RadianceTest::kExpected, Thresholds::RadianceTest::kNoiseAware,
                            Thresholds::RadianceTest::kPlain})
      if (*name == radianceTestName(test)) {
        run.thresholds.radianceTest = test;
        known = true;
      }
    if (!known)
      return fail(ErrorCode::kInvalidData, "{}: /thresholds/radiance_test: expected pairs, expected, noise-aware or plain (got '{}')",
                  path.string(), *name);
  }
  auto mean = readPercentages(f, "/mean");
  if (!mean) return std::unexpected(mean.error());
  run.mean = *mean;
  run.mean.frame = -1;
  auto frames = f.value("/frames");
  if (!frames) return std::unexpected(frames.error());
  if (!(*frames)->is_array()) return fail(ErrorCode::kInvalidData, "{}: /frames: expected an array", path.string());
  for (std::size_t k = 0; k < (*frames)->size(); ++k) {
    const std::string base = fmt::format("/frames/{}", k);
    auto p = readPercentages(f, base);
    if (!p) return std::unexpected(p.error());
    auto frame = f.integer(base + "/frame");
    if (!frame) return std::unexpected(frame.error());
    auto time = f.number(base + "/time");
    if (!time) return std::unexpected(time.error());
    p->frame = static_cast<long>(*frame);
    if (f.has(base + "/cut")) {
      auto cut = f.boolean(base + "/cut");
      if (!cut) return std::unexpected(cut.error());
      p->cut = *cut;
      run.cutPairs += p->cut ? 1 : 0;
    }
    p->time = *time;
    run.frames.push_back(*p);
  }
  return run;
}

}  // namespace dynbench::discard
