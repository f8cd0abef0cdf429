// BsdfBatch's kernel, compiled once per SIMD target by Highway's foreach_target (this file
// includes itself through HWY_TARGET_INCLUDE) and picked at run time by HWY_DYNAMIC_DISPATCH.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/bsdf_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "core/simd.h"
#include "render/bsdf_batch.h"

HWY_BEFORE_NAMESPACE();
namespace dynbench::render::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;
using M = hn::Mask<D>;

struct Vec3 {
  V x, y, z;
};

HWY_INLINE V dot(const Vec3& a, const Vec3& b) { return hn::Add(hn::Add(hn::Mul(a.x, b.x), hn::Mul(a.y, b.y)), hn::Mul(a.z, b.z)); }
HWY_INLINE Vec3 scale(const Vec3& a, V s) { return {hn::Mul(a.x, s), hn::Mul(a.y, s), hn::Mul(a.z, s)}; }
HWY_INLINE Vec3 add(const Vec3& a, const Vec3& b) { return {hn::Add(a.x, b.x), hn::Add(a.y, b.y), hn::Add(a.z, b.z)}; }
// glm::normalize: v x (1 / sqrt(v.v)).
HWY_INLINE Vec3 normalize(D d, const Vec3& v) { return scale(v, hn::Div(hn::Set(d, 1.0), hn::Sqrt(dot(v, v)))); }
HWY_INLINE Vec3 select(M m, const Vec3& a, const Vec3& b) { return {hn::IfThenElse(m, a.x, b.x), hn::IfThenElse(m, a.y, b.y), hn::IfThenElse(m, a.z, b.z)}; }

// One vector of lanes of the batch's arrays (a Vec3 is three consecutive fields).
struct Lanes {
  double* data;
  std::size_t capacity, offset;
  HWY_INLINE V load(D d, std::size_t field) const { return hn::LoadU(d, data + field * capacity + offset); }
  HWY_INLINE Vec3 load3(D d, std::size_t first) const { return {load(d, first), load(d, first + 1), load(d, first + 2)}; }
  HWY_INLINE void store(D d, std::size_t field, V v) const { hn::StoreU(v, d, data + field * capacity + offset); }
  HWY_INLINE void store3(D d, std::size_t first, const Vec3& v) const {
    store(d, first, v.x);
    store(d, first + 1, v.y);
    store(d, first + 2, v.z);
  }
};

struct Material {
  Vec3 t, b, n, g, base, f0;
  V metallic, alpha, f90;
  Vec3 wo;
  V specularProbability, maskingWo;
};

struct Evaluation {
  Vec3 value;
  V pdf;
};

// Schlick's weight (1 - cosine)^5, the cosine clamped to [0, 1].
HWY_INLINE V schlickWeight(D d, V cosine) {
  const V c = hn::Min(hn::Max(hn::Sub(hn::Set(d, 1.0), cosine), hn::Zero(d)), hn::Set(d, 1.0));
  const V c2 = hn::Mul(c, c);
  return hn::Mul(hn::Mul(c2, c2), c);
}

HWY_INLINE Vec3 dielectricFresnel(const Material& m, V w) {
  return {hn::Add(m.f0.x, hn::Mul(hn::Sub(m.f90, m.f0.x), w)), hn::Add(m.f0.y, hn::Mul(hn::Sub(m.f90, m.f0.y), w)),
          hn::Add(m.f0.z, hn::Mul(hn::Sub(m.f90, m.f0.z), w))};
}

HWY_INLINE Vec3 metalFresnel(D d, const Material& m, V w) {
  const V one = hn::Set(d, 1.0);
  return {hn::Add(m.base.x, hn::Mul(hn::Sub(one, m.base.x), w)), hn::Add(m.base.y, hn::Mul(hn::Sub(one, m.base.y), w)),
          hn::Add(m.base.z, hn::Mul(hn::Sub(one, m.base.z), w))};
}

