#pragma once
// The path tracer behind `dynbench render --engine embree`: unidirectional path tracing with next
// event estimation and multiple importance sampling (Veach 1997, power heuristic), over the
// two-level Embree scene, writing the feature buffers of docs/feature-buffers.md.
//
// Direct = emitted light seen from the camera (surfaces, environment) plus light that reaches the
// first hit straight from a light source or the environment; indirect = light that arrives after
// one or more further bounces. `bounces` counts those further bounces, as Cycles' "max bounces"
// does: 0 renders direct light only.
//
// The geometry buffers of a pixel (P, N, Z, id, motion, albedo, hit) describe one surface point:
// the hit of the ray through the pixel centre. Radiance is the pixel's: the mean of paths whose
// camera rays are spread over the pixel by the reconstruction filter (RenderSettings::pixelFilter),
// as Cycles' radiance passes are; with the centre "filter" every path starts at the centre's hit
// (radiance at a point, which aliases where a texture or an edge is finer than a pixel). Punctual
// lights are chosen at every path vertex by the light tree (LightSet::selectPunctual): where no
// more than lightsPerPoint can reach the point they are all summed, so a scene lit by few of them
// has noise-free direct light at 1 spp; where more can, they are sampled without bias.
#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "frames/feature_frame.h"
#include "frames/radiance_change.h"
#include "render/bsdf.h"
#include "render/camera.h"
#include "render/light_visibility.h"
#include "render/lights.h"
#include "render/pixel_filter.h"
#include "render/raytracing_scene.h"
#include "render/textures.h"

