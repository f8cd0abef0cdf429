#pragma once
// The glTF 2.0 metallic-roughness BRDF (glTF 2.0 Appendix B, with KHR_materials_specular's
// specular factor): a mix by `metallic` of
//   dielectric = (1 - max(F_d)) * baseColor / pi + F_d * S,   F_d = Schlick(f0 = 0.04 * specular)
//   metal      = F_m * S,                                      F_m = Schlick(f0 = baseColor)
// with the microfacet term S = D G / (4 |n.l| |n.v|): GGX distribution D (alpha = roughness^2),
// separable Smith masking-shadowing G, Schlick Fresnel on v.h. Surfaces reflect only; both sides
// of a surface are shaded alike (the normal is turned towards the viewer).
#include <optional>

#include <glm/glm.hpp>

#include "render/sampling.h"

namespace dynbench::render {

struct SurfaceMaterial {
  glm::dvec3 baseColor{1.0};
  double metallic = 0.0;
  double roughness = 1.0;
  double specular = 1.0;          // KHR_materials_specular specularFactor
  glm::dvec3 specularColor{1.0};  // KHR_materials_specular specularColorFactor
  glm::dvec3 emission{0.0};       // radiance leaving the surface, both sides
};

struct BsdfSample {
  glm::dvec3 direction{0.0};  // world, unit, away from the surface
  glm::dvec3 value{0.0};      // f(wo, wi)
  double pdf = 0.0;           // solid angle
};

class Bsdf {
 public:
  // `shading` is the shading frame (its n faces the viewer); `geometricNormal` also faces the
  // viewer and rejects directions below the true surface (light leaks through normal maps).
  Bsdf(const SurfaceMaterial& material, const Frame& shading, const glm::dvec3& geometricNormal);

  glm::dvec3 eval(const glm::dvec3& wo, const glm::dvec3& wi) const;
  double pdf(const glm::dvec3& wo, const glm::dvec3& wi) const;
  // Picks the specular lobe with probability specularProbability(wo), else the diffuse one
  // (cosine-weighted); the GGX lobe samples visible normals (Heitz 2018).
  std::optional<BsdfSample> sample(const glm::dvec3& wo, glm::dvec2 u, double uLobe) const;

  // What the three calls above derive from wo alone, derived once: a path vertex evaluates, weighs
  // and samples with the same wo (same results, less arithmetic).
  struct View {
    glm::dvec3 local;  // wo in the shading frame
    double specularProbability = 0.0;
    double maskingWo = 0.0;  // Smith G1(wo)
    bool above = false;      // wo is on the geometric normal's side
  };
  View view(const glm::dvec3& wo) const;
  // f(wo, wi) and the solid-angle pdf of sample() choosing wi, in one pass: they share the half
  // vector and the GGX terms (a light sample needs both).
  struct Evaluation {
    glm::dvec3 value{0.0};
    double pdf = 0.0;
  };
  Evaluation evaluate(const View& view, const glm::dvec3& wi) const;
  // sample() from a view, into `out`; false where sample() gives nothing. (Written in place: the
  // optional, returned, cost GCC a copy whose loads waited on the stores just made.)
  bool sample(const View& view, glm::dvec2 u, double uLobe, BsdfSample& out) const;

  double alpha() const { return alpha_; }

  // Building blocks, in the local frame (n = +Z), exposed for known-answer tests.
  static double ggxD(const glm::dvec3& h, double alpha);
  static double smithG1(const glm::dvec3& v, double alpha);
  static glm::dvec3 sampleGgxVisibleNormal(const glm::dvec3& wo, double alpha, glm::dvec2 u);

 private:
  Evaluation evaluateLocal(const View& view, const glm::dvec3& wi) const;  // wi in the shading frame
  double specularProbability(const glm::dvec3& woLocal) const;

  SurfaceMaterial m_;
  Frame frame_;
  glm::dvec3 ng_;
  double alpha_;
  glm::dvec3 dielectricF0_;
  double dielectricF90_;
};

}  // namespace dynbench::render