HWY_INLINE V luminance(D d, const Vec3& rgb) {  // core/math.h's Rec. 709 weights
  return hn::Add(hn::Add(hn::Mul(hn::Set(d, 0.2126), rgb.x), hn::Mul(hn::Set(d, 0.7152), rgb.y)), hn::Mul(hn::Set(d, 0.0722), rgb.z));
}

// Bsdf::specularProbability: the specular share of the reflection by the Fresnel term at n.wo,
// clamped to [0.05, 0.95] where both lobes reflect.
HWY_INLINE V specularProbability(D d, const Material& m) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  const V w = schlickWeight(d, m.wo.z);
  const Vec3 fDielectric = dielectricFresnel(m, w), fMetal = metalFresnel(d, m, w);
  const V dielectricWeight = hn::Sub(one, m.metallic);
  const V specular = luminance(d, {hn::Add(hn::Mul(dielectricWeight, fDielectric.x), hn::Mul(m.metallic, fMetal.x)),
                                   hn::Add(hn::Mul(dielectricWeight, fDielectric.y), hn::Mul(m.metallic, fMetal.y)),
                                   hn::Add(hn::Mul(dielectricWeight, fDielectric.z), hn::Mul(m.metallic, fMetal.z))});
  const V diffuse = hn::Mul(hn::Mul(dielectricWeight, hn::Sub(one, hn::Max(fDielectric.x, hn::Max(fDielectric.y, fDielectric.z)))),
                            luminance(d, m.base));
  const V sum = hn::Add(specular, diffuse);
  V p = hn::Min(hn::Max(hn::Div(specular, sum), hn::Set(d, 0.05)), hn::Set(d, 0.95));
  p = hn::IfThenElse(hn::Le(diffuse, zero), one, p);
  p = hn::IfThenElse(hn::Le(specular, zero), zero, p);
  return hn::IfThenElse(hn::Le(sum, zero), hn::Set(d, 0.5), p);
}

// Smith G1 = 2 c / (c + sqrt(a2 + (1 - a2) c^2)) of a direction with cosine c > 0 (a2 = alpha^2).
HWY_INLINE V smithG1(D d, V c, V a2) {
  const V one = hn::Set(d, 1.0);
  return hn::Div(hn::Mul(hn::Set(d, 2.0), c), hn::Add(c, hn::Sqrt(hn::Add(a2, hn::Mul(hn::Sub(one, a2), hn::Mul(c, c))))));
}

// Bsdf::evaluateLocal (bsdf.cpp has the equations), for lanes where wo.z > 0 and wi.z > 0 (the
// caller masks the others).
HWY_INLINE Evaluation evaluateLocal(D d, const Material& m, const Vec3& wi) {
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0), pi = hn::Set(d, 3.14159265358979323846);
  const Vec3 h = normalize(d, add(m.wo, wi));
  // GGX D(h) = a2 / (pi (h.z^2 (a2 - 1) + 1)^2), 0 where h.z <= 0.
  const V a2 = hn::Mul(m.alpha, m.alpha);
  const V denominator = hn::Add(hn::Mul(hn::Mul(h.z, h.z), hn::Sub(a2, one)), one);
  const V ggx = hn::IfThenElseZero(hn::Gt(h.z, zero), hn::Div(a2, hn::Mul(pi, hn::Mul(denominator, denominator))));
  const V w = schlickWeight(d, hn::Max(zero, dot(m.wo, h)));
  const Vec3 fDielectric = dielectricFresnel(m, w), fMetal = metalFresnel(d, m, w);
  const V s = hn::Div(hn::Mul(hn::Mul(ggx, m.maskingWo), smithG1(d, wi.z, a2)), hn::Mul(hn::Mul(hn::Set(d, 4.0), m.wo.z), wi.z));
  const V diffuseScale = hn::Div(hn::Sub(one, hn::Max(fDielectric.x, hn::Max(fDielectric.y, fDielectric.z))), pi);
  const V dielectricWeight = hn::Sub(one, m.metallic);
  auto channel = [&](V base, V fd, V fm) {
    const V dielectric = hn::Add(hn::Mul(diffuseScale, base), hn::Mul(fd, s));
    return hn::Add(hn::Mul(dielectricWeight, dielectric), hn::Mul(m.metallic, hn::Mul(fm, s)));
  };
  Evaluation e;
  e.value = {channel(m.base.x, fDielectric.x, fMetal.x), channel(m.base.y, fDielectric.y, fMetal.y),
             channel(m.base.z, fDielectric.z, fMetal.z)};
  // Cosine-weighted diffuse plus the visible-normal density's reflection, G1(wo) D / (4 wo.z).
  const V specular = hn::Div(hn::Mul(hn::Mul(m.specularProbability, m.maskingWo), ggx), hn::Mul(hn::Set(d, 4.0), m.wo.z));
  e.pdf = hn::Add(hn::Div(hn::Mul(hn::Sub(one, m.specularProbability), wi.z), pi),
                  hn::IfThenElseZero(hn::Gt(m.specularProbability, zero), specular));
  return e;
}

