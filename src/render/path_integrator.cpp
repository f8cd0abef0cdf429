// The batched integrator: paths traced in batches through their stages (trace, prefetch, shade,
// bounce), their BSDFs and environment lookups evaluated together.
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


void PathTracer::tracePaths(std::span<PathState> paths, PathScratch& scratch, bool firstHitsKnown) const {
  // A path's camera ray is set by whoever queued it (its pixel's, or its own through the filter).
  const bool ownCameraRays = !filter_.atCentre() && !firstHitsKnown;
  for (PathState& p : paths) {
    p.throughput = glm::dvec3(1.0);
    p.pathLength = 0.0;
    p.out = PathSample{};
    p.previousBsdfPdf = 0.0;
    p.previousDelta = true;
    p.active = true;
  }
  const bool lightSample = settings_.nextEventEstimation;
  scratch.bsdfs.reserve(paths.size());
  scratch.equirect.reserve(paths.size());
  for (int depth = 0;; ++depth) {
    const bool shadesHere = depth <= settings_.bounces;  // a hit at this depth gathers light and bounces
    for (PathState& p : paths)
      if (p.active && p.keyed) p.rng = Random::vertex(p.keySeed, p.keyFrame, p.keyPixel, p.keySample, static_cast<std::uint64_t>(depth) + 1);
    // Stage 1: trace; start loading the hit's texture coordinates and the environment pixel of an
    // escape; start the light choice (which loads the table entry stage 2 reads).
    bool any = false;
    const bool streamed = depth > 0 || ownCameraRays;  // this depth's hits come from the stream
    if (streamed) {
      scratch.streamRays.clear();
      for (PathState& p : paths)
        if (p.active) scratch.streamRays.push_back(p.ray);
      // Grown, never shrunk: growing again after a shrink would value-initialise the hit records.
      if (scratch.streamHits.size() < scratch.streamRays.size()) scratch.streamHits.resize(scratch.streamRays.size());
      scratch.scene->intersect(scratch.streamRays, std::span(scratch.streamHits).first(scratch.streamRays.size()));
      std::size_t k = 0;
      for (PathState& p : paths)
        if (p.active) p.streamIndex = k++;
      scratch.rays += scratch.streamRays.size();
    }
    // The hits are read where the stream left them (a hit record is 150 bytes: not copied).
    auto hitOf = [&](const PathState& p) -> const SurfaceHit& { return streamed ? scratch.streamHits[p.streamIndex] : *p.first->hit; };
    auto escaped = [&](const PathState& p) { return p.active && !hitOf(p).hit && environment_; };
    std::size_t escapes = 0;
    for (PathState& p : paths) {
      if (!p.active) continue;
      any = true;
      const SurfaceHit& hit = hitOf(p);
      if (!hit.hit) {
        if (environment_) scratch.equirect.setDirection(escapes++, p.ray.direction);
        continue;
      }
      if (streamed) prefetchTexCoords(hit);
      if (lightSample && shadesHere) {
        const double uChoice = p.rng.uniform();
        const glm::dvec2 uLight = p.rng.uniform2();
        scratch.lights->startChoice(uChoice, uLight, p.lightChoice);
      }
    }
    if (!any) break;
    // The escapes' environment image points, all at once; start loading their pixels.
    if (escapes > 0) {
      scratch.equirect.coordinates(escapes);
      std::size_t lane = 0;
      for (PathState& p : paths)
        if (escaped(p)) {
          p.uv = scratch.equirect.point(lane++, &p.escapeSinTheta);
          scratch.lights->prefetchEnvironment(p.uv);
        }
    }
    // Stage 2: what stage 1's loads point to: the texels at the hit; the light choice, which
    // starts loading the environment pixel or triangle it picks. Then the directions of the
    // environment choices, all at once.
    scratch.choices.clear();
    for (PathState& p : paths) {
      if (!p.active) continue;
      const SurfaceHit& hit = hitOf(p);
      if (!hit.hit) continue;
      if (streamed) {
        p.uv = texCoord(hit);
        prefetchTextures(hit, p.uv);
      }
      if (lightSample && shadesHere) {
        scratch.lights->finishChoice(p.lightChoice);
        scratch.choices.push_back(&p.lightChoice);
      }
    }
    scratch.lights->mapDirections(scratch.choices, scratch.equirect);
    // Stage 3: shade and gather the punctual lights, path by path, each path's BSDF going into a
    // lane of the batch; evaluate the light samples and sample the bounces of all the lanes at
    // once (BsdfBatch); then each path's light sample (its shadow ray) and its bounce.
    std::size_t lanes = 0;
    for (PathState& p : paths)
      if (p.active) p.active = advance(p, depth, hitOf(p), streamed ? nullptr : p.first, scratch, lanes);
    if (lanes > 0) scratch.bsdfs.run(lanes);
    for (PathState& p : paths)
      if (p.active) p.active = bounce(p, depth, scratch);
  }
  for (PathState& p : paths) {
    if (!finite(p.out.direct)) p.out.direct = glm::dvec3(0.0);
    if (!finite(p.out.indirect)) p.out.indirect = glm::dvec3(0.0);
  }
}

