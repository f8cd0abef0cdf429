#pragma once
// The radiance-change pairs' contract (docs/feature-buffers.md, "Radiance change"; docs/metrics.md,
// "Radiance discard"): how a pixel's pairs decide whether its direct or indirect radiance changed
// between two frames by more than a threshold. The renderer uses it to know when a pixel has
// enough pairs (render/path_tracer.cpp, renderChanges), discard to count the pixel (Table 6.7's
// radiance columns): one rule in one place, so the two cannot disagree.
//
// A pair is one pixel-filter sample of frame t whose first hit is rebuilt in frame t - 1's scene
// and shaded in both with the same random numbers; D = Y_t - Y_{t-1} is the difference of the two
// halves' luminance. Where nothing on the path changed both halves compute the same numbers and D
// is exactly 0; where something did, D is an unbiased sample of the change.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "core/math.h"  // luminance

namespace dynbench::frames {

// sqrt(3): the RGB distance of a grey change per unit of luminance, the scale discard's radiance
// thresholds are on (docs/metrics.md).
inline constexpr double kGreyDistance = 1.7320508075688772;

// Discard's default radiance thresholds, direct and indirect alike: a change of a tenth of the
// frame's mean luminance of that buffer (docs/metrics.md). The render's adaptive sampling and its
// pairs aim at the same threshold (RenderSettings), so both read it from here.
inline constexpr double kDefaultRadianceThreshold = 0.1;

// The mean luminance of an RGB buffer (3 floats a pixel): what a relative radiance threshold is a
// fraction of (discard's defaults).
inline double meanLuminance(const std::vector<float>& rgb) {
  const std::size_t n = rgb.size() / 3;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) sum += luminance(glm::dvec3(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]));
  return n ? sum / static_cast<double>(n) : 0.0;
}

// One pixel's pairs for one buffer (direct or indirect), in luminance units.
struct ChangeEstimate {
  double mean = 0.0;           // the mean of D over the pairs
  double standardError = 0.0;  // the sample standard deviation of D (n - 1) over sqrt(n)
  // The mean over the pairs of |Y_t| + |Y_{t-1}| of the light the halves' paths gathered (without the
  // environment seen directly and the first hit's own emission, the same in both by construction),
  // and at least twice the pixel's luminance in frame t's image: what a pair whose paths diverged
  // could differ by, on average.
  double gathered = 0.0;
  int pairs = 0;               // n
};

enum class ChangeDecision { kUnchanged, kChanged, kUndecided };

// The sequential test's z: a decision needs the estimate z standard errors clear of the threshold
// (one-sided 0.135 % per look; docs/metrics.md bounds the error rate over the looks).
inline constexpr double kChangeZ = 3.0;
// The pair schedule: the first round's pairs, then each round doubles the pixel's pairs up to the
// cap (RenderSettings::maxPairs).
inline constexpr int kFirstPairs = 4;

// The rule of three's bound on what changes no pair has shown yet: after n pairs whose D are all
// the same, the share of paths that would diverge (touch something that changed) is below 3 / n at
// 95 %, and a diverging pair's |D| is at most |Y_t| + |Y_{t-1}|, on average `gathered`:
// 3 gathered / n. (The largest sample instead of the mean, as first planned, left 99 % of a static
// room's indirect pixels undecided at 256 pairs: indirect light is heavy-tailed, and the largest of
// n samples grows with n.)
inline double unseenChangeBound(const ChangeEstimate& e) {
  return e.pairs > 0 ? 3.0 * e.gathered / static_cast<double>(e.pairs) : HUGE_VAL;
}

// With at least two pairs: changed when |d| - tau > z s; unchanged when |d| + z s < tau, and where every D was exactly the
// same (s = 0: nothing on any path changed, or everything by the same amount) only when the
// unseen-change bound is below tau too; else undecided (more pairs, or counted as uncertain).
// tau is the threshold on luminance (discard's RGB threshold / sqrt(3)). A bound of exactly 0
// (every D 0 and no light gathered on any path: a black pixel) is unchanged under any tau, also
// 0: a buffer black over the whole frame has a relative threshold of 0, and its every pixel stayed
// undecided up to the pair cap (4096 pairs a pixel for nothing).
inline ChangeDecision decideChange(const ChangeEstimate& e, double tau) {
  if (e.pairs < 2) return ChangeDecision::kUndecided;  // no spread to judge by
  const double d = std::abs(e.mean), s = e.standardError;
  if (d - tau > kChangeZ * s) return ChangeDecision::kChanged;
  const double unseen = s > 0 ? 0.0 : unseenChangeBound(e);
  const double bound = d + kChangeZ * s + unseen;
  if (bound < tau || bound == 0.0) return ChangeDecision::kUnchanged;
  return ChangeDecision::kUndecided;
}

// How many times the test was applied to a pixel with n pairs under the schedule (rounds of
// kFirstPairs, then doubling): 1 + ceil(log2(n / kFirstPairs)), at least 1. Bounds the error of
// the sequential test (Bonferroni over its looks).
inline int changeLooks(int pairs) {
  if (pairs <= kFirstPairs) return 1;
  return 1 + static_cast<int>(std::ceil(std::log2(static_cast<double>(pairs) / kFirstPairs) - 1e-9));
}

}  // namespace dynbench::frames
