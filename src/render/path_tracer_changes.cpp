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

// A frame's radiance-change pairs (renderChanges): each pixel's running sums, and per thread the
// batch of samples whose two halves are traced together. renderChanges runs its steps in order:
// the pixels in rounds, then the change buffers and the summary.
class PathTracer::ChangeSampler {
 public:
  ChangeSampler(const PathTracer& tracer, std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera,
                FrameBuffers& frame)
      : tracer_(tracer),
        settings_(tracer.settings_),
        frameIndex_(frameIndex),
        camera_(camera),
        frame_(frame),
        width_(camera.width()),
        // The thresholds on luminance: discard's (a fraction of the frame's mean luminance of each
        // buffer, an RGB distance) over sqrt(3), the grey change's scale (frames/radiance_change.h).
        tau_{settings_.directThresholdFraction * frames::meanLuminance(frame.direct) / frames::kGreyDistance,
             settings_.indirectThresholdFraction * frames::meanLuminance(frame.indirect) / frames::kGreyDistance},
        cap_(std::max(frames::kFirstPairs, settings_.maxPairs)),
        pixelSpread_(std::atan(2.0 * std::tan(0.5 * camera.yfov()) / camera.height())),
        jitter_(settings_.jitter ? frames::jitterOffset(static_cast<long>(frameIndex)) : glm::dvec2(0.0)),
        seed_(settings_.seed ^ kPairStream),
        cameraNow_(camera.position()),
        cameraBefore_(previousCamera.position()),
        batchSize_(std::max<std::size_t>(1, static_cast<std::size_t>(settings_.pathBatch) / 2)),
        sums_(frame.pixelCount()),
        batches_([spread = pixelSpread_] {
          Batch b;
          b.scratch.pixelSpread = spread;
          return b;
        }) {}