namespace dynbench::render {

// The learned light visibility's pilot (PathTracer::learnLightVisibility): every 4th pixel of every
// 4th row, and cells of 1/128 of the scene's diameter (about 30 units on oa_dm1, a tenth of a room).
inline constexpr int kPilotStride = 4;
inline constexpr double kVisibilityCellsAcross = 128.0;

// RenderSettings::everyLightUpTo's default (docs/feature-buffers.md, "Every light in reach").
inline constexpr int kEveryLightUpTo = 16;
// At a path's first vertex in a learned cell (RenderSettings::learnedLightSelection), the point and
// spot lights not seen arriving there sampled beside the seen ones, which are all evaluated: on v2's
// oa_dm1 frame 108, one of them gave the variance four gave (their light is a small part) at 0.9
// times the time.
inline constexpr int kUnseenLightsPerPoint = 1;

struct RenderSettings {
  int width = 480, height = 270;
  int samplesPerPixel = 16;
  int bounces = 4;
  std::uint64_t seed = 1;
  // Light the scene with this radiance from every direction instead of the dataset's environment.
  std::optional<glm::dvec3> constantEnvironment;
  bool useEnvironment = true;  // false: no image-based light (black background)
  // false: BSDF sampling alone, no light sampling (an independent estimator for tests; punctual
  // lights are then invisible, as no BSDF sample can hit a point).
  bool nextEventEstimation = true;
  // Point and spot lights evaluated at a shading point at most, chosen by the light tree
  // (LightSet::selectPunctual: unbiased, no light skipped; exact where no more than this many can
  // reach the point). 0: every light that can reach it, without the tree (exact, slow).
  int lightsPerPoint = 4;
  // Where at most this many point and spot lights can reach a shading point (in front of it and in
  // range), every one of them is evaluated, exactly (LightTree::select's everyLightUpTo); only
  // where more can are lightsPerPoint of them sampled. 0: always sample (as before; for comparison).
  int everyLightUpTo = kEveryLightUpTo;
  // The tree's selection weighted by what was learned to arrive, per cell and tree node, from a
  // pilot before each frame (render/light_visibility.h; unbiased); false: the tree's own importance,
  // as before (`render --light-selection tree`, kept for comparison). Radiance-change pairs select
  // from their shared tree without it either way, so both halves take the same decisions.
  bool learnedLightSelection = true;
  // Adaptive sampling (`render --converge`): after samplesPerPixel samples, each pixel takes more
  // in rounds until the standard error of its direct and of its indirect luminance is at most
  // tolerance x the discard threshold (thresholdFraction x the frame's mean luminance of that
  // buffer, discard's default relative thresholds) / sqrt(3) (the expected test's grey scale,
  // discard.h), or maxSamplesPerPixel is reached.
  bool converge = false;
  double tolerance = 0.25;
  int maxSamplesPerPixel = 4096;
  // render --jitter: every pixel's sample (the hit that P, N, Z, id, motion and the radiance
  // describe) is offset from the pixel centre by frames::jitterOffset(frame), as a real-time
  // renderer jitters its projection for TAA.
  bool jitter = false;
  // render --pixel-filter: the reconstruction filter `direct` and `indirect` (and their variances)
  // estimate the pixel's radiance through (render/pixel_filter.h): each radiance sample traces its
  // own camera ray, offset from the (jittered) pixel centre by the filter. The geometry buffers stay
  // the centre's. kCentre: every path starts at the centre's hit (radiance at a point, aliased).
  PixelFilterSpec pixelFilter;
  double directThresholdFraction = frames::kDefaultRadianceThreshold, indirectThresholdFraction = frames::kDefaultRadianceThreshold;
  // Paths traced together (PathTracer::tracePaths); 1 traces one path at a time. The image does
  // not depend on it (tested): only the speed does.
  int pathBatch = 64;
  // Radiance-change pairs (render --pairs; on with --converge): for each frame, the change of each
  // pixel's direct and indirect radiance since the frame before, by correlated re-shading
  // (PathTracer::renderChanges): kFirstPairs pairs a pixel, doubled in rounds until the test of
  // frames/radiance_change.h decides both buffers, or maxPairs.
  bool pairs = false;
  int maxPairs = 4096;
};

// Point and spot lights a radiance-change pair's half evaluates at its first vertex at most
// (PairLights::select; lightsPerPoint at the vertices after it): at least 32, or every light in
// reach with lightsPerPoint 0. On oa_dm1 (169 lights without a range; frame 108 at 96x54, 128
// samples, pairs up to 64) 4 lights at every vertex left 1219 pixels undecided against 586 with
// every light, 16 at the first vertex 647, 32 about 580; pairs took 8.3 s of the frame with every
// light, 2.5 s with 4 (docs/feature-buffers.md).
constexpr int kPairLightsPerPoint = 32;
inline int pairLightsPerPoint(int lightsPerPoint) { return lightsPerPoint == 0 ? 0 : std::max(lightsPerPoint, kPairLightsPerPoint); }

// RenderSettings::learnedLightSelection by name: "learned" (true) or "tree" (false); nullopt for
// another name.
inline const char* lightSelectionName(bool learned) { return learned ? "learned" : "tree"; }
inline std::optional<bool> parseLightSelection(std::string_view name) {
  if (name == "learned") return true;
  if (name == "tree") return false;
  return std::nullopt;
}

// One frame's buffers: the feature-buffer contract's frame (frames/feature_frame.h).
using FrameBuffers = frames::FeatureFrame;

struct RenderStatistics {
  std::uint64_t cameraSamples = 0, rays = 0;
  std::uint64_t shadingPoints = 0;         // path vertices where direct light was gathered
  std::uint64_t punctualEvaluated = 0;     // punctual lights evaluated at them (selected)
  std::uint64_t punctualInFrame = 0;       // what evaluating every light would have cost
};

class PathTracer {
 public:
  static Expected<std::unique_ptr<PathTracer>> create(const scene::Scene& scene, const RenderSettings& settings,
                                                      std::vector<std::string>& warnings);
  ~PathTracer();