bool PathTracer::advance(PathState& p, int depth, const SurfaceHit& hit, const FirstVertex* first, PathScratch& scratch,
                         std::size_t& lanes) const {
  const Ray& ray = p.ray;
  // Radiance found by this ray is direct when it reaches the camera from the first surface
  // (depth 1) or is seen by the camera itself (depth 0).
  glm::dvec3& bucket = depth <= 1 ? p.out.direct : p.out.indirect;
  if (!hit.hit) {
    if (environment_) {
      double pdfLight = 0.0;
      const glm::dvec3 le = scratch.lights->environmentRadianceAt(p.uv, p.escapeSinTheta, &pdfLight);
      const double w = p.previousDelta || !settings_.nextEventEstimation ? 1.0 : powerHeuristic(p.previousBsdfPdf, pdfLight);
      bucket += p.throughput * le * w;
    }
    return false;
  }
  const glm::dvec3 wo = -ray.direction;
  p.pathLength += hit.distance;
  // The hit's shading, written in place (scratch.shading: returned, GCC zeroed and copied it).
  if (!first) shade(hit, wo, p.uv, scratch.pixelSpread * p.pathLength, *scratch.scene, scratch.shading);
  const Shading& s = first ? first->shading : scratch.shading;
  if (s.material.emission != glm::dvec3(0.0)) {
    double w = 1.0;
    if (!p.previousDelta && settings_.nextEventEstimation) {
      const double cosLight = std::abs(glm::dot(hit.geometricNormal, ray.direction));
      w = powerHeuristic(p.previousBsdfPdf, scratch.lights->pdfEmissive(s.emissiveWeight, hit.distance, cosLight));
    }
    bucket += p.throughput * s.material.emission * w;
  }
  if (depth > settings_.bounces) return false;
  if (first) return scatter(p, depth, hit, s, first->origin, scratch, lanes);
  return scatter(p, depth, hit, s, offsetOrigin(hit.position, s.geometricNormal), scratch, lanes);
}

