#include "render/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/math.h"
#include "frames/radiance_change.h"
#include "render/bsdf_batch.h"
#include "render/equirect_batch.h"
#include "render/prefetch.h"

namespace dynbench::render {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kMinFirstRound = 16;

// Rays leave a surface from a point pushed off it along the geometric normal, by an amount that
// grows with the coordinates' magnitude (Embree intersects in single precision).
glm::dvec3 offsetOrigin(const glm::dvec3& p, const glm::dvec3& normalTowardsRay) {
  const double scale = std::max({1.0, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
  return p + normalTowardsRay * (3e-5 * scale);
}

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void put3(std::vector<float>& buffer, std::size_t pixel, const glm::dvec3& v) {
  for (int c = 0; c < 3; ++c) buffer[3 * pixel + static_cast<std::size_t>(c)] = static_cast<float>(v[c]);
}

}  // namespace

struct PathTracer::Shading {
  SurfaceMaterial material;
  glm::dvec3 shadingNormal{0.0};    // faces the viewer
  glm::dvec3 geometricNormal{0.0};  // faces the viewer
  double emissiveWeight = 0.0;      // luminance of the emissive factor (the light choice's weight)
};

PathTracer::PathTracer(const scene::Scene& scene, const RenderSettings& settings)
    : scene_(scene), settings_(settings), filter_(settings.pixelFilter) {}
PathTracer::~PathTracer() = default;

Expected<std::unique_ptr<PathTracer>> PathTracer::create(const scene::Scene& scene, const RenderSettings& settings,
                                                         std::vector<std::string>& warnings) {
  if (settings.width <= 0 || settings.height <= 0 || settings.samplesPerPixel <= 0 || settings.bounces < 0 || settings.pathBatch <= 0)
    return fail(ErrorCode::kUsage, "render settings: resolution, samples and path batch must be positive, bounces non-negative");
  if (settings.pixelFilter.type != PixelFilterType::kCentre && !(settings.pixelFilter.width > 0 && settings.pixelFilter.width <= 8))
    return fail(ErrorCode::kUsage, "--pixel-filter-width {}: expected a width in pixels in (0, 8]", settings.pixelFilter.width);
  std::unique_ptr<PathTracer> tracer(new PathTracer(scene, settings));
  auto textures = TextureSet::load(scene, warnings);
  if (!textures) return std::unexpected(textures.error());
  tracer->textures_ = std::move(*textures);
  if (settings.constantEnvironment) {
    tracer->environment_ = EnvironmentLight::constant(*settings.constantEnvironment);
  } else if (settings.useEnvironment && scene.environment) {
    auto env = EnvironmentLight::load(*scene.environment);
    if (!env) return std::unexpected(env.error());
    tracer->environment_ = std::move(*env);
  }
  const PathTracer* self = tracer.get();
  auto alphaTest = [self] {
    AlphaTest alpha;
    alpha.needed = [self](int node, int primitive) {
      const scene::Material* m = self->materialOf(node, primitive);
      return m && m->alphaMode == scene::AlphaMode::kMask;
    };
    alpha.opaque = [self](int node, int primitive, unsigned triangle, glm::dvec2 b) {
      return self->alphaOpaque(node, primitive, triangle, b);
    };
    return alpha;
  };
  auto rt = RayTracingScene::create(scene, alphaTest());
  if (!rt) return std::unexpected(rt.error());
  tracer->rayTracing_ = std::move(*rt);
  if (settings.pairs) {
    if (settings.maxPairs < frames::kFirstPairs)
      return fail(ErrorCode::kUsage, "--max-pairs {}: expected at least {} (the first round's pairs)", settings.maxPairs, frames::kFirstPairs);
    // The same geometries in the same order as rayTracing_, so that a hit of one names the same
    // surface point in the other (RayTracingScene::surfaceAt).
    auto previous = RayTracingScene::create(scene, alphaTest());
    if (!previous) return std::unexpected(previous.error());
    tracer->previousRayTracing_ = std::move(*previous);
  }
  return tracer;
}

const scene::Primitive& PathTracer::primitiveOf(int node, int primitive) const {
  const auto& n = scene_.nodes[static_cast<std::size_t>(node)];
  return scene_.meshes[static_cast<std::size_t>(n.mesh)].primitives[static_cast<std::size_t>(primitive)];
}

const scene::Material* PathTracer::materialOf(int node, int primitive) const { return materialOf(primitiveOf(node, primitive)); }

const scene::Material* PathTracer::materialOf(const scene::Primitive& primitive) const {
  return primitive.material >= 0 ? &scene_.materials[static_cast<std::size_t>(primitive.material)] : nullptr;
}

namespace {

// The texture coordinates at barycentric point b of the triangle with these vertices.
glm::dvec2 interpolateUv(const scene::Primitive& prim, const std::uint32_t* vertices, glm::dvec2 b) {
  if (prim.uvs.empty()) return glm::dvec2(0.0);
  return (1.0 - b.x - b.y) * glm::dvec2(prim.uvs[vertices[0]]) + b.x * glm::dvec2(prim.uvs[vertices[1]]) +
         b.y * glm::dvec2(prim.uvs[vertices[2]]);
}

}  // namespace

glm::dvec2 PathTracer::texCoord(int node, int primitive, unsigned triangle, glm::dvec2 b) const {
  const scene::Primitive& prim = primitiveOf(node, primitive);
  return interpolateUv(prim, &prim.indices[3 * static_cast<std::size_t>(triangle)], b);
}

glm::dvec2 PathTracer::texCoord(const SurfaceHit& hit) const {
  return interpolateUv(*hit.source, hit.vertices.data(), hit.barycentric);
}

void PathTracer::prefetchTexCoords(const SurfaceHit& hit) const {
  const scene::Primitive& prim = *hit.source;
  if (prim.uvs.empty()) return;
  for (const std::uint32_t v : hit.vertices) prefetchLine(&prim.uvs[v]);
}

void PathTracer::prefetchTextures(const SurfaceHit& hit, glm::dvec2 uv) const {
  const scene::Material* m = materialOf(*hit.source);
  if (!m) return;
  textures_.prefetch(m->baseColorTexture, true, uv);
  if (m->workflow == scene::MaterialWorkflow::kMetallicRoughness) textures_.prefetch(m->metallicRoughnessTexture, false, uv);
  textures_.prefetch(m->normalTexture, false, uv);
  if (m->emissiveFactor != glm::vec3(0.0f)) textures_.prefetch(m->emissiveTexture, true, uv);
}

// glTF alphaMode MASK: the surface exists where base colour alpha (factor x texture) >= cutoff.
bool PathTracer::alphaOpaque(int node, int primitive, unsigned triangle, glm::dvec2 b) const {
  const scene::Material* m = materialOf(node, primitive);
  if (!m || m->alphaMode != scene::AlphaMode::kMask) return true;
  double alpha = m->baseColorFactor.a;
  if (m->baseColorTexture.image >= 0)
    alpha *= textures_.sample(m->baseColorTexture, true, texCoord(node, primitive, triangle, b)).a;
  return alpha >= m->alphaCutoff;
}

glm::dvec3 PathTracer::emission(int node, int primitive, unsigned triangle, glm::dvec2 b) const {
  const scene::Material* m = materialOf(node, primitive);
  if (!m) return glm::dvec3(0.0);
  // The texture coordinates only where the texture is read.
  if (m->emissiveFactor == glm::vec3(0.0f) || m->emissiveTexture.image < 0) return glm::dvec3(m->emissiveFactor);
  return emission(*m, texCoord(node, primitive, triangle, b));
}

glm::dvec3 PathTracer::emission(const scene::Material& m, glm::dvec2 uv, double lod) const {
  glm::dvec3 e(m.emissiveFactor);
  if (e != glm::dvec3(0.0) && m.emissiveTexture.image >= 0) e *= glm::dvec3(textures_.sample(m.emissiveTexture, true, uv, lod));
  return e;
}

PathTracer::Shading PathTracer::shade(const SurfaceHit& hit, const glm::dvec3& wo, glm::dvec2 uv, double coneWidth) const {
  Shading s;
  shade(hit, wo, uv, coneWidth, *rayTracing_, s);
  return s;
}

double PathTracer::textureLodAt(const SurfaceHit& hit, const std::array<glm::dvec3, 3>& p, const glm::dvec3& direction,
                                double coneWidth) const {
  const scene::Primitive& prim = *hit.source;
  if (prim.uvs.empty() || !(coneWidth > 0)) return -kInfinity;
  const std::uint32_t* idx = hit.vertices.data();
  const glm::dvec2 d1 = glm::dvec2(prim.uvs[idx[1]]) - glm::dvec2(prim.uvs[idx[0]]);
  const glm::dvec2 d2 = glm::dvec2(prim.uvs[idx[2]]) - glm::dvec2(prim.uvs[idx[0]]);
  const double uvArea = std::abs(d1.x * d2.y - d2.x * d1.y);
  const double worldArea = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
  return textureLod(coneWidth, glm::dot(hit.geometricNormal, direction), uvArea, worldArea);
}

void PathTracer::shade(const SurfaceHit& hit, const glm::dvec3& wo, glm::dvec2 uv, double coneWidth, const RayTracingScene& scene,
                       Shading& s) const {
  // The triangle's corners and the level of detail only where a texture is read.
  const scene::Material* m = materialOf(*hit.source);
  const bool textured = m && (m->baseColorTexture.image >= 0 || m->metallicRoughnessTexture.image >= 0 || m->normalTexture.image >= 0 ||
                              m->emissiveTexture.image >= 0);
  std::array<glm::dvec3, 3> corners{};
  if (textured) corners = scene.trianglePositions(hit);
  const double lod = textured ? textureLodAt(hit, corners, -wo, coneWidth) : -kInfinity;
  shadeAt(hit, wo, uv, corners, lod, s);
}

void PathTracer::shadeAt(const SurfaceHit& hit, const glm::dvec3& wo, glm::dvec2 uv, const std::array<glm::dvec3, 3>& corners, double lod,
                         Shading& s) const {
  const scene::Material* m = materialOf(*hit.source);
  SurfaceMaterial& mat = s.material;
  if (!m) {
    // glTF's default material when a primitive has none: white, metallic 1, roughness 1 (§3.9.6).
    mat = SurfaceMaterial{};
    mat.metallic = 1.0;
    s.emissiveWeight = 0.0;
  } else {
    glm::dvec4 base(m->baseColorFactor);
    if (m->baseColorTexture.image >= 0) base *= textures_.sample(m->baseColorTexture, true, uv, lod);
    if (const scene::Primitive& prim = *hit.source; !prim.colors.empty()) {
      // glTF: COLOR_0 multiplies the base colour, interpolated over the triangle.
      const glm::dvec2 b = hit.barycentric;
      base *= (1.0 - b.x - b.y) * glm::dvec4(prim.colors[hit.vertices[0]]) + b.x * glm::dvec4(prim.colors[hit.vertices[1]]) +
              b.y * glm::dvec4(prim.colors[hit.vertices[2]]);
    }
    mat.baseColor = glm::dvec3(base);
    if (m->workflow == scene::MaterialWorkflow::kMetallicRoughness) {
      mat.metallic = m->metallicFactor;
      mat.roughness = m->roughnessFactor;
      if (m->metallicRoughnessTexture.image >= 0) {
        const glm::dvec4 mr = textures_.sample(m->metallicRoughnessTexture, false, uv, lod);
        mat.roughness *= mr.g;  // glTF: green = roughness, blue = metallic
        mat.metallic *= mr.b;
      }
    } else {
      // Specular-glossiness and Phong-style materials render as their diffuse colour.
      mat.metallic = 0.0;
      mat.roughness = 1.0;
    }
    mat.specular = m->specularFactor;
    mat.specularColor = glm::dvec3(m->specularColorFactor);
    s.emissiveWeight = LightSet::emissiveWeight(glm::dvec3(m->emissiveFactor));
    mat.emission = emission(*m, uv, lod);
  }
  // Both sides of a surface are shaded alike: the normals are turned towards the viewer. When a
  // mesh's winding contradicts its vertex normals, the vertex normals say which side is which.
  const glm::dvec3 ng = glm::dot(hit.geometricNormal, hit.shadingNormal) < 0 ? -hit.geometricNormal : hit.geometricNormal;
  const bool back = glm::dot(ng, wo) < 0;
  s.geometricNormal = back ? -ng : ng;
  glm::dvec3 n = back ? -hit.shadingNormal : hit.shadingNormal;
  if (m && m->normalTexture.image >= 0 && textures_.find(m->normalTexture.image, false)) {
    // Tangent frame from the triangle's uv parameterisation (what glTF implies when a mesh has no
    // TANGENT attribute), then n = T x + B y + N z with (x, y, z) = 2 texel - 1.
    const auto& p = corners;
    const scene::Primitive& prim = *hit.source;
    if (!prim.uvs.empty()) {
      const std::uint32_t* idx = hit.vertices.data();
      const glm::dvec2 d1 = glm::dvec2(prim.uvs[idx[1]]) - glm::dvec2(prim.uvs[idx[0]]);
      const glm::dvec2 d2 = glm::dvec2(prim.uvs[idx[2]]) - glm::dvec2(prim.uvs[idx[0]]);
      const double det = d1.x * d2.y - d2.x * d1.y;
      if (std::abs(det) > 1e-20) {
        glm::dvec3 t = ((p[1] - p[0]) * d2.y - (p[2] - p[0]) * d1.y) / det;
        t -= n * glm::dot(n, t);
        if (glm::length(t) > 1e-20) {
          t = glm::normalize(t);
          const glm::dvec3 b = glm::cross(n, t);
          const glm::dvec3 texel = 2.0 * glm::dvec3(textures_.sample(m->normalTexture, false, uv, lod)) - 1.0;
          const glm::dvec3 mapped = texel.x * t + texel.y * b + texel.z * n;
          if (glm::length(mapped) > 1e-12) n = glm::normalize(mapped);
        }
      }
    }
  }
  // A shading normal facing away from the viewer would make the surface black: pull it back to
  // just in front (a common fix; pbrt and Cycles do similar).
  if (glm::dot(n, wo) < 1e-4) n = glm::normalize(n - wo * (glm::dot(n, wo) - 1e-4));
  s.shadingNormal = n;
}

SurfaceHit PathTracer::trace(const Ray& ray) const { return rayTracing_->intersect(ray); }

Expected<void> PathTracer::setTime(double time, double previousTime) {
  if (!time_ || *time_ != previousTime)
    if (auto ok = rayTracing_->update(previousTime); !ok) return ok;
  if (auto ok = rayTracing_->update(time); !ok) return ok;
  time_ = time;
  // The scene's size for the light choice: from the first frame's geometry.
  if (!sceneRadius_) {
    sceneRadius_ = 1.0;
    glm::dvec3 lo(kInfinity), hi(-kInfinity);
    rayTracing_->forEachPrimitive([&](const PrimitiveView& v) {
      for (const auto& p : *v.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    });
    if (lo.x <= hi.x) sceneRadius_ = std::max(1e-3, 0.5 * glm::length(hi - lo));
  }
  const auto emissionAt = [this](int node, int primitive, unsigned triangle, glm::dvec2 b) { return emission(node, primitive, triangle, b); };
  if (previousRayTracing_) {
    if (!previousTime_ || *previousTime_ != previousTime)
      if (auto ok = previousRayTracing_->update(previousTime); !ok) return ok;
    previousTime_ = previousTime;
    if (auto ok = previousLights_.build(scene_, *previousRayTracing_, environment_ ? &*environment_ : nullptr, *sceneRadius_, emissionAt); !ok)
      return ok;
  }
  return lights_.build(scene_, *rayTracing_, environment_ ? &*environment_ : nullptr, *sceneRadius_, emissionAt);
}

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
      // A pair's halves evaluate every light that reaches the point (lightsPerPoint 0): each frame's
      // light tree is built from its own lights, and once they differ (a muzzle flash, a moving
      // player's light) the same number picks different lights in the two halves everywhere.
      scratch.lights->selectPunctual(hit.position, s.geometricNormal, uLight, p.keyed ? 0 : settings_.lightsPerPoint, scratch.selected);
      scratch.punctualEvaluated += scratch.selected.size();
      if (!scratch.selected.empty()) {
        const Bsdf bsdf(s.material, Frame(s.shadingNormal), s.geometricNormal);
        const Bsdf::View view = bsdf.view(wo);
        LightSample& punctual = scratch.lightSample;
        for (const LightTree::Selected& selected : scratch.selected)
          if (scratch.lights->samplePunctual(selected.light, hit.position, punctual)) {
            punctual.pdf = selected.probability;
            addLight(p, depth, punctual, bsdf.evaluate(view, punctual.direction), scratch);
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
  const double tMax = std::isinf(ls.distance) ? 1e30 : ls.distance * (1.0 - 1e-4) - 3e-5;
  ++scratch.rays;
  if (scratch.scene->occluded(p.origin, ls.direction, tMax)) return;
  const double w = ls.delta ? 1.0 : powerHeuristic(ls.pdf, e.pdf);
  glm::dvec3& bucket = depth == 0 ? p.out.direct : p.out.indirect;  // light reaching this hit
  bucket += p.throughput * f * ls.radiance * (cosine * w / ls.pdf);
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

namespace {

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

FrameBuffers PathTracer::render(std::uint64_t frameIndex, const RenderCamera& camera, const RenderCamera& previousCamera,
                                std::atomic<int>* rowsDone, RenderStatistics* statistics) const {
  FrameBuffers out;
  out.resize(camera.width(), camera.height());
  std::fill(out.id.begin(), out.id.end(), -1.0f);  // the contract's "no instance"
  // Adaptive sampling needs a variance estimate to stop on: its first round has at least 16 samples.
  const int width = camera.width(), height = camera.height(),
            firstRound = settings_.converge ? std::max(settings_.samplesPerPixel, kMinFirstRound) : settings_.samplesPerPixel;
  const std::size_t pixels = out.pixelCount();
  const glm::dvec3 forward = -glm::dvec3(camera.world()[2]);
  std::vector<PixelSums> sums(pixels);
  std::vector<SurfaceHit> firstHits(pixels);
  // A pixel's ray cone spreads by this angle (radians) per unit of length (textureLod).
  const double pixelSpread = std::atan(2.0 * std::tan(0.5 * camera.yfov()) / height);
  tbb::enumerable_thread_specific<PathScratch> scratches([this, pixelSpread] {
    PathScratch scratch;
    scratch.scene = rayTracing_.get();
    scratch.lights = &lights_;
    scratch.pixelSpread = pixelSpread;
    return scratch;
  });
  const glm::dvec2 jitter = settings_.jitter ? frames::jitterOffset(static_cast<long>(frameIndex)) : glm::dvec2(0.0);

  // The ray through a pixel's (jittered) centre.
  auto pixelRay = [&](std::size_t pixel) {
    const int px = static_cast<int>(pixel % static_cast<std::size_t>(width)), py = static_cast<int>(pixel / static_cast<std::size_t>(width));
    return camera.ray(px + 0.5 + jitter.x, py + 0.5 + jitter.y);
  };
  // With a pixel filter: a radiance sample's own camera ray, through the (jittered) pixel centre
  // offset by the filter, from the first two numbers of the sample's random stream.
  const bool filtered = !filter_.atCentre();
  auto filteredRay = [&](std::size_t pixel, Random& rng) {
    const int px = static_cast<int>(pixel % static_cast<std::size_t>(width)), py = static_cast<int>(pixel / static_cast<std::size_t>(width));
    const glm::dvec2 offset = filter_.offset(rng.uniform2());
    return camera.ray(px + 0.5 + jitter.x + offset.x, py + 0.5 + jitter.y + offset.y);
  };
  // A pixel's samples up to `upTo`: at the pixel centre, one environment lookup where its camera
  // ray `ray` escapes, else its paths queued in the thread's scratch (`known`: the first hit's
  // shading when the caller has it already, the first round's buffers); with a filter, its paths
  // queued to trace their own camera rays. flush traces them.
  auto enqueue = [&](std::size_t pixel, const Ray& ray, int upTo, PathScratch& scratch, const Shading* known = nullptr) {
    const SurfaceHit& hit = firstHits[pixel];
    PixelSums& sum = sums[pixel];
    if (!filtered && !hit.hit) {
      // The camera sees the environment: a single lookup, no noise.
      const glm::dvec3 le = environment_ ? environment_->radiance(ray.direction) : glm::dvec3(0.0);
      while (sum.samples < upTo) sum.add(le, glm::dvec3(0.0));
      return;
    }
    if (sum.samples >= upTo) return;
    if (scratch.queueEnd == scratch.queue.size()) scratch.queue.emplace_back();
    FirstVertex& v = scratch.queue[scratch.queueEnd++];
    v.pixel = pixel;
    v.ray = ray;
    v.hit = filtered ? nullptr : &hit;
    if (!filtered) {
      if (known) v.shading = *known;
      else shade(hit, -ray.direction, texCoord(hit), pixelSpread * hit.distance, *rayTracing_, v.shading);
      v.origin = offsetOrigin(hit.position, v.shading.geometricNormal);
    }
    v.next = sum.samples;
    v.upTo = upTo;
  };
  // Traces the queued paths in batches of pathBatch, in queue order, each path with the random
  // stream of its pixel and sample index, and sums them per pixel in sample order; a batch may
  // span several pixels (at 16 spp one pixel filled half a batch, and a shorter batch hides less of
  // the memory latency and fills fewer SIMD lanes). `all`: also the last, partial batch. Each path
  // computes what it would alone, so the image does not depend on how pixels share batches.
  auto flush = [&](PathScratch& scratch, bool all) {
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
        for (; v.next < v.upTo && n < batch; ++v.next, ++n) {
          paths[n].first = &v;
          paths[n].rng = Random(settings_.seed, frameIndex, v.pixel, static_cast<std::uint64_t>(v.next));
          paths[n].ray = v.hit ? v.ray : filteredRay(v.pixel, paths[n].rng);
        }
      }
      tracePaths(paths, scratch);
      for (const PathState& p : paths) sums[p.first->pixel].add(p.out.direct, p.out.indirect);
      while (scratch.queueHead < scratch.queueEnd && queue[scratch.queueHead].next == queue[scratch.queueHead].upTo) ++scratch.queueHead;
      if (scratch.queueHead == scratch.queueEnd) scratch.queueHead = scratch.queueEnd = 0;
    }
  };

  // First round: the geometry buffers from the ray through each pixel centre (so that P, N, Z,
  // id and motion describe one surface point; a blend of two surfaces across an edge is on
  // neither), then samplesPerPixel paths from that same hit.
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 1), [&](const tbb::blocked_range<int>& rows) {
    PathScratch& scratch = scratches.local();
    for (int py = rows.begin(); py < rows.end(); ++py) {
      for (int px = 0; px < width; ++px) {
        const std::size_t pixel = static_cast<std::size_t>(py) * static_cast<std::size_t>(width) + static_cast<std::size_t>(px);
        const Ray ray = pixelRay(pixel);
        const SurfaceHit hit = trace(ray);
        ++scratch.rays;
        firstHits[pixel] = hit;
        std::optional<Shading> shading;
        if (hit.hit) {
          const Shading& s = shading.emplace(shade(hit, -ray.direction, texCoord(hit), pixelSpread * hit.distance));
          put3(out.position, pixel, hit.position);
          put3(out.normal, pixel, s.shadingNormal);
          put3(out.albedo, pixel, s.material.baseColor);
          out.depth[pixel] = static_cast<float>(glm::dot(hit.position - camera.position(), forward));
          out.id[pixel] = static_cast<float>(hit.node);
          out.hit[pixel] = 1.0f;
          const PixelProjection previous = previousCamera.project(rayTracing_->previousPosition(hit));
          // Behind the previous camera there is no pixel to point to: a vector far off screen.
          const glm::dvec2 target = previous.inFront ? previous.pixel : glm::dvec2(-1e9);
          out.motion[2 * pixel] = static_cast<float>(target.x - (px + 0.5 + jitter.x));
          out.motion[2 * pixel + 1] = static_cast<float>(target.y - (py + 0.5 + jitter.y));
        }
        enqueue(pixel, ray, firstRound, scratch, shading ? &*shading : nullptr);
        flush(scratch, false);
      }
      flush(scratch, true);
      if (rowsDone && !settings_.converge) rowsDone->fetch_add(1, std::memory_order_relaxed);
    }
  });

  frames::SamplingSummary summary;
  summary.lightsPerPoint = settings_.lightsPerPoint;
  if (settings_.converge) {
    // The targets: tolerance x the discard threshold of each buffer, which is a fraction of the
    // frame's mean luminance (discard's default relative thresholds), estimated from the first
    // round. A pixel converges when both standard errors are at or below their targets.
    double meanDirect = 0.0, meanIndirect = 0.0;
    for (const auto& p : sums) {
      meanDirect += luminance(p.direct) / p.samples;
      meanIndirect += luminance(p.indirect) / p.samples;
    }
    meanDirect /= static_cast<double>(pixels);
    meanIndirect /= static_cast<double>(pixels);
    summary.adaptive = true;
    summary.tolerance = settings_.tolerance;
    // Discard's expected test measures a luminance change on the thresholds' RGB scale, x sqrt(3)
    // (a grey change): the luminance standard error's target is the threshold's share over sqrt(3).
    summary.directTarget = settings_.tolerance * settings_.directThresholdFraction * meanDirect / frames::kGreyDistance;
    summary.indirectTarget = settings_.tolerance * settings_.indirectThresholdFraction * meanIndirect / frames::kGreyDistance;
    const double directTargetSq = summary.directTarget * summary.directTarget;
    const double indirectTargetSq = summary.indirectTarget * summary.indirectTarget;
    const int cap = std::max(firstRound, settings_.maxSamplesPerPixel);
    // Each pixel sampled in rounds until it converges; its random streams are its sample indices,
    // so the result does not depend on the thread schedule. Scheduled in runs of 8 pixels, not
    // rows: a row of capped pixels costs seconds, and a core would wait for it at the frame's end.
    std::atomic<std::size_t> pixelsDone{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels, 8), [&](const tbb::blocked_range<std::size_t>& run) {
      PathScratch& scratch = scratches.local();
      auto ratio = [](double variance, double targetSq) {
        if (variance <= 0) return 0.0;
        return targetSq > 0 ? variance / targetSq : std::numeric_limits<double>::infinity();
      };
      // In rounds: every pixel of the run that has not converged queues its next samples, then
      // they are traced together. A pixel's counts depend on its own sums alone.
      for (bool queued = true; queued;) {
        queued = false;
        for (std::size_t pixel = run.begin(); pixel < run.end(); ++pixel) {
          const PixelSums& sum = sums[pixel];
          if (sum.samples >= cap) continue;
          const double r = std::max(ratio(sum.directVariance(), directTargetSq), ratio(sum.indirectVariance(), indirectTargetSq));
          if (r <= 1.0) continue;
          enqueue(pixel, pixelRay(pixel), nextSampleCount(sum.samples, r, firstRound, cap), scratch);
          queued = true;
        }
        flush(scratch, true);
      }
      const std::size_t done = pixelsDone.fetch_add(run.size(), std::memory_order_relaxed) + run.size();
      // Whole rows' worth, for progress; the last run's store below makes it `height` exactly.
      if (rowsDone) rowsDone->store(std::min(height - 1, static_cast<int>(done / static_cast<std::size_t>(width))), std::memory_order_relaxed);
    });
    if (rowsDone) rowsDone->store(height, std::memory_order_relaxed);
    for (const auto& p : sums)
      if (p.samples >= cap && (p.directVariance() > directTargetSq || p.indirectVariance() > indirectTargetSq)) ++summary.cappedPixels;
  }

  std::uint64_t totalSamples = 0;
  summary.minSamples = std::numeric_limits<int>::max();
  for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
    const PixelSums& p = sums[pixel];
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
  summary.meanSamples = pixels ? static_cast<double>(totalSamples) / static_cast<double>(pixels) : 0.0;
  out.sampling = summary;
  if (statistics) {
    statistics->cameraSamples += totalSamples;
    for (const auto& scratch : scratches) {
      statistics->rays += scratch.rays;
      statistics->shadingPoints += scratch.shadingPoints;
      statistics->punctualEvaluated += scratch.punctualEvaluated;
    }
    statistics->punctualInFrame += lights_.punctualCount();
  }
  return out;
}

}  // namespace dynbench::render

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
    b.scratch.scene = rayTracing_.get();
    b.scratch.lights = &lights_;
    tracePaths(b.pathsNow, b.scratch, true);
    b.scratch.scene = previousRayTracing_.get();
    b.scratch.lights = &previousLights_;
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
