#pragma once
// The light sources a frame is lit by, and how next event estimation picks one.
//
// Units: dynbench renders radiance in the dataset's photometric units. A KHR_lights_punctual point
// or spot light of intensity I (candela) and colour c gives a surface at distance d the
// illuminance I c cos(theta) / d^2 (times KHR's range window and spot cone falloff); a directional
// light gives E c cos(theta) (lux); the environment image holds radiance (cd/m2) times its
// intensity; an emissive surface emits emissiveFactor (times emissiveStrength and the emissive
// texture) as radiance. docs/feature-buffers.md repeats this.
#include <functional>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "render/raytracing_scene.h"
#include "render/sampling.h"
#include "scene/scene.h"

namespace dynbench::render {

// An equirectangular environment (core/math.h's mapping), importance-sampled by pixel luminance
// times the pixel's solid angle. Radiance is looked up at the nearest pixel, so the sampled
// density and the looked-up radiance are the same piecewise-constant function.
class EnvironmentLight {
 public:
  static Expected<EnvironmentLight> load(const scene::Environment& environment);
  // The same radiance from every direction (white furnace tests, `--env-constant`).
  static EnvironmentLight constant(const glm::dvec3& radiance);

  glm::dvec3 radiance(const glm::dvec3& direction) const;
  // A direction towards the environment with its solid-angle density.
  glm::dvec3 sample(glm::dvec2 u, double* pdf) const;
  double pdf(const glm::dvec3& direction) const;
  // Mean radiance over the sphere (luminance), for choosing between lights.
  double meanLuminance() const { return meanLuminance_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<glm::vec3> pixels_;  // radiance, intensity applied
  Distribution2D distribution_;
  double meanLuminance_ = 0.0;
};

struct LightSample {
  glm::dvec3 direction{0.0};  // unit, from the shaded point towards the light
  double distance = 0.0;      // to the light; infinity for the environment and directional lights
  glm::dvec3 radiance{0.0};   // arriving radiance, or for a delta light the irradiance it gives a surface facing it
  double pdf = 0.0;           // selection probability times the solid-angle density (delta: selection only)
  bool delta = false;         // punctual light: no other strategy can hit it, no MIS
};

// Emission of an emissive surface at a point of a triangle (the integrator evaluates the material).
using EmissionFunction = std::function<glm::dvec3(int node, int primitive, unsigned triangle, glm::dvec2 barycentric)>;

class LightSet {
 public:
  // Gathers the frame's lights: punctual lights at their nodes' world transforms (from the
  // ray-tracing scene's pose; hidden nodes are off), every visible emissive triangle, and the
  // environment. `sceneRadius` sizes the power estimate of directional and environment light.
  void build(const scene::Scene& scene, const RayTracingScene& rayTracing, const EnvironmentLight* environment,
             double sceneRadius, EmissionFunction emission);

  // With a few punctual lights (up to kEveryPunctualLimit) every one of them is sampled at each
  // shading point (a shadow ray each, no noise from choosing); with more, they join the random
  // choice below. Cube 2 maps have hundreds of lights; small test scenes have one or two.
  static constexpr std::size_t kEveryPunctualLimit = 8;
  std::size_t everyPunctualCount() const { return punctualInChoice_ ? 0 : punctual_.size(); }
  std::optional<LightSample> samplePunctual(std::size_t light, const glm::dvec3& point) const;

  bool empty() const { return choice_.empty(); }
  // One light picked by estimated power (the environment, the emissive triangles and, when there
  // are many, the punctual lights), then a point on it (next event estimation).
  std::optional<LightSample> sample(const glm::dvec3& point, double uChoice, glm::dvec2 u) const;
  // Densities of the other strategy for MIS, when a BSDF-sampled ray reaches the environment or
  // an emissive triangle (whose emissive factor luminance is `emissiveLuminance`).
  double pdfEnvironment(const glm::dvec3& direction) const;
  double pdfEmissive(double emissiveLuminance, double distance, double cosAtLight) const;
  // Luminance of an emissive factor as used for the triangle choice.
  static double emissiveWeight(const glm::dvec3& emissiveFactor) { return luminance(emissiveFactor); }

 private:
  struct Punctual {
    scene::Light::Type type;
    glm::dvec3 position{0.0}, direction{0.0, 0.0, -1.0};  // direction the light shines along
    glm::dvec3 intensity{0.0};                            // colour x intensity
    double range = 0.0, cosOuter = -1.0, cosInner = 1.0;
  };
  struct Triangle {
    glm::dvec3 p0, p1, p2;
    int node, primitive;
    unsigned index;
  };
  std::vector<Punctual> punctual_;
  std::vector<Triangle> triangles_;
  Distribution1D triangleChoice_;
  const EnvironmentLight* environment_ = nullptr;
  EmissionFunction emission_;
  // Choice among: punctual lights [0, P) when punctualInChoice_ (else P = 0), the environment (P),
  // the emissive triangles (P + 1).
  Distribution1D choice_;
  bool punctualInChoice_ = false;
  double environmentChoice_ = 0.0, emissiveChoice_ = 0.0;
};

}  // namespace dynbench::render