  // Pixels in runs of 8, each in rounds: kFirstPairs pairs, then doubling while either buffer is
  // undecided, up to the cap. A pixel's pairs depend on its own sums alone, so the result does not
  // depend on the thread schedule.
  void sampleInRounds() {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sums_.size(), 8), [&](const tbb::blocked_range<std::size_t>& run) {
      Batch& b = batches_.local();
      for (;;) {
        b.samples.clear();
        for (std::size_t pixel = run.begin(); pixel < run.end(); ++pixel) {
          ChangeSums& sum = sums_[pixel];
          if (sum.done) continue;
          const int upTo = sum.attempted == 0 ? frames::kFirstPairs : std::min(cap_, 2 * sum.attempted);
          for (int k = sum.attempted; k < upTo; ++k) b.samples.emplace_back(pixel, k);
          sum.attempted = upTo;
        }
        if (b.samples.empty()) break;
        for (std::size_t start = 0; start < b.samples.size(); start += batchSize_)
          traceBatch(b, std::span(b.samples).subspan(start, std::min(batchSize_, b.samples.size() - start)));
        for (std::size_t pixel = run.begin(); pixel < run.end(); ++pixel) {
          ChangeSums& sum = sums_[pixel];
          if (sum.done) continue;
          const bool decided = frames::decideChange(estimate(sum, 0, pixel), tau_[0]) != frames::ChangeDecision::kUndecided &&
                               frames::decideChange(estimate(sum, 1, pixel), tau_[1]) != frames::ChangeDecision::kUndecided;
          // No pair after the first round: every sample's surface is new in this frame.
          sum.done = decided || sum.attempted >= cap_ || sum.pairs == 0;
        }
      }
    });
  }

  // The change buffers (mean, standard error, gathered light of each pixel) and pair counts of the
  // frame, and its sampling summary's pair figures.
  void write() {
    FrameBuffers& frame = frame_;
    long undecided = 0;
    double totalPairs = 0.0;
    int mostPairs = 0;
    for (std::size_t pixel = 0; pixel < sums_.size(); ++pixel) {
      const ChangeSums& sum = sums_[pixel];
      std::array<frames::ChangeEstimate, 2> estimates{};
      for (std::size_t b = 0; b < 2; ++b) {
        const frames::ChangeEstimate e = estimates[b] = estimate(sum, b, pixel);
        std::vector<float>& out = b == 0 ? frame.directChange : frame.indirectChange;
        out[3 * pixel] = static_cast<float>(e.mean);
        out[3 * pixel + 1] = static_cast<float>(e.standardError);
        out[3 * pixel + 2] = static_cast<float>(e.gathered);
      }
      frame.changePairs[pixel] = static_cast<float>(sum.pairs);
      totalPairs += sum.pairs;
      mostPairs = std::max(mostPairs, sum.pairs);
      if (sum.pairs > 0 && (frames::decideChange(estimates[0], tau_[0]) == frames::ChangeDecision::kUndecided ||
                            frames::decideChange(estimates[1], tau_[1]) == frames::ChangeDecision::kUndecided))
        ++undecided;
    }
    if (!frame.sampling) frame.sampling = frames::SamplingSummary{};
    frame.sampling->pairCap = cap_;
    frame.sampling->maxPairs = mostPairs;
    frame.sampling->meanPairs = totalPairs / static_cast<double>(sums_.size());
    frame.sampling->undecidedPixels = undecided;
  }

  // The threads' ray, shading-point and light counts.
  void addCounts(RenderStatistics& statistics) const {
    for (const Batch& b : batches_) {
      statistics.rays += b.scratch.rays;
      statistics.shadingPoints += b.scratch.shadingPoints;
      statistics.punctualEvaluated += b.scratch.punctualEvaluated;
    }
  }

 private:
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
  // What both halves of one sample share: its key, this frame's hit, the view direction from this
  // frame's camera, and the texture coordinates and level of detail of this frame's sample.
  struct PairKey {
    std::size_t pixel = 0;
    int sample = 0;
    const SurfaceHit* hitNow = nullptr;
    glm::dvec3 woNow{0.0};
    glm::dvec2 uv{0.0};
    double lod = 0.0;
  };

  // A pixel's estimate in buffer b (0 direct, 1 indirect), floored by the frame's own luminance there.
  frames::ChangeEstimate estimate(const ChangeSums& sum, std::size_t b, std::size_t pixel) const {
    const std::vector<float>& rgb = b == 0 ? frame_.direct : frame_.indirect;
    return sum.estimate(b, luminance(glm::dvec3(rgb[3 * pixel], rgb[3 * pixel + 1], rgb[3 * pixel + 2])));
  }

  // One batch of samples: trace their camera rays in this frame, rebuild each hit in the previous
  // frame, trace both halves, add each pair to its pixel's sums.
  void traceBatch(Batch& b, std::span<const std::pair<std::size_t, int>> samples) {
    traceCameraRays(b, samples);
    setUpPairs(b, samples);
    if (b.traced.empty()) return;
    b.scratch.pairLights = &tracer_.pairLights_;
    b.scratch.scene = tracer_.rayTracing_.get();
    b.scratch.lights = &tracer_.lights_;
    b.scratch.pairHalf = 0;
    tracer_.tracePaths(b.pathsNow, b.scratch, true);
    b.scratch.scene = tracer_.previousRayTracing_.get();
    b.scratch.lights = &tracer_.previousLights_;
    b.scratch.pairHalf = 1;
    tracer_.tracePaths(b.pathsBefore, b.scratch, true);
    addPairs(b, samples);
  }

  // The samples' camera rays (offset by the pixel filter from the pair stream) and their hits in this frame.
  void traceCameraRays(Batch& b, std::span<const std::pair<std::size_t, int>> samples) const {
    const std::size_t n = samples.size();
    b.rays.resize(n);
    b.hits.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const auto [pixel, sample] = samples[k];
      const int px = static_cast<int>(pixel % static_cast<std::size_t>(width_)), py = static_cast<int>(pixel / static_cast<std::size_t>(width_));
      Random rng = Random::vertex(seed_, frameIndex_, pixel, static_cast<std::uint64_t>(sample), 0);
      const glm::dvec2 offset = tracer_.filter_.atCentre() ? glm::dvec2(0.0) : tracer_.filter_.offset(rng.uniform2());
      b.rays[k] = camera_.ray(px + 0.5 + jitter_.x + offset.x, py + 0.5 + jitter_.y + offset.y);
    }
    tracer_.rayTracing_->intersect(b.rays, b.hits);
    b.scratch.rays += n;
  }

  // Each sample's hit rebuilt in the previous frame and both halves' first vertices and paths set
  // up (b.traced); an escaped sample adds its pair here (the environment, at infinity and
  // unanimated: the same radiance in both frames), a surface absent from the previous frame none.
  void setUpPairs(Batch& b, std::span<const std::pair<std::size_t, int>> samples) {
    const std::size_t n = samples.size();
    b.previousHits.resize(n);
    b.now.resize(n);
    b.before.resize(n);
    b.pathsNow.clear();
    b.pathsBefore.clear();
    b.traced.clear();
    for (std::size_t k = 0; k < n; ++k) {
      const auto [pixel, sample] = samples[k];
      const SurfaceHit& hit = b.hits[k];
      if (!hit.hit) {
        const double y = tracer_.environment_ ? luminance(tracer_.environment_->radiance(b.rays[k].direction)) : 0.0;
        sums_[pixel].add({y, 0.0}, {y, 0.0}, {0.0, 0.0});
        continue;
      }
      b.previousHits[k] = tracer_.previousRayTracing_->surfaceAt(hit);
      if (!b.previousHits[k].hit) continue;  // the surface is not in the previous frame: no pair
      // Both halves' first vertices alike: the view direction from each frame's camera to its
      // point, the texture level of detail of this frame's sample (a filtering choice of the
      // pixel, not a change of its lighting).
      PairKey key{pixel, sample, &hit, glm::normalize(cameraNow_ - hit.position), tracer_.texCoord(hit), 0.0};
      const auto cornersNow = tracer_.rayTracing_->trianglePositions(hit);
      key.lod = tracer_.textureLodAt(hit, cornersNow, -key.woNow, pixelSpread_ * hit.distance);
      setUpHalf(key, hit, cameraNow_, cornersNow, nullptr, b.now[k], b.pathsNow);
      setUpHalf(key, b.previousHits[k], cameraBefore_, tracer_.previousRayTracing_->trianglePositions(b.previousHits[k]), &b.now[k],
                b.before[k], b.pathsBefore);
      b.traced.push_back(k);
    }
  }

  // One half's first vertex v at hit h seen from cameraPosition (corners: the triangle's world
  // corners in that half's frame), and its path added to `paths`; nowHalf: this frame's half when
  // v is the previous frame's, else nullptr.
  void setUpHalf(const PairKey& key, const SurfaceHit& h, const glm::dvec3& cameraPosition, const std::array<glm::dvec3, 3>& corners,
                 const FirstVertex* nowHalf, FirstVertex& v, std::vector<PathState>& paths) const {
    glm::dvec3 wo = glm::normalize(cameraPosition - h.position);
    // A point the previous camera sees from behind (a silhouette turning away) is shaded from
    // the side this frame sees, the view mirrored in its plane: which side a camera sees is the
    // position column's business, not a change of lighting.
    if (nowHalf && (glm::dot(h.geometricNormal, wo) > 0) != (glm::dot(key.hitNow->geometricNormal, key.woNow) > 0))
      wo -= 2.0 * glm::dot(wo, h.geometricNormal) * h.geometricNormal;
    v.pixel = key.pixel;
    v.ray = Ray{cameraPosition, -wo};
    v.hit = &h;
    tracer_.shadeAt(h, wo, key.uv, corners, key.lod, v.shading);
    v.origin = offsetOrigin(h.position, v.shading.geometricNormal);
    PathState& p = paths.emplace_back();
    p.first = &v;
    p.ray = v.ray;
    p.keyed = true;
    p.keySeed = seed_;
    p.keyFrame = frameIndex_;
    p.keyPixel = key.pixel;
    p.keySample = static_cast<std::uint64_t>(key.sample);
    // Both halves' first bounces are sampled from this frame's view, carried into the previous
    // surface's shading frame where it turned: the same lobe and direction wherever the surface
    // did not move, so the rest of the path is the same (see renderChanges in path_tracer.h);
    // both weigh it with the scalar BSDF (the batch's SIMD evaluation rounds differently).
    p.sharedFirstBounce = true;
    const glm::dvec3& nowNormal = nowHalf ? nowHalf->shading.shadingNormal : v.shading.shadingNormal;
    p.samplingView = v.shading.shadingNormal == nowNormal ? key.woNow : Frame(v.shading.shadingNormal).toWorld(Frame(nowNormal).toLocal(key.woNow));
  }

  // Each traced sample's pair added to its pixel's sums.
  void addPairs(const Batch& b, std::span<const std::pair<std::size_t, int>> samples) {
    for (std::size_t j = 0; j < b.traced.size(); ++j) {
      const std::size_t k = b.traced[j];
      const PathSample& now = b.pathsNow[j].out;
      const PathSample& before = b.pathsBefore[j].out;
      const double yNow = luminance(now.direct), yBefore = luminance(before.direct);
      // The first hit's emission reaches the camera unweighted (depth 0): the same in both halves.
      const double gatheredDirect = std::abs(yNow - luminance(b.now[k].shading.material.emission)) +
                                    std::abs(yBefore - luminance(b.before[k].shading.material.emission));
      const double gatheredIndirect = std::abs(luminance(now.indirect)) + std::abs(luminance(before.indirect));
      sums_[samples[k].first].add({yNow, luminance(now.indirect)}, {yBefore, luminance(before.indirect)}, {gatheredDirect, gatheredIndirect});
    }
  }

  const PathTracer& tracer_;
  const RenderSettings& settings_;
  const std::uint64_t frameIndex_;
  const RenderCamera& camera_;
  FrameBuffers& frame_;  // its images give the thresholds; write() fills its change buffers
  const int width_;
  const std::array<double, 2> tau_;
  const int cap_;
  const double pixelSpread_;
  const glm::dvec2 jitter_;
  const std::uint64_t seed_;
  const glm::dvec3 cameraNow_, cameraBefore_;
  const std::size_t batchSize_;
  std::vector<ChangeSums> sums_;
  tbb::enumerable_thread_specific<Batch> batches_;
};

void PathTracer::renderChanges(std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera, FrameBuffers& frame,
                               RenderStatistics* statistics) const {
  const std::size_t pixels = frame.pixelCount();
  frame.directChange.assign(3 * pixels, 0.0f);
  frame.indirectChange.assign(3 * pixels, 0.0f);
  frame.changePairs.assign(pixels, 0.0f);
  if (!previousRayTracing_ || pixels == 0) return;
  ChangeSampler sampler(*this, frameIndex, camera, previousCamera, frame);
  sampler.sampleInRounds();
  sampler.write();
  if (statistics) sampler.addCounts(*statistics);
}

}  // namespace dynbench::render