void RunBsdfBatch(double* data, std::size_t capacity, std::size_t count) {
  const D d;
  const std::size_t n = hn::Lanes(d);
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0);
  for (std::size_t offset = 0; offset < count; offset += n) {
    const Lanes in{data, capacity, offset};
    // The Bsdf constructor: the shading frame (Duff et al. 2017, Frame in sampling.h), alpha and
    // the dielectric Fresnel terms.
    Material m;
    m.n = in.load3(d, BsdfBatch::kNx);
    const V sign = hn::CopySign(one, m.n.z);
    const V a = hn::Div(hn::Set(d, -1.0), hn::Add(sign, m.n.z));
    const V c = hn::Mul(hn::Mul(m.n.x, m.n.y), a);
    m.t = {hn::Add(one, hn::Mul(hn::Mul(hn::Mul(sign, m.n.x), m.n.x), a)), hn::Mul(sign, c), hn::Neg(hn::Mul(sign, m.n.x))};
    m.b = {c, hn::Add(sign, hn::Mul(hn::Mul(m.n.y, m.n.y), a)), hn::Neg(m.n.y)};
    m.g = in.load3(d, BsdfBatch::kGx);
    m.base = in.load3(d, BsdfBatch::kBaseR);
    m.metallic = in.load(d, BsdfBatch::kMetallic);
    const V roughness = hn::Min(hn::Max(in.load(d, BsdfBatch::kRoughness), zero), one);
    m.alpha = hn::Max(hn::Mul(roughness, roughness), hn::Set(d, 2e-3));
    m.f90 = in.load(d, BsdfBatch::kSpecular);
    const V f0Scale = hn::Set(d, 0.04);
    const Vec3 specularColor = in.load3(d, BsdfBatch::kSpecularR);
    m.f0 = {hn::Mul(hn::Min(hn::Mul(f0Scale, specularColor.x), one), m.f90), hn::Mul(hn::Min(hn::Mul(f0Scale, specularColor.y), one), m.f90),
            hn::Mul(hn::Min(hn::Mul(f0Scale, specularColor.z), one), m.f90)};
    auto toLocal = [&](const Vec3& v) { return Vec3{dot(v, m.t), dot(v, m.b), dot(v, m.n)}; };
    // Bsdf::view: wo in the shading frame, the lobe choice and Smith G1(wo) (0 at |wo.z| = 0).
    const Vec3 woWorld = in.load3(d, BsdfBatch::kWoX);
    m.wo = toLocal(woWorld);
    m.specularProbability = specularProbability(d, m);
    const V cosWo = hn::Abs(m.wo.z);
    m.maskingWo = hn::IfThenElseZero(hn::Gt(cosWo, zero), smithG1(d, cosWo, hn::Mul(m.alpha, m.alpha)));
    const M above = hn::Gt(dot(woWorld, m.g), zero);
    const M woAbove = hn::Gt(m.wo.z, zero);

    // Bsdf::evaluate: none below the geometric surface on either side.
    const Vec3 wiWorld = in.load3(d, BsdfBatch::kWiX);
    const Vec3 wi = toLocal(wiWorld);
    const M evaluated = hn::And(hn::And(hn::Gt(in.load(d, BsdfBatch::kEvaluate), zero), above),
                                hn::And(hn::And(hn::Gt(dot(wiWorld, m.g), zero), woAbove), hn::Gt(wi.z, zero)));
    const Evaluation light = evaluateLocal(d, m, wi);
    in.store3(d, BsdfBatch::kValueR,
              {hn::IfThenElseZero(evaluated, light.value.x), hn::IfThenElseZero(evaluated, light.value.y), hn::IfThenElseZero(evaluated, light.value.z)});
    in.store(d, BsdfBatch::kPdf, hn::IfThenElseZero(evaluated, light.pdf));

    // Bsdf::sample. Both lobes' directions come from r = sqrt(u1) and the angle 2 pi u2.
    const V u1 = in.load(d, BsdfBatch::kU1);
    // The angle rounded to single precision, as Bsdf's sinCosSingle does (core/math.h), so both
    // sample the same directions to about 1e-7.
    const hn::Rebind<float, D> f;
    const V angle = hn::PromoteTo(d, hn::DemoteTo(f, hn::Mul(hn::Set(d, 2.0 * 3.14159265358979323846), in.load(d, BsdfBatch::kU2))));
    const V r = hn::Sqrt(u1);
    const V p1 = hn::Mul(r, hn::Cos(d, angle));
    const V sinPart = hn::Mul(r, hn::Sin(d, angle));
    // The diffuse lobe: Malley's method (sampleCosineHemisphere).
    const Vec3 diffuse{p1, sinPart, hn::Sqrt(hn::Max(zero, hn::Sub(one, u1)))};
    // The specular lobe: a visible normal (Heitz 2018, Bsdf::sampleGgxVisibleNormal), reflected.
    const Vec3 vh = normalize(d, Vec3{hn::Mul(m.alpha, m.wo.x), hn::Mul(m.alpha, m.wo.y), m.wo.z});
    const V lensq = hn::Add(hn::Mul(vh.x, vh.x), hn::Mul(vh.y, vh.y));
    const M tilted = hn::Gt(lensq, zero);
    const V inverseLength = hn::Div(one, hn::Sqrt(lensq));
    const Vec3 t1{hn::IfThenElse(tilted, hn::Mul(hn::Neg(vh.y), inverseLength), one), hn::IfThenElseZero(tilted, hn::Mul(vh.x, inverseLength)),
                  zero};
    const Vec3 t2{hn::Neg(hn::Mul(vh.z, t1.y)), hn::Mul(vh.z, t1.x), hn::Sub(hn::Mul(vh.x, t1.y), hn::Mul(vh.y, t1.x))};
    const V blend = hn::Mul(hn::Set(d, 0.5), hn::Add(one, vh.z));
    const V p2 = hn::Add(hn::Mul(hn::Sub(one, blend), hn::Sqrt(hn::Max(zero, hn::Sub(one, hn::Mul(p1, p1))))), hn::Mul(blend, sinPart));
    const V p3 = hn::Sqrt(hn::Max(zero, hn::Sub(hn::Sub(one, hn::Mul(p1, p1)), hn::Mul(p2, p2))));
    const Vec3 nh = add(add(scale(t1, p1), scale(t2, p2)), scale(vh, p3));
    const Vec3 h = normalize(d, Vec3{hn::Mul(m.alpha, nh.x), hn::Mul(m.alpha, nh.y), hn::Max(hn::Set(d, 1e-9), nh.z)});
    const V twoCos = hn::Mul(hn::Set(d, 2.0), dot(m.wo, h));
    const Vec3 mirror{hn::Sub(hn::Mul(twoCos, h.x), m.wo.x), hn::Sub(hn::Mul(twoCos, h.y), m.wo.y), hn::Sub(hn::Mul(twoCos, h.z), m.wo.z)};
    const Vec3 i = select(hn::Lt(in.load(d, BsdfBatch::kULobe), m.specularProbability), mirror, diffuse);
    const Vec3 direction = add(add(scale(m.t, i.x), scale(m.b, i.y)), scale(m.n, i.z));
    const Evaluation e = evaluateLocal(d, m, i);
    const M sampled = hn::And(hn::And(woAbove, hn::Gt(i.z, zero)), hn::And(hn::Gt(dot(direction, m.g), zero), hn::Gt(e.pdf, zero)));
    in.store3(d, BsdfBatch::kDirX, direction);
    in.store3(d, BsdfBatch::kSampleR, e.value);
    in.store(d, BsdfBatch::kSamplePdf, hn::IfThenElseZero(sampled, e.pdf));
  }
}

}  // namespace dynbench::render::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>

