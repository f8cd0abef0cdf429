// One frame: camera rays, the first hits, and adaptive sampling in rounds (render --converge).
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

// The stream of a pixel's filter shift (Random's `sample` key): no sample has this index.
constexpr std::uint64_t kFilterShiftStream = 0xFFFFFFFFFFFFull;

// Running sums of one pixel's samples.
struct PixelSums {
  glm::dvec3 direct{0.0}, indirect{0.0};
  double directSq = 0.0, indirectSq = 0.0;  // of luminance
  int samples = 0;

  void add(const glm::dvec3& d, const glm::dvec3& i) {
    direct += d;
    indirect += i;
    directSq += luminance(d) * luminance(d);
    indirectSq += luminance(i) * luminance(i);
    ++samples;
  }
  // Variance of the pixel's mean luminance: the sample variance (n - 1 denominator) over n.
  double varianceOfMean(double sum, double sumSq) const {
    const double n = samples;
    if (n < 2) return 0.0;
    const double mean = sum / n;
    return std::max(0.0, (sumSq - n * mean * mean) / (n - 1.0)) / n;
  }
  double directVariance() const { return varianceOfMean(luminance(direct), directSq); }
  double indirectVariance() const { return varianceOfMean(luminance(indirect), indirectSq); }
};

// The next sample count of an adaptive pixel: the count its present standard error predicts for
// the target (SE falls as 1/sqrt(n)), 10 % over, at least one more round of `round` samples and at
// most four times as many, capped.
int nextSampleCount(int n, double ratioSquared, int round, int cap) {
  const double predicted = std::ceil(1.1 * n * ratioSquared);
  const double next = std::clamp(predicted, static_cast<double>(n + round), 4.0 * n);
  return static_cast<int>(std::min<double>(cap, next));
}

}  // namespace

LightVisibility PathTracer::learnLightVisibility(const RenderCamera& camera, std::uint64_t frameIndex) const {
  LightVisibility visibility;
  if (!settings_.learnedLightSelection || !settings_.nextEventEstimation || settings_.lightsPerPoint <= 0 || !lights_.hasPunctualTree())
    return visibility;
  const int columns = (camera.width() + kPilotStride - 1) / kPilotStride, rows = (camera.height() + kPilotStride - 1) / kPilotStride;
  const auto lattice = static_cast<std::size_t>(columns) * static_cast<std::size_t>(rows);
  // Two slots a lattice pixel (its first hit, its bounce's hit), filled in parallel, then the
  // points found kept in slot order.
  std::vector<LightVisibility::Point> slots(2 * lattice);
  std::vector<std::uint8_t> found(2 * lattice, 0);
  auto facing = [](const SurfaceHit& hit, const glm::dvec3& direction) {
    return glm::dot(hit.geometricNormal, direction) < 0 ? hit.geometricNormal : -hit.geometricNormal;
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lattice, 64), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t k = range.begin(); k < range.end(); ++k) {
      const int px = static_cast<int>(k % static_cast<std::size_t>(columns)) * kPilotStride;
      const int py = static_cast<int>(k / static_cast<std::size_t>(columns)) * kPilotStride;
      const Ray ray = camera.ray(px + 0.5, py + 0.5);
      const SurfaceHit hit = trace(ray);
      if (!hit.hit) continue;
      const glm::dvec3 normal = facing(hit, ray.direction);
      slots[2 * k] = {hit.position, normal};
      found[2 * k] = 1;
      const auto pixel = static_cast<std::uint64_t>(py) * static_cast<std::uint64_t>(camera.width()) + static_cast<std::uint64_t>(px);
      Random rng(kPilotSeed, frameIndex, pixel, 0);
      const Ray bounce{offsetOrigin(hit.position, normal), Frame(normal).toWorld(sampleCosineHemisphere(rng.uniform2()))};
      const SurfaceHit next = trace(bounce);
      if (!next.hit) continue;
      slots[2 * k + 1] = {next.position, facing(next, bounce.direction)};
      found[2 * k + 1] = 1;
    }
  });
  std::vector<LightVisibility::Point> points;
  for (std::size_t s = 0; s < slots.size(); ++s)
    if (found[s]) points.push_back(slots[s]);
  const double cellSize = 2.0 * sceneRadius_.value_or(1.0) / kVisibilityCellsAcross;
  visibility.learn(lights_, points, cellSize, [this](const LightVisibility::Point& p, const LightSample& sample) {
    return !rayTracing_->occluded(offsetOrigin(p.position, p.normal), sample.direction, shadowRayEnd(sample.distance));
  });
  return visibility;
}

