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
  if (auto ok = lights_.build(scene_, *rayTracing_, environment_ ? &*environment_ : nullptr, *sceneRadius_, emissionAt); !ok) return ok;
  if (previousRayTracing_) pairLights_.build(lights_, previousLights_);
  return {};
}


}  // namespace dynbench::render
