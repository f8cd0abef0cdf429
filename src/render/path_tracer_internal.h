#pragma once
// What the path tracer's files share (path_tracer.cpp: construction and surface queries;
// path_integrator.cpp: the batched integrator; path_tracer_frame.cpp: a frame and its adaptive
// sampling; path_tracer_changes.cpp: the radiance-change pairs): the paths' state between the stages
// of a batch and small helpers. Not for use outside src/render.
#include <cmath>
#include <limits>
#include <vector>

#include "render/bsdf_batch.h"
#include "render/equirect_batch.h"
#include "render/path_tracer.h"

namespace dynbench::render {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Adaptive sampling needs a variance estimate to stop on: its first round has at least this many samples.
inline constexpr int kMinFirstRound = 16;
// The pilot's random streams' seed, the word pilot in ASCII (the frame and pixel key them; the
// render's seed does not).
inline constexpr std::uint64_t kPilotSeed = 0x70696c6f74ull;

// Rays leave a surface from a point pushed off it along the geometric normal, by an amount that
// grows with the coordinates' magnitude (Embree intersects in single precision).
inline glm::dvec3 offsetOrigin(const glm::dvec3& p, const glm::dvec3& normalTowardsRay) {
  const double scale = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return p + normalTowardsRay * (3e-5 * scale);
}

// Where a shadow ray towards a light `distance` away stops: short of the light, by a relative and
// an absolute margin (the light may sit on a surface), and at 1e30 for light from infinitely far.
inline double shadowRayEnd(double distance) { return std::isinf(distance) ? 1e30 : distance * (1.0 - 1e-4) - 3e-5; }

inline bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

inline void put3(std::vector<float>& buffer, std::size_t pixel, const glm::dvec3& v) {
  for (int c = 0; c < 3; ++c) buffer[3 * pixel + static_cast<std::size_t>(c)] = static_cast<float>(v[c]);
}

struct PathTracer::Shading {
  SurfaceMaterial material;
  glm::dvec3 shadingNormal{0.0};    // faces the viewer
  glm::dvec3 geometricNormal{0.0};  // faces the viewer
  double emissiveWeight = 0.0;      // luminance of the emissive factor (the light choice's weight)
};

struct PathTracer::PathSample {
  glm::dvec3 direct{0.0}, indirect{0.0};
};

// One path of a batch between its stages.
struct PathTracer::PathState {
  const FirstVertex* first = nullptr;  // its pixel's camera ray and first hit
  Random rng;
  // A radiance-change pair's half (renderChanges): `rng` is drawn anew at every vertex from this
  // key (Random::vertex), so that both halves draw the same numbers at every vertex.
  bool keyed = false;
  std::uint64_t keySeed = 0, keyFrame = 0, keyPixel = 0, keySample = 0;
  // A pair's previous half: its first bounce is sampled as the current half's is, from the current
  // camera's view direction `samplingView` (the same lobe, the same direction, the same density),
  // and weighted by its own BSDF value towards its own camera (renderChanges says why).
  bool sharedFirstBounce = false;
  glm::dvec3 samplingView{0.0};
  Ray ray;
  std::size_t streamIndex = 0;  // where the hit of `ray` is in the batch's stream (depth > 0)
  glm::dvec3 throughput{1.0};
  double pathLength = 0.0;  // from the camera to the current hit along the path: the ray cone's length
  PathSample out;
  double previousBsdfPdf = 0.0;  // solid-angle pdf of the BSDF sample that made `ray`
  bool previousDelta = true;     // camera rays: nothing else could have found the emitter
  bool active = true;
  // The light sample, started in the trace stage (its random numbers drawn in the order the path
  // draws them: nothing else draws between the hit and them) so that the table entry it reads
  // next is loading; finished in the prefetch stage.
  LightSet::Choice lightChoice;
  glm::dvec2 uv{0.0};  // the hit's texture coordinates, or the environment image point of an escape
  double escapeSinTheta = 0.0;  // sin(theta) of an escape's direction (the environment's Jacobian)
  // Between the shading and the bounce of stage 3: the path's lane of the batch's BSDFs, its light
  // sample (evaluated in that lane when `lightEvaluated`) and where its rays leave.
  std::size_t lane = 0;
  LightSample lightSample;
  bool lightEvaluated = false;
  glm::dvec3 origin{0.0}, shadingNormal{0.0};
};

// A pixel whose paths wait in the thread's queue (PathScratch::queue): its camera ray and first
// hit, the same for every path of the pixel (the same hit seen from the same direction), so its
// shading and ray origin are found once; and its samples still to be traced, [next, upTo). With a
// pixel filter each path traces its own camera ray: `hit` is null and `ray` unused.
struct PathTracer::FirstVertex {
  std::size_t pixel = 0;
  Ray ray;
  const SurfaceHit* hit = nullptr;
  Shading shading;
  glm::dvec3 origin{0.0};
  int next = 0, upTo = 0;
};

// Per-thread working memory of the path loop, so the per-ray path does not allocate.
struct PathTracer::PathScratch {
  // The scene state the paths are traced in: the frame's (rayTracing_, lights_), or for the
  // previous half of a radiance-change pair the previous frame's (renderChanges).
  const RayTracingScene* scene = nullptr;
  const LightSet* lights = nullptr;
  // For a radiance-change pair's halves: both frames' punctual lights, and which half (0: this
  // frame, 1: the previous) is traced.
  const PairLights* pairLights = nullptr;
  int pairHalf = 0;
  // The frame's learned light visibility (render), or nullptr: the tree's own importance.
  const LightVisibility* visibility = nullptr;
  // What advance computes at a path vertex, written in place (returned by value, GCC zeroed and
  // copied them, with loads that waited on the stores just made).
  Shading shading;
  LightSample lightSample;
  BsdfSample bsdfSample;
  BsdfBatch bsdfs;  // the BSDFs of a stage's shading points, evaluated and sampled together
  EquirectBatch equirect;  // escapes' directions mapped to environment image points, together
  std::vector<LightSet::Choice*> choices;  // a stage's light choices, their directions mapped together
  std::vector<LightTree::Selected> selected;  // punctual lights selected at a shading point
  // Pixels whose paths are still to be traced: entries [queueHead, queueEnd) of `queue`, which
  // keeps its entries for the next pixels.
  std::vector<FirstVertex> queue;
  std::size_t queueHead = 0, queueEnd = 0;
  std::vector<PathState> paths;   // a batch
  // The spread angle of a pixel's ray cone (Akenine-Möller et al. 2019: atan(2 tan(yfov / 2) / H)),
  // set by render for its frame: the cone of a path is pixelSpread x its length, for the textures'
  // level of detail at each hit (the primary cone carried along the path; a surface's curvature
  // and roughness do not widen it).
  double pixelSpread = 0.0;
  std::vector<Ray> streamRays;        // the batch's rays still going, and their hits
  std::vector<SurfaceHit> streamHits;
  std::uint64_t rays = 0, shadingPoints = 0, punctualEvaluated = 0;
};

}  // namespace dynbench::render