// One frame's samples (render): each pixel's running sums and first hit, and the paths queued in
// each thread's scratch and traced in batches. render runs its steps in order: the first round
// (with the geometry buffers), the adaptive rounds (--converge), then the radiance buffers.
class PathTracer::FrameSampler {
 public:
  FrameSampler(const PathTracer& tracer, std::uint64_t frameIndex, const RenderCamera& camera, const LightVisibility& visibility)
      : tracer_(tracer),
        settings_(tracer.settings_),
        frameIndex_(frameIndex),
        camera_(camera),
        width_(camera.width()),
        height_(camera.height()),
        // Adaptive sampling needs a variance estimate to stop on: its first round has at least 16 samples.
        firstRound_(settings_.converge ? std::max(settings_.samplesPerPixel, kMinFirstRound) : settings_.samplesPerPixel),
        pixels_(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_)),
        // A pixel's ray cone spreads by this angle (radians) per unit of length (textureLod).
        pixelSpread_(std::atan(2.0 * std::tan(0.5 * camera.yfov()) / height_)),
        jitter_(settings_.jitter ? frames::jitterOffset(static_cast<long>(frameIndex)) : glm::dvec2(0.0)),
        filtered_(!tracer.filter_.atCentre()),
        sums_(pixels_),
        firstHits_(pixels_),
        scratches_([&tracer, spread = pixelSpread_, &visibility] {
          PathScratch scratch;
          scratch.scene = tracer.rayTracing_.get();
          scratch.lights = &tracer.lights_;
          scratch.visibility = visibility.empty() ? nullptr : &visibility;
          scratch.pixelSpread = spread;
          return scratch;
        }) {}

  // First round: the geometry buffers from the ray through each pixel centre (so that P, N, Z,
  // id and motion describe one surface point; a blend of two surfaces across an edge is on
  // neither), then samplesPerPixel paths from that same hit.
  void firstRound(const RenderCamera& previousCamera, FrameBuffers& out, std::atomic<int>* rowsDone) {
    const glm::dvec3 forward = -glm::dvec3(camera_.world()[2]);
    tbb::parallel_for(tbb::blocked_range<int>(0, height_, 1), [&](const tbb::blocked_range<int>& rows) {
      PathScratch& scratch = scratches_.local();
      for (int py = rows.begin(); py < rows.end(); ++py) {
        for (int px = 0; px < width_; ++px) {
          const std::size_t pixel = static_cast<std::size_t>(py) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(px);
          const Ray ray = pixelRay(pixel);
          const SurfaceHit hit = tracer_.trace(ray);
          ++scratch.rays;
          firstHits_[pixel] = hit;
          std::optional<Shading> shading;
          if (hit.hit) {
            const Shading& s = shading.emplace(tracer_.shade(hit, -ray.direction, tracer_.texCoord(hit), pixelSpread_ * hit.distance));
            put3(out.position, pixel, hit.position);
            put3(out.normal, pixel, s.shadingNormal);
            put3(out.albedo, pixel, s.material.baseColor);
            out.depth[pixel] = static_cast<float>(glm::dot(hit.position - camera_.position(), forward));
            out.id[pixel] = static_cast<float>(hit.node);
            out.hit[pixel] = 1.0f;
            const PixelProjection previous = previousCamera.project(tracer_.rayTracing_->previousPosition(hit));
            // Behind the previous camera there is no pixel to point to: a vector far off screen.
            const glm::dvec2 target = previous.inFront ? previous.pixel : glm::dvec2(-1e9);
            out.motion[2 * pixel] = static_cast<float>(target.x - (px + 0.5 + jitter_.x));
            out.motion[2 * pixel + 1] = static_cast<float>(target.y - (py + 0.5 + jitter_.y));
          }
          enqueue(pixel, ray, firstRound_, scratch, shading ? &*shading : nullptr);
          flush(scratch, false);
        }
        flush(scratch, true);
        if (rowsDone && !settings_.converge) rowsDone->fetch_add(1, std::memory_order_relaxed);
      }
    });
  }

  // Adaptive sampling (--converge). The targets: tolerance x the discard threshold of each buffer,
  // which is a fraction of the frame's mean luminance (discard's default relative thresholds),
  // estimated from the first round. A pixel converges when both standard errors are at or below
  // their targets. Fills the summary's targets and capped pixels.
  void adaptiveRounds(frames::SamplingSummary& summary, std::atomic<int>* rowsDone) {
    double meanDirect = 0.0, meanIndirect = 0.0;
    for (const auto& p : sums_) {
      meanDirect += luminance(p.direct) / p.samples;
      meanIndirect += luminance(p.indirect) / p.samples;
    }
    meanDirect /= static_cast<double>(pixels_);
    meanIndirect /= static_cast<double>(pixels_);
    summary.adaptive = true;
    summary.tolerance = settings_.tolerance;
    // Discard's expected test measures a luminance change on the thresholds' RGB scale, x sqrt(3)
    // (a grey change): the luminance standard error's target is the threshold's share over sqrt(3).
    summary.directTarget = settings_.tolerance * settings_.directThresholdFraction * meanDirect / frames::kGreyDistance;
    summary.indirectTarget = settings_.tolerance * settings_.indirectThresholdFraction * meanIndirect / frames::kGreyDistance;
    const double directTargetSq = summary.directTarget * summary.directTarget;
    const double indirectTargetSq = summary.indirectTarget * summary.indirectTarget;
    const int cap = std::max(firstRound_, settings_.maxSamplesPerPixel);
    // Each pixel sampled in rounds until it converges; its random streams are its sample indices,
    // so the result does not depend on the thread schedule. Scheduled in runs of 8 pixels, not
    // rows: a row of capped pixels costs seconds, and a core would wait for it at the frame's end.
    std::atomic<std::size_t> pixelsDone{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels_, 8), [&](const tbb::blocked_range<std::size_t>& run) {
      PathScratch& scratch = scratches_.local();
      auto ratio = [](double variance, double targetSq) {
        if (variance <= 0) return 0.0;
        return targetSq > 0 ? variance / targetSq : std::numeric_limits<double>::infinity();
      };
      // In rounds: every pixel of the run that has not converged queues its next samples, then
      // they are traced together. A pixel's counts depend on its own sums alone.
      for (bool queued = true; queued;) {
        queued = false;
        for (std::size_t pixel = run.begin(); pixel < run.end(); ++pixel) {
          const PixelSums& sum = sums_[pixel];
          if (sum.samples >= cap) continue;
          const double r = std::max(ratio(sum.directVariance(), directTargetSq), ratio(sum.indirectVariance(), indirectTargetSq));
          if (r <= 1.0) continue;
          enqueue(pixel, pixelRay(pixel), nextSampleCount(sum.samples, r, firstRound_, cap), scratch);
          queued = true;
        }
        flush(scratch, true);
      }
      const std::size_t done = pixelsDone.fetch_add(run.size(), std::memory_order_relaxed) + run.size();
      // Whole rows' worth, for progress; the last run's store below makes it `height` exactly.
      if (rowsDone) rowsDone->store(std::min(height_ - 1, static_cast<int>(done / static_cast<std::size_t>(width_))), std::memory_order_relaxed);
    });
    if (rowsDone) rowsDone->store(height_, std::memory_order_relaxed);
    for (const auto& p : sums_)
      if (p.samples >= cap && (p.directVariance() > directTargetSq || p.indirectVariance() > indirectTargetSq)) ++summary.cappedPixels;
  }

  // The radiance buffers and their variances from the sums, and the summary's sample counts;
  // returns the frame's samples.
  std::uint64_t writeRadiance(FrameBuffers& out, frames::SamplingSummary& summary) const {
    std::uint64_t totalSamples = 0;
    summary.minSamples = std::numeric_limits<int>::max();
    for (std::size_t pixel = 0; pixel < pixels_; ++pixel) {
      const PixelSums& p = sums_[pixel];
      const double n = p.samples;
      put3(out.direct, pixel, p.direct / n);
      put3(out.indirect, pixel, p.indirect / n);
      out.directVariance[pixel] = static_cast<float>(p.directVariance());
      out.indirectVariance[pixel] = static_cast<float>(p.indirectVariance());
      out.spp[pixel] = static_cast<float>(p.samples);
      totalSamples += static_cast<std::uint64_t>(p.samples);
      summary.minSamples = std::min(summary.minSamples, p.samples);
      summary.maxSamples = std::max(summary.maxSamples, p.samples);
    }
    summary.meanSamples = pixels_ ? static_cast<double>(totalSamples) / static_cast<double>(pixels_) : 0.0;
    return totalSamples;
  }

  // The threads' ray, shading-point and light counts.
  void addCounts(RenderStatistics& statistics) const {
    for (const auto& scratch : scratches_) {
      statistics.rays += scratch.rays;
      statistics.shadingPoints += scratch.shadingPoints;
      statistics.punctualEvaluated += scratch.punctualEvaluated;
    }
  }

 private:
  // The ray through a pixel's (jittered) centre.
  Ray pixelRay(std::size_t pixel) const {
    const int px = static_cast<int>(pixel % static_cast<std::size_t>(width_)), py = static_cast<int>(pixel / static_cast<std::size_t>(width_));
    return camera_.ray(px + 0.5 + jitter_.x, py + 0.5 + jitter_.y);
  }
  // A pixel's shift of its stratified filter points, from a stream of its own.
  glm::dvec2 filterShift(std::size_t pixel) const { return Random(settings_.seed, frameIndex_, pixel, kFilterShiftStream).uniform2(); }
  // With a pixel filter: a radiance sample's own camera ray, through the (jittered) pixel centre
  // offset by the filter, at the sample's stratified point (stratifiedPoint, with the pixel's
  // filterShift). The sample's stream still gives up its first two numbers, which drew the point
  // before, so the rest of the path draws what it drew.
  Ray filteredRay(std::size_t pixel, Random& rng, std::uint32_t sample, glm::dvec2 shift) const {
    const int px = static_cast<int>(pixel % static_cast<std::size_t>(width_)), py = static_cast<int>(pixel / static_cast<std::size_t>(width_));
    (void)rng.uniform2();
    const glm::dvec2 offset = tracer_.filter_.offset(stratifiedPoint(sample, shift));
    return camera_.ray(px + 0.5 + jitter_.x + offset.x, py + 0.5 + jitter_.y + offset.y);
  }
  // A pixel's samples up to `upTo`: at the pixel centre, one environment lookup where its camera
  // ray `ray` escapes, else its paths queued in the thread's scratch (`known`: the first hit's
  // shading when the caller has it already, the first round's buffers); with a filter, its paths
  // queued to trace their own camera rays. flush traces them.
  void enqueue(std::size_t pixel, const Ray& ray, int upTo, PathScratch& scratch, const Shading* known = nullptr) {
    const SurfaceHit& hit = firstHits_[pixel];
    PixelSums& sum = sums_[pixel];
    if (!filtered_ && !hit.hit) {
      // The camera sees the environment: a single lookup, no noise.
      const glm::dvec3 le = tracer_.environment_ ? tracer_.environment_->radiance(ray.direction) : glm::dvec3(0.0);
      while (sum.samples < upTo) sum.add(le, glm::dvec3(0.0));
      return;
    }
    if (sum.samples >= upTo) return;
    if (scratch.queueEnd == scratch.queue.size()) scratch.queue.emplace_back();
    FirstVertex& v = scratch.queue[scratch.queueEnd++];
    v.pixel = pixel;
    v.ray = ray;
    v.hit = filtered_ ? nullptr : &hit;
    if (!filtered_) {
      if (known) v.shading = *known;
      else tracer_.shade(hit, -ray.direction, tracer_.texCoord(hit), pixelSpread_ * hit.distance, *tracer_.rayTracing_, v.shading);
      v.origin = offsetOrigin(hit.position, v.shading.geometricNormal);
    }
    v.next = sum.samples;
    v.upTo = upTo;
  }
  // Traces the queued paths in batches of pathBatch, in queue order, each path with the random
  // stream of its pixel and sample index, and sums them per pixel in sample order; a batch may
  // span several pixels (at 16 spp one pixel filled half a batch, and a shorter batch hides less of
  // the memory latency and fills fewer SIMD lanes). `all`: also the last, partial batch. Each path
  // computes what it would alone, so the image does not depend on how pixels share batches.
  void flush(PathScratch& scratch, bool all) {
    auto& queue = scratch.queue;
    const auto batchSize = static_cast<std::size_t>(settings_.pathBatch);
    while (true) {
      std::size_t waiting = 0;
      for (std::size_t q = scratch.queueHead; q < scratch.queueEnd && waiting < batchSize; ++q)
        waiting += static_cast<std::size_t>(queue[q].upTo - queue[q].next);
      if (waiting == 0 || (waiting < batchSize && !all)) break;
      const std::size_t batch = std::min(waiting, batchSize);
      scratch.paths.resize(std::max(scratch.paths.size(), batch));
      const std::span<PathState> paths(scratch.paths.data(), batch);
      std::size_t n = 0;
      for (std::size_t q = scratch.queueHead; n < batch; ++q) {
        FirstVertex& v = queue[q];
        const glm::dvec2 shift = v.hit || v.next >= v.upTo ? glm::dvec2(0.0) : filterShift(v.pixel);
        for (; v.next < v.upTo && n < batch; ++v.next, ++n) {
          paths[n].first = &v;
          paths[n].rng = Random(settings_.seed, frameIndex_, v.pixel, static_cast<std::uint64_t>(v.next));
          paths[n].ray = v.hit ? v.ray : filteredRay(v.pixel, paths[n].rng, static_cast<std::uint32_t>(v.next), shift);
        }
      }
      tracer_.tracePaths(paths, scratch);
      for (const PathState& p : paths) sums_[p.first->pixel].add(p.out.direct, p.out.indirect);
      while (scratch.queueHead < scratch.queueEnd && queue[scratch.queueHead].next == queue[scratch.queueHead].upTo) ++scratch.queueHead;
      if (scratch.queueHead == scratch.queueEnd) scratch.queueHead = scratch.queueEnd = 0;
    }
  }

  const PathTracer& tracer_;
  const RenderSettings& settings_;
  const std::uint64_t frameIndex_;
  const RenderCamera& camera_;
  const int width_, height_, firstRound_;
  const std::size_t pixels_;
  const double pixelSpread_;
  const glm::dvec2 jitter_;
  const bool filtered_;
  std::vector<PixelSums> sums_;
  std::vector<SurfaceHit> firstHits_;
  tbb::enumerable_thread_specific<PathScratch> scratches_;
};