bool PathTracer::scatter(PathState& p, int depth, const SurfaceHit& hit, const Shading& s, const glm::dvec3& origin,
                         PathScratch& scratch, std::size_t& lanes) const {
  p.origin = origin;
  p.shadingNormal = s.shadingNormal;
  p.lightEvaluated = false;
  p.lane = lanes++;
  BsdfBatch& bsdfs = scratch.bsdfs;
  const glm::dvec3 wo = -p.ray.direction;
  // A pair's previous half samples its first bounce (and weighs it, in MIS) as the current half
  // does; its BSDF's values towards its own camera are applied in addLight and bounce.
  bsdfs.set(p.lane, s.material, s.shadingNormal, s.geometricNormal, depth == 0 && p.sharedFirstBounce ? p.samplingView : wo);
  if (settings_.nextEventEstimation) {
    ++scratch.shadingPoints;
    // The punctual lights the light tree selects for this point, each divided by the probability
    // of its selection (LightSet::selectPunctual), here, with the scalar BSDF. The tree's random
    // number is drawn only where there is a tree, so scenes without point lights keep their stream.
    // A pair's halves draw it whatever their frames' lights, though they select without a tree
    // (below), so that a vertex's numbers keep the places they had when first measured.
    const double uTree = p.keyed ? p.rng.uniform() : 0.0;
    if (scratch.lights->punctualCount() > 0) {
      const double uLight = p.keyed ? uTree : scratch.lights->hasPunctualTree() ? p.rng.uniform() : 0.0;
      // A pair's halves select from the lights both frames share with one tree and the same number
      // (PairLights): each frame's own tree is built from its own lights, and once they differ (a
      // muzzle flash, a moving player's light) the same number picks different lights everywhere.
      // At the first vertex they select more lights than an image sample: a glossy surface seen
      // from a moving camera changes under every light, and D's estimate of that change gets the
      // selection's noise. Further vertices are reached along the same directions in both halves,
      // so there an unchanged light at an unmoved point gives both the same light, whichever.
      if (p.keyed && scratch.pairLights)
        scratch.pairLights->select(scratch.pairHalf, hit.position, s.geometricNormal, uLight,
                                   depth == 0 ? pairLightsPerPoint(settings_.lightsPerPoint) : settings_.lightsPerPoint, scratch.selected,
                                   settings_.everyLightUpTo);
      else {
        // The learned cell, where there is one (LightVisibility): at a path's first vertex its
        // seen lights are summed and kUnseenLightsPerPoint of the others sampled; at the vertices
        // after it, whose light reaches the pixel through a sampled bounce anyway, the tree samples
        // lightsPerPoint among every light (summing the seen lights there too cost 40 % more time
        // on v2's oa_dm1 frame 108 for 2 % less variance). Either way the search for every light in
        // reach is skipped where more than half the cell's pilot points had more in reach than it
        // takes (a point's cost only: both ways the estimate is unbiased).
        const LightVisibility::Cell cell = scratch.visibility ? scratch.visibility->cell(hit.position, s.geometricNormal) : LightVisibility::Cell{};
        const int everyLightUpTo =
            cell.factors && cell.typicalReaching > static_cast<std::uint32_t>(settings_.everyLightUpTo) ? 0 : settings_.everyLightUpTo;
        // Where every light in reach is taken, the cell's occluded lights are kept by roulette
        // (LightTree::Guide::keepFactors), at every vertex.
        const LightTree::Guide guide{.factors = depth == 0 ? cell.factors : nullptr,
                                     .everyLightUpTo = everyLightUpTo,
                                     .keepFactors = cell.factors,
                                     .reachLeaves = cell.reachLeaves};
        if (depth == 0 && cell.factors)
          scratch.lights->selectPunctual(hit.position, s.geometricNormal, uLight, kUnseenLightsPerPoint, scratch.selected, guide, cell.seen);
        else
          scratch.lights->selectPunctual(hit.position, s.geometricNormal, uLight, settings_.lightsPerPoint, scratch.selected, guide);
      }
      scratch.punctualEvaluated += scratch.selected.size();
      if (!scratch.selected.empty()) {
        const Bsdf bsdf(s.material, Frame(s.shadingNormal), s.geometricNormal);
        const Bsdf::View view = bsdf.view(wo);
        LightSample& punctual = scratch.lightSample;
        for (const LightTree::Selected& selected : scratch.selected)
          if (scratch.lights->samplePunctual(selected.light, hit.position, punctual)) {
            punctual.pdf = selected.probability;
            addPunctualLight(p, depth, punctual, bsdf, view, scratch);
          }
      }
    }
    // The environment or an emissive triangle: one Monte Carlo sample (its random numbers drawn
    // in the trace stage whether or not there is anything to choose, so the stream stays aligned),
    // evaluated in the path's lane. No light to choose: a kNone choice, no sample.
    p.lightEvaluated = scratch.lights->sample(hit.position, p.lightChoice, p.lightSample) && p.lightSample.pdf > 0;
  }
  if (p.lightEvaluated) bsdfs.setEvaluation(p.lane, p.lightSample.direction);
  else bsdfs.clearEvaluation(p.lane);
  const double uLobe = p.rng.uniform();
  bsdfs.setSample(p.lane, p.rng.uniform2(), uLobe);
  return true;
}

