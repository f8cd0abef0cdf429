// The folder run: a frames folder streamed two frames at a time, each pair compared, the mean over
// the pairs (Eq. 3.5); and the mask images of Figure 6.2.
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

}  // namespace dynbench::discard
