#include "render/bsdf.h"

#include <algorithm>
#include <cmath>

namespace dynbench::render {
namespace {

double schlickWeight(double cosine) {
  const double m = std::clamp(1.0 - cosine, 0.0, 1.0);
  return (m * m) * (m * m) * m;
}
double maxComponent(const glm::dvec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

}  // namespace

Bsdf::Bsdf(const SurfaceMaterial& material, const Frame& shading, const glm::dvec3& geometricNormal)
    : m_(material), frame_(shading), ng_(geometricNormal) {
  // Roughness 0 is a perfect mirror; a floor on alpha keeps the GGX lobe finite (a 2e-3 lobe is
  // far narrower than a pixel at our resolutions).
  const double r = std::clamp(m_.roughness, 0.0, 1.0);
  alpha_ = std::max(r * r, 2e-3);
  dielectricF0_ = glm::min(0.04 * m_.specularColor, glm::dvec3(1.0)) * m_.specular;  // (ior 1.5 - 1)^2/(ior + 1)^2 = 0.04
  dielectricF90_ = m_.specular;
}

double Bsdf::ggxD(const glm::dvec3& h, double alpha) {
  if (h.z <= 0) return 0.0;
  const double a2 = alpha * alpha, c2 = h.z * h.z;
  const double d = c2 * (a2 - 1.0) + 1.0;
  return a2 / (kPi * d * d);
}

double Bsdf::smithG1(const glm::dvec3& v, double alpha) {
  const double c = std::abs(v.z);
  if (c <= 0) return 0.0;
  const double a2 = alpha * alpha;
  return 2.0 * c / (c + std::sqrt(a2 + (1.0 - a2) * c * c));
}

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4).
glm::dvec3 Bsdf::sampleGgxVisibleNormal(const glm::dvec3& wo, double alpha, glm::dvec2 u) {
  const glm::dvec3 vh = glm::normalize(glm::dvec3(alpha * wo.x, alpha * wo.y, wo.z));
  const double lensq = vh.x * vh.x + vh.y * vh.y;
  const glm::dvec3 t1 = lensq > 0 ? glm::dvec3(-vh.y, vh.x, 0) / std::sqrt(lensq) : glm::dvec3(1, 0, 0);
  const glm::dvec3 t2 = glm::cross(vh, t1);
  const double r = std::sqrt(u.x);
  const SinCos phi = sinCosSingle(2.0 * kPi * u.y);
  const double p1 = r * phi.cos;
  double p2 = r * phi.sin;
  const double s = 0.5 * (1.0 + vh.z);
  p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
  const glm::dvec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::dvec3(alpha * nh.x, alpha * nh.y, std::max(1e-9, nh.z)));
}

Bsdf::Evaluation Bsdf::evaluateLocal(const View& v, const glm::dvec3& wi) const {
  const glm::dvec3& wo = v.local;
  if (wo.z <= 0 || wi.z <= 0) return {};
  const glm::dvec3 h = glm::normalize(wo + wi);
  const double d = ggxD(h, alpha_);
  Evaluation e;
  const double vh = std::max(0.0, glm::dot(wo, h));
  const double w = schlickWeight(vh);
  const glm::dvec3 fDielectric = dielectricF0_ + (dielectricF90_ - dielectricF0_) * w;
  const glm::dvec3 fMetal = m_.baseColor + (glm::dvec3(1.0) - m_.baseColor) * w;
  const double s = d * v.maskingWo * smithG1(wi, alpha_) / (4.0 * wo.z * wi.z);
  const glm::dvec3 diffuse = (1.0 - maxComponent(fDielectric)) * m_.baseColor / kPi;
  const glm::dvec3 dielectric = diffuse + fDielectric * s;
  const glm::dvec3 metal = fMetal * s;
  e.value = (1.0 - m_.metallic) * dielectric + m_.metallic * metal;
  // The pdf: cosine-weighted diffuse, plus the visible-normal density
  // D_v(h) = G1(wo) max(0, wo.h) D(h) / wo.z times the reflection Jacobian 1 / (4 wo.h).
  const double pSpecular = v.specularProbability;
  e.pdf = (1.0 - pSpecular) * wi.z / kPi;
  if (pSpecular > 0) e.pdf += pSpecular * v.maskingWo * d / (4.0 * wo.z);
  return e;
}

// How much of the reflection is specular, estimated with the Fresnel term at n.v.
double Bsdf::specularProbability(const glm::dvec3& wo) const {
  const double w = schlickWeight(wo.z);
  const glm::dvec3 fDielectric = dielectricF0_ + (dielectricF90_ - dielectricF0_) * w;
  const glm::dvec3 fMetal = m_.baseColor + (glm::dvec3(1.0) - m_.baseColor) * w;
  const double specular = luminance((1.0 - m_.metallic) * fDielectric + m_.metallic * fMetal);
  const double diffuse = (1.0 - m_.metallic) * (1.0 - maxComponent(fDielectric)) * luminance(m_.baseColor);
  if (specular + diffuse <= 0) return 0.5;
  if (specular <= 0) return 0.0;
  if (diffuse <= 0) return 1.0;
  return std::clamp(specular / (specular + diffuse), 0.05, 0.95);  // both lobes stay reachable
}

Bsdf::View Bsdf::view(const glm::dvec3& wo) const {
  View v;
  v.local = frame_.toLocal(wo);
  v.specularProbability = specularProbability(v.local);
  v.maskingWo = smithG1(v.local, alpha_);
  v.above = glm::dot(wo, ng_) > 0;
  return v;
}

glm::dvec3 Bsdf::eval(const glm::dvec3& wo, const glm::dvec3& wi) const { return evaluate(view(wo), wi).value; }
double Bsdf::pdf(const glm::dvec3& wo, const glm::dvec3& wi) const { return evaluate(view(wo), wi).pdf; }
std::optional<BsdfSample> Bsdf::sample(const glm::dvec3& wo, glm::dvec2 u, double uLobe) const {
  BsdfSample s;
  if (!sample(view(wo), u, uLobe, s)) return std::nullopt;
  return s;
}

Bsdf::Evaluation Bsdf::evaluate(const View& v, const glm::dvec3& wi) const {
  if (glm::dot(wi, ng_) <= 0 || !v.above) return {};
  return evaluateLocal(v, frame_.toLocal(wi));
}

bool Bsdf::sample(const View& v, glm::dvec2 u, double uLobe, BsdfSample& s) const {
  const glm::dvec3& o = v.local;
  if (o.z <= 0) return false;
  glm::dvec3 i;
  if (uLobe < v.specularProbability) {
    const glm::dvec3 h = sampleGgxVisibleNormal(o, alpha_, u);
    i = glm::reflect(-o, h);
  } else {
    i = sampleCosineHemisphere(u);
  }
  if (i.z <= 0) return false;
  s.direction = frame_.toWorld(i);
  if (glm::dot(s.direction, ng_) <= 0) return false;
  const Evaluation e = evaluateLocal(v, i);
  if (e.pdf <= 0) return false;
  s.pdf = e.pdf;
  s.value = e.value;
  return true;
}

}  // namespace dynbench::render