  // Moves the scene to time t; `previousTime` is where motion vectors point back to.
  [[nodiscard]] Expected<void> setTime(double time, double previousTime);
  // Renders the frame at the current time. `frameIndex` seeds the random streams;
  // `rowsDone` (optional) counts finished rows for progress reporting.
  FrameBuffers render(std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera,
                      std::atomic<int>* rowsDone = nullptr, RenderStatistics* statistics = nullptr) const;
  // The radiance change of the frame at the current time since the one at setTime's previousTime
  // (settings().pairs), into `frame`'s directChange, indirectChange and changePairs
  // (docs/feature-buffers.md). Each pair is one pixel-filter sample of this frame: its first hit
  // (instance, primitive, triangle, barycentrics) is rebuilt in the previous frame's scene state
  // (RayTracingScene::surfaceAt) and both halves are path traced, each in its own frame's scene,
  // lights and camera, with the same random numbers keyed per path vertex (Random::vertex), the
  // texture level of detail of this frame's sample in both; D = Y_t - Y_{t-1} is then exactly 0
  // wherever nothing on the path changed, and unbiased where something did (the gradient samples of
  // A-SVGF, Schied et al. 2018, at every pixel). Two choices keep the halves together where the
  // view or the lights change: the previous half samples its first bounce as this frame's half does
  // (from this frame's view direction, its lobe, direction and density) and weighs it with its own
  // BSDF towards its own camera, f_{t-1}(wo_{t-1}, wi) cos / pdf_t(wi), unbiased since pdf_t covers
  // the hemisphere (a glossy lobe sampled from each half's own view gave different bounces, and the
  // indirect column stayed undecided on a third of Cube 2's pixels); and both halves select the
  // lights the two frames share from one tree with the same random number and evaluate the lights
  // that differ wherever they reach (PairLights; each frame's own tree picks different lights once
  // the frames' lights differ). A sample whose surface is hidden in the previous
  // frame is no pair (that pixel's history is the position column's). The thresholds come from
  // `frame`'s own direct and indirect, as discard computes them.
  void renderChanges(std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera, FrameBuffers& frame,
                     RenderStatistics* statistics = nullptr) const;

  // For each pixel of `camera`'s image, whether any light of the frame at the current time reaches
  // the surface the ray through the pixel's centre hits (1; LightSet::anyLightReaches, no sampling),
  // or the surface emits itself; 0 where no light reaches it or the ray hits nothing.
  std::vector<std::uint8_t> lightReach(const RenderCamera& camera) const;
  const RayTracingScene& rayTracing() const { return *rayTracing_; }
  const RenderSettings& settings() const { return settings_; }

