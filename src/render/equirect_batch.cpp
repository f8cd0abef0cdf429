// EquirectBatch's kernels, compiled once per SIMD target by Highway's foreach_target (this file
// includes itself through HWY_TARGET_INCLUDE) and picked at run time by HWY_DYNAMIC_DISPATCH.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "render/equirect_batch.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>
#include <hwy/contrib/math/math-inl.h>

#include "core/simd.h"
#include "render/equirect_batch.h"

HWY_BEFORE_NAMESPACE();
namespace dynbench::render::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<double>;
using V = hn::Vec<D>;

constexpr double kPi = 3.14159265358979323846;

HWY_INLINE V load(D d, const double* data, std::size_t capacity, std::size_t field, std::size_t offset) {
  return hn::LoadU(d, data + field * capacity + offset);
}
HWY_INLINE void store(D d, double* data, std::size_t capacity, std::size_t field, std::size_t offset, V v) {
  hn::StoreU(v, d, data + field * capacity + offset);
}

// atan2(y, x) from Highway's Atan on [0, 1] (Highway 1.0 has no Atan2): the smaller magnitude
// over the larger, then the octant by the signs, as std::atan2 takes them, zeros' signs included
// (a pole's direction (0, +-1, -0) maps to u = 1 in both).
HWY_INLINE V atan2(D d, V y, V x) {
  const hn::RebindToSigned<D> bits;
  const V zero = hn::Zero(d), ax = hn::Abs(x), ay = hn::Abs(y);
  const V larger = hn::Max(ax, ay), smaller = hn::Min(ax, ay);
  const auto nonzero = hn::Gt(larger, zero);
  V a = hn::Atan(d, hn::IfThenElseZero(nonzero, hn::Div(smaller, hn::IfThenElse(nonzero, larger, hn::Set(d, 1.0)))));
  a = hn::IfThenElse(hn::Gt(ay, ax), hn::Sub(hn::Set(d, kPi / 2), a), a);
  const auto xNegative = hn::RebindMask(d, hn::Lt(hn::BitCast(bits, x), hn::Zero(bits)));  // the sign bit: -0 too
  a = hn::IfThenElse(xNegative, hn::Sub(hn::Set(d, kPi), a), a);
  return hn::CopySign(a, y);
}

// equirectDirection: phi = 2 pi (u - 0.5) from -Z towards +X, theta = pi v from +Y.
void RunEquirectDirections(double* data, std::size_t capacity, std::size_t count) {
  const D d;
  for (std::size_t offset = 0; offset < count; offset += hn::Lanes(d)) {
    const V phi = hn::Mul(hn::Set(d, 2.0 * kPi), hn::Sub(load(d, data, capacity, EquirectBatch::kU, offset), hn::Set(d, 0.5)));
    const V theta = hn::Mul(hn::Set(d, kPi), load(d, data, capacity, EquirectBatch::kV, offset));
    const V sinTheta = hn::Sin(d, theta);
    store(d, data, capacity, EquirectBatch::kX, offset, hn::Mul(sinTheta, hn::Sin(d, phi)));
    store(d, data, capacity, EquirectBatch::kY, offset, hn::Cos(d, theta));
    store(d, data, capacity, EquirectBatch::kZ, offset, hn::Neg(hn::Mul(sinTheta, hn::Cos(d, phi))));
    store(d, data, capacity, EquirectBatch::kSinTheta, offset, sinTheta);
  }
}

// equirectCoordinates: u = atan2(x, -z) / (2 pi) + 0.5, v = atan2(horizontal, y) / pi, and
// sin(theta) = horizontal / length from the direction itself.
void RunEquirectCoordinates(double* data, std::size_t capacity, std::size_t count) {
  const D d;
  for (std::size_t offset = 0; offset < count; offset += hn::Lanes(d)) {
    const V x = load(d, data, capacity, EquirectBatch::kX, offset), y = load(d, data, capacity, EquirectBatch::kY, offset),
            z = load(d, data, capacity, EquirectBatch::kZ, offset);
    const V phi = atan2(d, x, hn::Neg(z));
    const V horizontal = hn::Sqrt(hn::Add(hn::Mul(x, x), hn::Mul(z, z)));
    const V theta = atan2(d, horizontal, y);
    const V length = hn::Sqrt(hn::Add(hn::Mul(horizontal, horizontal), hn::Mul(y, y)));
    const auto positive = hn::Gt(length, hn::Zero(d));
    store(d, data, capacity, EquirectBatch::kSinTheta, offset,
          hn::IfThenElseZero(positive, hn::Div(horizontal, hn::IfThenElse(positive, length, hn::Set(d, 1.0)))));
    store(d, data, capacity, EquirectBatch::kU, offset, hn::Add(hn::Div(phi, hn::Set(d, 2.0 * kPi)), hn::Set(d, 0.5)));
    store(d, data, capacity, EquirectBatch::kV, offset, hn::Div(theta, hn::Set(d, kPi)));
  }
}

}  // namespace dynbench::render::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>

namespace dynbench::render {

HWY_EXPORT(RunEquirectDirections);
HWY_EXPORT(RunEquirectCoordinates);

void EquirectBatch::setPoint(std::size_t lane, glm::dvec2 uv) {
  at(kU, lane) = uv.x;
  at(kV, lane) = uv.y;
}

void EquirectBatch::directions(std::size_t count) {
  core::useMachineIndependentSimd();
  HWY_DYNAMIC_DISPATCH(RunEquirectDirections)(lanes_.data(), lanes_.capacity(), std::min(count, lanes_.capacity()));
}

glm::dvec3 EquirectBatch::direction(std::size_t lane, double* sinTheta) const {
  *sinTheta = at(kSinTheta, lane);
  return {at(kX, lane), at(kY, lane), at(kZ, lane)};
}

void EquirectBatch::setDirection(std::size_t lane, const glm::dvec3& direction) {
  at(kX, lane) = direction.x;
  at(kY, lane) = direction.y;
  at(kZ, lane) = direction.z;
}

void EquirectBatch::coordinates(std::size_t count) {
  core::useMachineIndependentSimd();
  HWY_DYNAMIC_DISPATCH(RunEquirectCoordinates)(lanes_.data(), lanes_.capacity(), std::min(count, lanes_.capacity()));
}

glm::dvec2 EquirectBatch::point(std::size_t lane, double* sinTheta) const {
  *sinTheta = at(kSinTheta, lane);
  return {at(kU, lane), at(kV, lane)};
}

}  // namespace dynbench::render
#endif