FrameBuffers PathTracer::render(std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera,
                                std::atomic<int>* rowsDone, RenderStatistics* statistics) const {
  FrameBuffers out;
  out.resize(camera.width(), camera.height());
  std::fill(out.id.begin(), out.id.end(), -1.0f);  // the contract's "no instance"
  const LightVisibility visibility = learnLightVisibility(camera, frameIndex);
  FrameSampler sampler(*this, frameIndex, camera, visibility);
  sampler.firstRound(previousCamera, out, rowsDone);
  frames::SamplingSummary summary;
  summary.lightsPerPoint = settings_.lightsPerPoint;
  if (settings_.converge) sampler.adaptiveRounds(summary, rowsDone);
  const std::uint64_t totalSamples = sampler.writeRadiance(out, summary);
  out.sampling = summary;
  if (statistics) {
    statistics->cameraSamples += totalSamples;
    sampler.addCounts(*statistics);
    statistics->punctualInFrame += lights_.punctualCount();
  }
  return out;
}

std::vector<std::uint8_t> PathTracer::lightReach(const RenderCamera& camera) const {
  const int width = camera.width(), height = camera.height();
  std::vector<std::uint8_t> reach(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 1), [&](const tbb::blocked_range<int>& rows) {
    for (int py = rows.begin(); py < rows.end(); ++py)
      for (int px = 0; px < width; ++px) {
        const Ray ray = camera.ray(px + 0.5, py + 0.5);
        const SurfaceHit hit = trace(ray);
        if (!hit.hit) continue;
        const std::size_t pixel = static_cast<std::size_t>(py) * static_cast<std::size_t>(width) + static_cast<std::size_t>(px);
        if (luminance(emission(hit.node, hit.primitive, hit.triangle, hit.barycentric)) > 0) {
          reach[pixel] = 1;
          continue;
        }
        // The side of the surface the camera sees (Shading's geometric normal faces the viewer).
        const glm::dvec3 normal = glm::dot(hit.geometricNormal, ray.direction) < 0 ? hit.geometricNormal : -hit.geometricNormal;
        const glm::dvec3 origin = offsetOrigin(hit.position, normal);
        reach[pixel] = lights_.anyLightReaches(hit.position, normal, [&](const glm::dvec3& direction, double distance) {
          return !rayTracing_->occluded(origin, direction, shadowRayEnd(distance));
        });
      }
  });
  return reach;
}

}  // namespace dynbench::render
