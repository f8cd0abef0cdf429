// Radiance-change pairs (render --pairs): each sample of a frame re-shaded in the frame before with
// the same random numbers (frames/radiance_change.h decides from them).
#include "render/path_tracer.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/math.h"
#include "frames/radiance_change.h"
#include "render/path_tracer_internal.h"
#include "render/prefetch.h"

namespace dynbench::render {
namespace {

// A radiance-change pair's random numbers: a stream of their own, apart from the image's samples.
constexpr std::uint64_t kPairStream = 0x7061697273ull;  // "pairs"

// Running sums of one pixel's radiance-change pairs: D = Y_t - Y_{t-1} of direct (0) and indirect
// (1) luminance, the smallest and largest D (all equal: no spread at all, whatever the rounding of
// the sums), and |Y_t| + |Y_{t-1}| of the light the halves' paths gathered (not the environment
// seen through the pixel, nor the first hit's own emission, the same in both by construction).
struct ChangeSums {
  std::array<double, 2> sum{}, sumSq{}, gathered{};
  std::array<double, 2> lowest{HUGE_VAL, HUGE_VAL}, highest{-HUGE_VAL, -HUGE_VAL};
  int pairs = 0, attempted = 0;
  bool done = false;

  void add(const std::array<double, 2>& now, const std::array<double, 2>& before, const std::array<double, 2>& light) {
    for (std::size_t b = 0; b < 2; ++b) {
      const double d = now[b] - before[b];
      sum[b] += d;
      sumSq[b] += d * d;
      lowest[b] = std::min(lowest[b], d);
      highest[b] = std::max(highest[b], d);
      gathered[b] += light[b];
    }
    ++pairs;
  }
  // `image`: the frame's own estimate of the pixel's luminance in that buffer (its converged image),
  // a floor under `gathered`: pairs that happened to gather no light (bounces that all missed the
  // one lit wall) say nothing about what the paths that would have could differ by.
  frames::ChangeEstimate estimate(std::size_t b, double image) const {
    frames::ChangeEstimate e;
    e.pairs = pairs;
    if (pairs == 0) return e;
    const double n = pairs;
    e.gathered = std::max(gathered[b] / n, 2.0 * std::abs(image));
    e.mean = sum[b] / n;
    // Pairs whose D are all equal have exactly no spread (all 0: nothing changed on any path).
    if (pairs >= 2 && lowest[b] < highest[b]) e.standardError = std::sqrt(std::max(0.0, (sumSq[b] - n * e.mean * e.mean) / (n - 1.0)) / n);
    if (lowest[b] == highest[b]) e.mean = lowest[b];
    return e;
  }
};

}  // namespace

void PathTracer::renderChanges(std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera, FrameBuffers& frame,
                               RenderStatistics* statistics) const {
  const std::size_t pixels = frame.pixelCount();
  frame.directChange.assign(3 * pixels, 0.0f);
  frame.indirectChange.assign(3 * pixels, 0.0f);
  frame.changePairs.assign(pixels, 0.0f);
  if (!previousRayTracing_ || pixels == 0) return;
  const int width = camera.width(), height = camera.height();
  // The thresholds on luminance: discard's (a fraction of the frame's mean luminance of each
  // buffer, an RGB distance) over sqrt(3), the grey change's scale (frames/radiance_change.h).
  auto imageLuminance = [](const std::vector<float>& rgb, std::size_t i) {
    return luminance(glm::dvec3(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]));
  };
  const std::array<double, 2> tau{settings_.directThresholdFraction * frames::meanLuminance(frame.direct) / frames::kGreyDistance,
                                  settings_.indirectThresholdFraction * frames::meanLuminance(frame.indirect) / frames::kGreyDistance};
  const int cap = std::max(frames::kFirstPairs, settings_.maxPairs);
  const double pixelSpread = std::atan(2.0 * std::tan(0.5 * camera.yfov()) / height);
  const glm::dvec2 jitter = settings_.jitter ? frames::jitterOffset(static_cast<long>(frameIndex)) : glm::dvec2(0.0);
  const std::uint64_t seed = settings_.seed ^ kPairStream;
  const glm::dvec3 cameraNow = camera.position(), cameraBefore = previousCamera.position();
  std::vector<ChangeSums> sums(pixels);

  // Per thread: the path scratch, and a batch's samples with both halves' first vertices and paths.
  struct Batch {
    PathScratch scratch;
    std::vector<std::pair<std::size_t, int>> samples;  // (pixel, sample index)
    std::vector<Ray> rays;
    std::vector<SurfaceHit> hits, previousHits;
    std::vector<FirstVertex> now, before;
    std::vector<PathState> pathsNow, pathsBefore;
    std::vector<std::size_t> traced;  // samples whose halves are traced (the others escaped or have no pair)
  };
  tbb::enumerable_thread_specific<Batch> batches([&] {
    Batch b;
    b.scratch.pixelSpread = pixelSpread;
    return b;
  });
  const std::size_t batchSize = std::max<std::size_t>(1, static_cast<std::size_t>(settings_.pathBatch) / 2);