// Adds one light's contribution to the light reaching the path's vertex: Monte Carlo samples are
// weighted against BSDF sampling (Veach's MIS), delta lights count fully (no other strategy can
// find them).
void PathTracer::addLight(PathState& p, int depth, const LightSample& ls, const Bsdf::Evaluation& e, PathScratch& scratch) const {
  const glm::dvec3& f = e.value;
  if (f == glm::dvec3(0.0)) return;
  const double cosine = std::abs(glm::dot(p.shadingNormal, ls.direction));
  const double tMax = shadowRayEnd(ls.distance);
  ++scratch.rays;
  if (scratch.scene->occluded(p.origin, ls.direction, tMax)) return;
  const double w = ls.delta ? 1.0 : powerHeuristic(ls.pdf, e.pdf);
  glm::dvec3& bucket = depth == 0 ? p.out.direct : p.out.indirect;  // light reaching this hit
  bucket += p.throughput * f * ls.radiance * (cosine * w / ls.pdf);
}

void PathTracer::addPunctualLight(PathState& p, int depth, const LightSample& ls, const Bsdf& bsdf, const Bsdf::View& view,
                                  PathScratch& scratch) const {
  const double tMax = shadowRayEnd(ls.distance);
  ++scratch.rays;
  if (scratch.scene->occluded(p.origin, ls.direction, tMax)) return;
  const glm::dvec3 f = bsdf.evaluate(view, ls.direction).value;
  if (f == glm::dvec3(0.0)) return;
  const double cosine = std::abs(glm::dot(p.shadingNormal, ls.direction));
  glm::dvec3& bucket = depth == 0 ? p.out.direct : p.out.indirect;
  bucket += p.throughput * f * ls.radiance * (cosine / ls.pdf);
}

bool PathTracer::bounce(PathState& p, int depth, PathScratch& scratch) const {
  const bool shared = depth == 0 && p.sharedFirstBounce;
  // The value of the pair's previous half's own BSDF, seen from its own camera, towards wi.
  auto ownValue = [&](const glm::dvec3& wi) {
    const Shading& s = p.first->shading;
    const Bsdf bsdf(s.material, Frame(s.shadingNormal), s.geometricNormal);
    return bsdf.evaluate(bsdf.view(-p.ray.direction), wi).value;
  };
  if (p.lightEvaluated) {
    Bsdf::Evaluation e = scratch.bsdfs.evaluation(p.lane);
    if (shared) e.value = ownValue(p.lightSample.direction);
    addLight(p, depth, p.lightSample, e, scratch);
  }
  BsdfSample& bs = scratch.bsdfSample;
  if (!scratch.bsdfs.sample(p.lane, bs)) return false;
  if (shared) bs.value = ownValue(bs.direction);
  p.throughput *= bs.value * (std::abs(glm::dot(p.shadingNormal, bs.direction)) / bs.pdf);
  if (depth >= 3) {  // Russian roulette keeps long paths cheap without bias
    const double survive = std::min(0.95, std::max({p.throughput.x, p.throughput.y, p.throughput.z}));
    if (p.rng.uniform() >= survive) return false;
    p.throughput /= survive;
  }
  if (!finite(p.throughput) || p.throughput == glm::dvec3(0.0)) return false;
  p.previousBsdfPdf = bs.pdf;
  p.previousDelta = false;
  p.ray.origin = p.origin;
  p.ray.direction = bs.direction;
  return true;
}
}  // namespace dynbench::render