namespace dynbench::render {

HWY_EXPORT(RunBsdfBatch);

void BsdfBatch::set(std::size_t lane, const SurfaceMaterial& material, const glm::dvec3& shadingNormal, const glm::dvec3& geometricNormal,
                    const glm::dvec3& wo) {
  const glm::dvec3* vectors[] = {&shadingNormal, &geometricNormal, &material.baseColor};
  for (std::size_t v = 0; v < 3; ++v)
    for (int c = 0; c < 3; ++c) at(static_cast<Field>(kNx + 3 * v + static_cast<std::size_t>(c)), lane) = (*vectors[v])[c];
  at(kMetallic, lane) = material.metallic;
  at(kRoughness, lane) = material.roughness;
  at(kSpecular, lane) = material.specular;
  for (int c = 0; c < 3; ++c) {
    at(static_cast<Field>(kSpecularR + static_cast<std::size_t>(c)), lane) = material.specularColor[c];
    at(static_cast<Field>(kWoX + static_cast<std::size_t>(c)), lane) = wo[c];
  }
}

void BsdfBatch::setEvaluation(std::size_t lane, const glm::dvec3& wi) {
  at(kWiX, lane) = wi.x;
  at(kWiY, lane) = wi.y;
  at(kWiZ, lane) = wi.z;
  at(kEvaluate, lane) = 1.0;
}

void BsdfBatch::clearEvaluation(std::size_t lane) { at(kEvaluate, lane) = 0.0; }

void BsdfBatch::setSample(std::size_t lane, glm::dvec2 u, double uLobe) {
  at(kU1, lane) = u.x;
  at(kU2, lane) = u.y;
  at(kULobe, lane) = uLobe;
}

Bsdf::Evaluation BsdfBatch::evaluation(std::size_t lane) const {
  return {{at(kValueR, lane), at(kValueG, lane), at(kValueB, lane)}, at(kPdf, lane)};
}

bool BsdfBatch::sample(std::size_t lane, BsdfSample& out) const {
  out.pdf = at(kSamplePdf, lane);
  if (!(out.pdf > 0)) return false;
  out.direction = {at(kDirX, lane), at(kDirY, lane), at(kDirZ, lane)};
  out.value = {at(kSampleR, lane), at(kSampleG, lane), at(kSampleB, lane)};
  return true;
}

void BsdfBatch::run(std::size_t count) {
  core::useMachineIndependentSimd();
  HWY_DYNAMIC_DISPATCH(RunBsdfBatch)(lanes_.data(), capacity(), std::min(count, capacity()));
}

}  // namespace dynbench::render
#endif