  // One batch of samples: trace their camera rays in this frame, rebuild each hit in the previous
  // frame, trace both halves, add each pair to its pixel's sums.
  auto trace = [&](Batch& b, std::span<const std::pair<std::size_t, int>> samples) {
    const std::size_t n = samples.size();
    b.rays.resize(n);
    b.hits.resize(n);
    b.previousHits.resize(n);
    b.now.resize(n);
    b.before.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const auto [pixel, sample] = samples[k];
      const int px = static_cast<int>(pixel % static_cast<std::size_t>(width)), py = static_cast<int>(pixel / static_cast<std::size_t>(width));
      Random rng = Random::vertex(seed, frameIndex, pixel, static_cast<std::uint64_t>(sample), 0);
      const glm::dvec2 offset = filter_.atCentre() ? glm::dvec2(0.0) : filter_.offset(rng.uniform2());
      b.rays[k] = camera.ray(px + 0.5 + jitter.x + offset.x, py + 0.5 + jitter.y + offset.y);
    }
    rayTracing_->intersect(b.rays, b.hits);
    b.scratch.rays += n;
    b.pathsNow.clear();
    b.pathsBefore.clear();
    b.traced.clear();
    for (std::size_t k = 0; k < n; ++k) {
      const auto [pixel, sample] = samples[k];
      const SurfaceHit& hit = b.hits[k];
      if (!hit.hit) {
        // The environment, at infinity and unanimated: the same radiance in both frames.
        const double y = environment_ ? luminance(environment_->radiance(b.rays[k].direction)) : 0.0;
        sums[pixel].add({y, 0.0}, {y, 0.0}, {0.0, 0.0});
        continue;
      }
      b.previousHits[k] = previousRayTracing_->surfaceAt(hit);
      if (!b.previousHits[k].hit) continue;  // the surface is not in the previous frame: no pair
      // Both halves' first vertices alike: the view direction from each frame's camera to its
      // point, the texture level of detail of this frame's sample (a filtering choice of the
      // pixel, not a change of its lighting).
      const glm::dvec2 uv = texCoord(hit);
      const glm::dvec3 woNow = glm::normalize(cameraNow - hit.position);
      const auto cornersNow = rayTracing_->trianglePositions(hit);
      const double lod = textureLodAt(hit, cornersNow, -woNow, pixelSpread * hit.distance);
      auto setUp = [&](FirstVertex& v, const SurfaceHit& h, const glm::dvec3& cameraPosition, const std::array<glm::dvec3, 3>& corners,
                       std::vector<PathState>& paths) {
        glm::dvec3 wo = glm::normalize(cameraPosition - h.position);
        // A point the previous camera sees from behind (a silhouette turning away) is shaded from
        // the side this frame sees, the view mirrored in its plane: which side a camera sees is the
        // position column's business, not a change of lighting.
        if (&h != &hit && (glm::dot(h.geometricNormal, wo) > 0) != (glm::dot(hit.geometricNormal, woNow) > 0))
          wo -= 2.0 * glm::dot(wo, h.geometricNormal) * h.geometricNormal;
        v.pixel = pixel;
        v.ray = Ray{cameraPosition, -wo};
        v.hit = &h;
        shadeAt(h, wo, uv, corners, lod, v.shading);
        v.origin = offsetOrigin(h.position, v.shading.geometricNormal);
        PathState& p = paths.emplace_back();
        p.first = &v;
        p.ray = v.ray;
        p.keyed = true;
        p.keySeed = seed;
        p.keyFrame = frameIndex;
        p.keyPixel = pixel;
        p.keySample = static_cast<std::uint64_t>(sample);
        // Both halves' first bounces are sampled from this frame's view, carried into the previous
        // surface's shading frame where it turned: the same lobe and direction wherever the surface
        // did not move, so the rest of the path is the same (see renderChanges in path_tracer.h);
        // both weigh it with the scalar BSDF (the batch's SIMD evaluation rounds differently).
        p.sharedFirstBounce = true;
        const glm::dvec3& nowNormal = b.now[k].shading.shadingNormal;
        p.samplingView = v.shading.shadingNormal == nowNormal ? woNow : Frame(v.shading.shadingNormal).toWorld(Frame(nowNormal).toLocal(woNow));
      };
      setUp(b.now[k], hit, cameraNow, cornersNow, b.pathsNow);
      setUp(b.before[k], b.previousHits[k], cameraBefore, previousRayTracing_->trianglePositions(b.previousHits[k]), b.pathsBefore);
      b.traced.push_back(k);
    }
    if (b.traced.empty()) return;
    b.scratch.pairLights = &pairLights_;
    b.scratch.scene = rayTracing_.get();
    b.scratch.lights = &lights_;
    b.scratch.pairHalf = 0;
    tracePaths(b.pathsNow, b.scratch, true);
    b.scratch.scene = previousRayTracing_.get();
    b.scratch.lights = &previousLights_;
    b.scratch.pairHalf = 1;
    tracePaths(b.pathsBefore, b.scratch, true);
    for (std::size_t j = 0; j < b.traced.size(); ++j) {
      const std::size_t k = b.traced[j];
      const PathSample& now = b.pathsNow[j].out;
      const PathSample& before = b.pathsBefore[j].out;
      const double yNow = luminance(now.direct), yBefore = luminance(before.direct);
      // The first hit's emission reaches the camera unweighted (depth 0): the same in both halves.
      const double gatheredDirect = std::abs(yNow - luminance(b.now[k].shading.material.emission)) +
                                    std::abs(yBefore - luminance(b.before[k].shading.material.emission));
      const double gatheredIndirect = std::abs(luminance(now.indirect)) + std::abs(luminance(before.indirect));
      sums[samples[k].first].add({yNow, luminance(now.indirect)}, {yBefore, luminance(before.indirect)}, {gatheredDirect, gatheredIndirect});
    }
  };

  // Pixels in runs of 8, each in rounds: kFirstPairs pairs, then doubling while either buffer is
  // undecided, up to the cap. A pixel's pairs depend on its own sums alone, so the result does not
  // depend on the thread schedule.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels, 8), [&](const tbb::blocked_range<std::size_t>& run) {
    Batch& b = batches.local();
    for (;;) {
      b.samples.clear();
      for (std::size_t pixel = run.begin(); pixel < run.end(); ++pixel) {
        ChangeSums& sum = sums[pixel];
        if (sum.done) continue;
        const int upTo = sum.attempted == 0 ? frames::kFirstPairs : std::min(cap, 2 * sum.attempted);
        for (int k = sum.attempted; k < upTo; ++k) b.samples.emplace_back(pixel, k);
        sum.attempted = upTo;
      }
      if (b.samples.empty()) break;
      for (std::size_t start = 0; start < b.samples.size(); start += batchSize)
        trace(b, std::span(b.samples).subspan(start, std::min(batchSize, b.samples.size() - start)));
      for (std::size_t pixel = run.begin(); pixel < run.end(); ++pixel) {
        ChangeSums& sum = sums[pixel];
        if (sum.done) continue;
        const bool decided = frames::decideChange(sum.estimate(0, imageLuminance(frame.direct, pixel)), tau[0]) != frames::ChangeDecision::kUndecided &&
                             frames::decideChange(sum.estimate(1, imageLuminance(frame.indirect, pixel)), tau[1]) != frames::ChangeDecision::kUndecided;
        // No pair after the first round: every sample's surface is new in this frame.
        sum.done = decided || sum.attempted >= cap || sum.pairs == 0;
      }
    }
  });

  long undecided = 0;
  double totalPairs = 0.0;
  int mostPairs = 0;
  for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
    const ChangeSums& sum = sums[pixel];
    std::array<frames::ChangeEstimate, 2> estimates{};
    for (std::size_t b = 0; b < 2; ++b) {
      const frames::ChangeEstimate e = estimates[b] = sum.estimate(b, imageLuminance(b == 0 ? frame.direct : frame.indirect, pixel));
      std::vector<float>& out = b == 0 ? frame.directChange : frame.indirectChange;
      out[3 * pixel] = static_cast<float>(e.mean);
      out[3 * pixel + 1] = static_cast<float>(e.standardError);
      out[3 * pixel + 2] = static_cast<float>(e.gathered);
    }
    frame.changePairs[pixel] = static_cast<float>(sum.pairs);
    totalPairs += sum.pairs;
    mostPairs = std::max(mostPairs, sum.pairs);
    if (sum.pairs > 0 && (frames::decideChange(estimates[0], tau[0]) == frames::ChangeDecision::kUndecided ||
                          frames::decideChange(estimates[1], tau[1]) == frames::ChangeDecision::kUndecided))
      ++undecided;
  }
  if (!frame.sampling) frame.sampling = frames::SamplingSummary{};
  frame.sampling->pairCap = cap;
  frame.sampling->maxPairs = mostPairs;
  frame.sampling->meanPairs = totalPairs / static_cast<double>(pixels);
  frame.sampling->undecidedPixels = undecided;
  if (statistics)
    for (const Batch& b : batches) {
      statistics->rays += b.scratch.rays;
      statistics->shadingPoints += b.scratch.shadingPoints;
      statistics->punctualEvaluated += b.scratch.punctualEvaluated;
    }
}

}  // namespace dynbench::render