 private:
  struct Shading;
  PathTracer(const scene::Scene& scene, const RenderSettings& settings);
  // The material at a hit seen from direction wo, at the hit's texture coordinates uv, its
  // textures filtered for a ray cone of width coneWidth there (textureLod; 0: level 0, unfiltered).
  Shading shade(const SurfaceHit& hit, const glm::dvec3& wo, glm::dvec2 uv, double coneWidth) const;
  // The same, written in place (every field), with the triangle's corners from `scene`.
  void shade(const SurfaceHit& hit, const glm::dvec3& wo, glm::dvec2 uv, double coneWidth, const RayTracingScene& scene, Shading& shading) const;
  // The same for a texture level of detail already known (corners: the triangle's world corners).
  void shadeAt(const SurfaceHit& hit, const glm::dvec3& wo, glm::dvec2 uv, const std::array<glm::dvec3, 3>& corners, double lod,
               Shading& shading) const;
  // The texture-independent level of detail of a ray cone of width coneWidth arriving along
  // `direction` at the hit's triangle, whose world corners are `corners` (textureLod).
  double textureLodAt(const SurfaceHit& hit, const std::array<glm::dvec3, 3>& corners, const glm::dvec3& direction,
                      double coneWidth) const;
  glm::dvec3 emission(int node, int primitive, unsigned triangle, glm::dvec2 barycentric) const;
  // The same, at texture coordinates uv and texture level of detail lod (-infinity: level 0).
  glm::dvec3 emission(const scene::Material& material, glm::dvec2 uv, double lod = -std::numeric_limits<double>::infinity()) const;
  glm::dvec2 texCoord(int node, int primitive, unsigned triangle, glm::dvec2 barycentric) const;
  glm::dvec2 texCoord(const SurfaceHit& hit) const;  // the same, from the vertex indices the hit carries
  // Memory prefetches of the batched tracer: a hit's vertex texture coordinates, then the texels
  // its material will read at uv.
  void prefetchTexCoords(const SurfaceHit& hit) const;
  void prefetchTextures(const SurfaceHit& hit, glm::dvec2 uv) const;
  bool alphaOpaque(int node, int primitive, unsigned triangle, glm::dvec2 barycentric) const;
  const scene::Primitive& primitiveOf(int node, int primitive) const;
  const scene::Material* materialOf(int node, int primitive) const;
  const scene::Material* materialOf(const scene::Primitive& primitive) const;
  SurfaceHit trace(const Ray& ray) const;
  // The frame's learned light visibility (settings().learnedLightSelection; LightVisibility): pilot
  // points where the rays through every kPilotStride-th pixel centre of `camera` (both axes) first
  // hit, and one cosine-sampled bounce from each (a stream keyed by the frame and pixel alone), in
  // cells of kVisibilityCellsAcross across the scene's diameter. Empty without point or spot lights.
  LightVisibility learnLightVisibility(const RenderCamera& camera, std::uint64_t frameIndex) const;
  struct PathSample;
  struct PathState;
  struct PathScratch;
  // A batch of paths, each from the camera through its pixel's centre and starting at that
  // pixel's first hit (already traced and shaded: PathState::first), each with its own random
  // stream: their direct and indirect radiance, in paths[k].out. A batch may hold the paths of
  // several pixels. The paths advance together, one bounce at a time, in stages (trace every path,
  // then shade every path), so that the memory each path's shading reads (texels, environment
  // pixels, light tables) is prefetched while the other paths trace: one path at a time spent
  // most of its time waiting on those loads. Each path computes exactly what it would alone: the
  // same random numbers in the same order, the same arithmetic.
  // firstHitsKnown: every path's first hit is its FirstVertex's, also with a pixel filter (the
  // halves of radiance-change pairs, whose first hits renderChanges has found).
  void tracePaths(std::span<PathState> paths, PathScratch& scratch, bool firstHitsKnown = false) const;
  // One vertex of one path (its hit traced, its prefetches issued), first half: adds the hit's
  // emission and its punctual lights to the path's radiance, takes its light sample and puts its
  // BSDF, the light sample's direction and the bounce's random numbers into lane `lanes` of the
  // batch's BSDFs (then counts the lane). false when the path ends here. At a pixel's first hit,
  // which every path of the pixel shares, `first` holds its shading and ray origin, found once.
  struct FirstVertex;
  // A frame's samples, in render's steps (path_tracer_frame.cpp), and a frame's radiance-change
  // pairs, in renderChanges' (path_tracer_changes.cpp).
  class FrameSampler;
  class ChangeSampler;
  bool advance(PathState& path, int depth, const SurfaceHit& hit, const FirstVertex* first, PathScratch& scratch,
               std::size_t& lanes) const;
  // advance below the hit's emission: the punctual lights the tree selects, the light sample and
  // the lane; the vertex's rays leave from `origin`.
  bool scatter(PathState& path, int depth, const SurfaceHit& hit, const Shading& shading, const glm::dvec3& origin,
               PathScratch& scratch, std::size_t& lanes) const;
  // Second half, once the batch's BSDFs are evaluated and sampled: the light sample's contribution
  // (its shadow ray) and the bounce (the next ray, Russian roulette). false when the path ends.
  bool bounce(PathState& path, int depth, PathScratch& scratch) const;
  // A light's contribution at the path's vertex, given the BSDF's value and pdf towards it.
  void addLight(PathState& path, int depth, const LightSample& light, const Bsdf::Evaluation& evaluation, PathScratch& scratch) const;
  // addLight for a point, spot or directional light (a delta light, counted fully): the shadow ray first, then
  // the BSDF, which an occluded light does not need (the same sum: the BSDF's value at an occluded
  // light was never used). On v2's calm frame 108, evaluating the BSDF at every light in reach
  // before its shadow ray was 11 % of the frame (perf).
  void addPunctualLight(PathState& path, int depth, const LightSample& light, const Bsdf& bsdf, const Bsdf::View& view,
                        PathScratch& scratch) const;

  const scene::Scene& scene_;
  RenderSettings settings_;
  PixelFilter filter_;
  TextureSet textures_;
  std::optional<EnvironmentLight> environment_;
  std::unique_ptr<RayTracingScene> rayTracing_;
  LightSet lights_;
  // The previous frame's scene state for radiance-change pairs (settings_.pairs).
  std::unique_ptr<RayTracingScene> previousRayTracing_;
  LightSet previousLights_;
  PairLights pairLights_;  // the two frames' punctual lights as a pair's halves select them
  std::optional<double> previousTime_;
  std::optional<double> sceneRadius_;  // from the first frame's geometry (1 when there is none)
  std::optional<double> time_;
};

}  // namespace dynbench::render
