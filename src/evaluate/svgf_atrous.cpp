// The à-trous iteration's kernel, compiled once per SIMD target by Highway's foreach_target (this
// file includes itself through HWY_TARGET_INCLUDE) and picked at run time by HWY_DYNAMIC_DISPATCH.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "evaluate/svgf_atrous.cpp"
#include <hwy/foreach_target.h>  // before highway.h

#include <hwy/highway.h>

#include <algorithm>

#include "core/simd.h"
#include "evaluate/svgf_atrous.h"

#ifndef DYNBENCH_SVGF_ATROUS_ARGS
#define DYNBENCH_SVGF_ATROUS_ARGS
namespace dynbench::evaluate::svgf {
// What the kernel reads and writes: the padded planes (AtrousPlanes' layout) and the luminance of
// the illumination, read and written.
struct AtrousArgs {
  const float *depth, *nx, *ny, *nz, *hit, *gradX, *gradY, *r, *g, *b, *variance, *luminance;
  float *outR, *outG, *outB, *outVariance, *outLuminance;
  int width, height, stride, step;
  float sigmaZ, sigmaL;
  const Remodulation* remodulation;  // when set, the output instead of out*
};
struct MomentsArgs {
  const float *depth, *nx, *ny, *nz, *hit, *gradX, *gradY, *luminance, *moment1, *temporalVariance, *historyLength;
  float* variance;
  int width, stride;
  float sigmaZ, sigmaL;
};
}  // namespace dynbench::evaluate::svgf
#endif

HWY_BEFORE_NAMESPACE();
namespace dynbench::evaluate::svgf::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using D = hn::ScalableTag<float>;
using V = hn::Vec<D>;

// The planes both kernels weigh taps by (AtrousArgs' and MomentsArgs' first members).
struct Geometry {
  const float *depth, *nx, *ny, *nz, *gradX, *gradY, *luminance;
};
// A vector of centre pixels' geometry.
struct Centre {
  V z, luminance, nx, ny, nz, gx, gy;
};
HWY_INLINE Centre LoadCentre(D d, const Geometry& g, std::size_t c) {
  return {hn::LoadU(d, g.depth + c), hn::LoadU(d, g.luminance + c), hn::LoadU(d, g.nx + c), hn::LoadU(d, g.ny + c),
          hn::LoadU(d, g.nz + c),    hn::LoadU(d, g.gradX + c),     hn::LoadU(d, g.gradY + c)};
}
// exp(-x) for x in [0, 80] (the edge-stopping exponent's range, below): 2^-k e^-y with k = round(x
// log2 e) and y = x - k ln 2 in [-0.35, 0.35], e^-y by its Taylor polynomial to degree 6 (error
// 0.35^7 / 7! = 1.2e-7 relative), 2^-k in the exponent bits: within 4.3e-7 relative of exp on
// every float in [0, 80] (checked by hand against std::exp in double). Highway's Exp serves every
// float and was a quarter of the filter's time; this range needs no overflow or underflow handling.
HWY_INLINE V NegExpShortRange(D d, V x) {
  const hn::RebindToSigned<D> di;
  const V k = hn::Round(hn::Mul(x, hn::Set(d, 1.44269504f)));
  const V y = hn::NegMulAdd(k, hn::Set(d, 0.693147181f), x);
  V p = hn::Set(d, 1.0f / 720.0f);
  p = hn::MulAdd(p, y, hn::Set(d, -1.0f / 120.0f));
  p = hn::MulAdd(p, y, hn::Set(d, 1.0f / 24.0f));
  p = hn::MulAdd(p, y, hn::Set(d, -1.0f / 6.0f));
  p = hn::MulAdd(p, y, hn::Set(d, 0.5f));
  p = hn::MulAdd(p, y, hn::Set(d, -1.0f));
  p = hn::MulAdd(p, y, hn::Set(d, 1.0f));
  const auto exponent = hn::ShiftLeft<23>(hn::Sub(hn::Set(di, 127), hn::ConvertTo(di, k)));  // 2^-k, k <= 116
  return hn::Mul(p, hn::BitCast(d, exponent));
}

// The edge-stopping weight of the tap at index j ([S17] Eqs. 3-5):
// exp(-|dz| x inverseDepthScale - |dl| x inverseLuminanceScale) x max(0, n . n')^128, one
// exponential for the depth and luminance terms as Falcor computes them. A tap that hit nothing
// has the normal 0 (AtrousPlanes), so its weight is 0 without a test. exp(-x) above x = 80 (below
// 2e-35) is taken as 0: single precision's exponential ends at 88.
HWY_INLINE V EdgeStoppingWeight(D d, const Geometry& g, const Centre& c, std::size_t j, V inverseDepthScale, V inverseLuminanceScale) {
  const V zero = hn::Zero(d);
  const V dl = hn::Mul(hn::Abs(hn::Sub(c.luminance, hn::LoadU(d, g.luminance + j))), inverseLuminanceScale);
  const V exponent = hn::MulAdd(hn::Abs(hn::Sub(c.z, hn::LoadU(d, g.depth + j))), inverseDepthScale, dl);
  V wn = hn::MulAdd(c.nx, hn::LoadU(d, g.nx + j), hn::MulAdd(c.ny, hn::LoadU(d, g.ny + j), hn::Mul(c.nz, hn::LoadU(d, g.nz + j))));
  wn = hn::Max(wn, zero);
  for (int k = 0; k < 7; ++k) wn = hn::Mul(wn, wn);  // ^128
  const V e = NegExpShortRange(d, hn::Min(exponent, hn::Set(d, 80.0f)));
  return hn::Mul(e, wn);
}
// 1 / (sigma_z |grad z . o| + 1e-8) for the offset o = (ox, oy) ([S17] Eq. 3's depth scale); the
// same for o and -o, so the 5x5 and 7x7 loops compute it once per pair of taps.
HWY_INLINE V InverseDepthScale(D d, const Centre& c, float ox, float oy, V sigmaZ) {
  const V scale = hn::MulAdd(sigmaZ, hn::Abs(hn::MulAdd(c.gx, hn::Set(d, ox), hn::Mul(c.gy, hn::Set(d, oy)))), hn::Set(d, 1e-8f));
  return hn::Div(hn::Set(d, 1.0f), scale);
}

// The 3x3 Gaussian (1, 2, 1)^2 / 16 of the variance around c ([S17] Eq. 5's g(Var)): rows then
// columns as a separable filter sums them. `above` and `below` are the rows' offsets, 0 at the
// image's top and bottom edge (clamped coordinates); the padding's columns next to the image hold
// the edge's values (atrousIteration), so the columns clamp too.
HWY_INLINE V BlurredVariance(D d, const float* variance, std::size_t c, std::ptrdiff_t above, std::ptrdiff_t below) {
  const V quarter = hn::Set(d, 0.25f), half = hn::Set(d, 0.5f);
  auto row = [&](std::size_t centre) {
    return hn::Add(hn::Add(hn::Mul(quarter, hn::LoadU(d, variance + centre - 1)), hn::Mul(half, hn::LoadU(d, variance + centre))),
                   hn::Mul(quarter, hn::LoadU(d, variance + centre + 1)));
  };
  return hn::Add(hn::Add(hn::Mul(quarter, row(c - above)), hn::Mul(half, row(c))), hn::Mul(quarter, row(c + below)));
}

// Rec. 709 luminance.
HWY_INLINE V Luminance(D d, V r, V g, V b) {
  return hn::Add(hn::Add(hn::Mul(hn::Set(d, 0.2126f), r), hn::Mul(hn::Set(d, 0.7152f), g)), hn::Mul(hn::Set(d, 0.0722f), b));
}

// The lanes' colours remodulated (Remodulation) into pixels i, i + 1, ... of `m.rgb`, `valid` of them
// (the row's last vector may reach past its end: those lanes go through a buffer).
template <class M>
HWY_INLINE void Remodulate(D d, const Remodulation& m, M surface, V r, V g, V b, std::size_t i, std::size_t valid) {
  constexpr std::size_t kMaxLanes = HWY_MAX_BYTES / sizeof(float);
  V baseR, baseG, baseB;
  HWY_ALIGN float buffer[3 * kMaxLanes] = {};
  const bool whole = valid == hn::Lanes(d);
  if (whole) {
    hn::LoadInterleaved3(d, m.baseColour + 3 * i, baseR, baseG, baseB);
  } else {
    std::copy_n(m.baseColour + 3 * i, 3 * valid, buffer);
    hn::LoadInterleaved3(d, buffer, baseR, baseG, baseB);
  }
  const V diffuse = hn::Set(d, m.diffuseShare), specular = hn::Set(d, m.specularShare), floor = hn::Set(d, m.floor), one = hn::Set(d, 1.0f);
  auto factor = [&](V base) { return hn::IfThenElse(surface, hn::Max(hn::Add(hn::Mul(diffuse, base), specular), floor), one); };
  r = hn::Mul(r, factor(baseR)), g = hn::Mul(g, factor(baseG)), b = hn::Mul(b, factor(baseB));
  if (whole) {
    hn::StoreInterleaved3(r, g, b, d, m.rgb + 3 * i);
  } else {
    hn::StoreInterleaved3(r, g, b, d, buffer);
    std::copy_n(buffer, 3 * valid, m.rgb + 3 * i);
  }
}

// Rows [y0, y1): for each pixel the 5x5 taps `step` apart, weighted by the B3 spline times the
// edge-stopping weight, the luminance's scale sigma_l sqrt(g(Var)) + 1e-10; the centre tap by the
// spline alone; the variance by the squared weights ([S17] Eq. 2). Also the output's luminance,
// the next iteration's edge-stopping input (a pass of its own read three planes more).
void AtrousRows(const AtrousArgs* a, int y0, int y1) {
  const D d;
  const std::size_t lanes = hn::Lanes(d);
  static constexpr float kSpline[3] = {3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};  // [S17] §4.3: B3 spline
  const V zero = hn::Zero(d), lumEpsilon = hn::Set(d, 1e-10f);
  const V sigmaZ = hn::Set(d, a->sigmaZ), sigmaL = hn::Set(d, a->sigmaL);
  const Geometry g{a->depth, a->nx, a->ny, a->nz, a->gradX, a->gradY, a->luminance};
  const int pad = AtrousPlanes::kPad;
  for (int y = y0; y < y1; ++y) {
    const std::ptrdiff_t above = y > 0 ? a->stride : 0, below = y + 1 < a->height ? a->stride : 0;
    // Lanes beyond the row's last pixel read and write the padding (at least kPad wide, more than
    // a vector): their centre is not a hit, so they copy their input.
    for (int x = 0; x < a->width; x += static_cast<int>(lanes)) {
      const std::size_t c = static_cast<std::size_t>(y + pad) * static_cast<std::size_t>(a->stride) + static_cast<std::size_t>(x + pad);
      const V hitC = hn::LoadU(d, a->hit + c);
      const Centre centre = LoadCentre(d, g, c);
      const V inverseLum = hn::Div(hn::Set(d, 1.0f), hn::MulAdd(sigmaL, hn::Sqrt(hn::Max(zero, BlurredVariance(d, a->variance, c, above, below))), lumEpsilon));
      // The centre tap weighs the spline alone; the others come in pairs o, -o sharing a depth scale.
      const V centreSpline = hn::Set(d, kSpline[0] * kSpline[0]);
      V sumR = hn::Mul(centreSpline, hn::LoadU(d, a->r + c)), sumG = hn::Mul(centreSpline, hn::LoadU(d, a->g + c));
      V sumB = hn::Mul(centreSpline, hn::LoadU(d, a->b + c)), sumW = centreSpline;
      V sumV = hn::Mul(hn::Mul(centreSpline, centreSpline), hn::LoadU(d, a->variance + c));
      for (int ky = 0; ky <= 2; ++ky)
        for (int kx = ky == 0 ? 1 : -2; kx <= 2; ++kx) {
          const V spline = hn::Set(d, kSpline[kx < 0 ? -kx : kx] * kSpline[ky]);
          const V inverseDepth = InverseDepthScale(d, centre, static_cast<float>(kx * a->step), static_cast<float>(ky * a->step), sigmaZ);
          const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(ky * a->step) * a->stride + kx * a->step;
          for (const std::ptrdiff_t o : {offset, -offset}) {
            const std::size_t j = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(c) + o);
            const V w = hn::Mul(spline, EdgeStoppingWeight(d, g, centre, j, inverseDepth, inverseLum));
            sumR = hn::MulAdd(w, hn::LoadU(d, a->r + j), sumR);
            sumG = hn::MulAdd(w, hn::LoadU(d, a->g + j), sumG);
            sumB = hn::MulAdd(w, hn::LoadU(d, a->b + j), sumB);
            sumW = hn::Add(sumW, w);
            sumV = hn::MulAdd(hn::Mul(w, w), hn::LoadU(d, a->variance + j), sumV);
          }
        }
      const auto surface = hn::Gt(hitC, zero);
      // Where the centre is not a hit the sums may be 0: divide by 1 there, the result is not used.
      const V safeW = hn::IfThenElse(surface, sumW, hn::Set(d, 1.0f));
      const V inverse = hn::Div(hn::Set(d, 1.0f), safeW);
      const V outR = hn::IfThenElse(surface, hn::Mul(sumR, inverse), hn::LoadU(d, a->r + c));
      const V outG = hn::IfThenElse(surface, hn::Mul(sumG, inverse), hn::LoadU(d, a->g + c));
      const V outB = hn::IfThenElse(surface, hn::Mul(sumB, inverse), hn::LoadU(d, a->b + c));
      if (a->remodulation) {
        Remodulate(d, *a->remodulation, surface, outR, outG, outB, static_cast<std::size_t>(y) * static_cast<std::size_t>(a->width) + x,
                   std::min(lanes, static_cast<std::size_t>(a->width - x)));
        continue;
      }
      hn::StoreU(outR, d, a->outR + c), hn::StoreU(outG, d, a->outG + c), hn::StoreU(outB, d, a->outB + c);
      hn::StoreU(Luminance(d, outR, outG, outB), d, a->outLuminance + c);
      hn::StoreU(hn::IfThenElse(surface, hn::Mul(sumV, hn::Mul(inverse, inverse)), hn::LoadU(d, a->variance + c)), d, a->outVariance + c);
    }
  }
}

// Rows [y0, y1) of the variance estimate (estimateVariance). A vector of lanes whose histories are
// all 4 frames or longer skips the 49 taps.
void MomentsRows(const MomentsArgs* a, int y0, int y1) {
  const D d;
  const std::size_t lanes = hn::Lanes(d);
  constexpr int kRadius = 3;  // [S17] §4.2: 7x7
  const V zero = hn::Zero(d), one = hn::Set(d, 1.0f), four = hn::Set(d, 4.0f);
  const V sigmaZ = hn::Set(d, a->sigmaZ), inverseSigmaL = hn::Set(d, 1.0f / a->sigmaL);
  const Geometry g{a->depth, a->nx, a->ny, a->nz, a->gradX, a->gradY, a->luminance};
  const int pad = AtrousPlanes::kPad;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < a->width; x += static_cast<int>(lanes)) {
      const std::size_t c = static_cast<std::size_t>(y + pad) * static_cast<std::size_t>(a->stride) + static_cast<std::size_t>(x + pad);
      const auto surface = hn::Gt(hn::LoadU(d, a->hit + c), zero);
      const V length = hn::LoadU(d, a->historyLength + c);
      const V m1c = hn::LoadU(d, a->moment1 + c), vc = hn::LoadU(d, a->temporalVariance + c);
      V variance = hn::Max(zero, vc);
      const auto spatial = hn::And(surface, hn::Lt(length, four));
      if (!hn::AllFalse(d, spatial)) {
        const Centre centre = LoadCentre(d, g, c);
        // The weighted m2 - m1^2 of the neighbourhood as E[v] + Var(m1), v = m2 - m1^2 per pixel
        // (computed in double), Var(m1) of m1 - m1(centre): the same number without single
        // precision's cancellation of two large second moments.
        V sumV = vc, sumD = zero, sumD2 = zero, sumW = one;  // the centre weighs 1
        // Taps in pairs o, -o sharing a depth scale, as in AtrousRows.
        for (int dy = 0; dy <= kRadius; ++dy)
          for (int dx = dy == 0 ? 1 : -kRadius; dx <= kRadius; ++dx) {
            const V inverseDepth = InverseDepthScale(d, centre, static_cast<float>(dx), static_cast<float>(dy), sigmaZ);
            const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(dy) * a->stride + dx;
            for (const std::ptrdiff_t o : {offset, -offset}) {
              const std::size_t j = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(c) + o);
              const V w = EdgeStoppingWeight(d, g, centre, j, inverseDepth, inverseSigmaL);
              const V deviation = hn::Sub(hn::LoadU(d, a->moment1 + j), m1c);
              sumV = hn::MulAdd(w, hn::LoadU(d, a->temporalVariance + j), sumV);
              sumD = hn::MulAdd(w, deviation, sumD);
              sumD2 = hn::MulAdd(w, hn::Mul(deviation, deviation), sumD2);
              sumW = hn::Add(sumW, w);
            }
          }
        const V inverse = hn::Div(one, sumW);
        const V meanD = hn::Mul(sumD, inverse);
        const V spread = hn::Add(hn::Mul(sumV, inverse), hn::NegMulAdd(meanD, meanD, hn::Mul(sumD2, inverse)));
        const V boosted = hn::Div(hn::Mul(hn::Max(zero, spread), four), hn::Max(length, one));
        variance = hn::IfThenElse(spatial, boosted, variance);
      }
      hn::StoreU(hn::IfThenElseZero(surface, variance), d, a->variance + c);
    }
}

}  // namespace dynbench::evaluate::svgf::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
#include <algorithm>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace dynbench::evaluate::svgf {

HWY_EXPORT(AtrousRows);
HWY_EXPORT(MomentsRows);

// Denormal floats flushed to 0 (and read as 0) in this thread while in scope. The filters' weights
// reach 1e-35 (exp(-80)) and their squares, the variance's weights, underflow: x86 computes with a
// denormal in about a hundred cycles, which made the iterations of wide steps, whose taps differ
// most, up to half as slow again as the first (issue 34). What is lost is below 1.2e-38 of sums
// near 1.
class FlushDenormals {
 public:
#if defined(__SSE__)
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040); }  // FTZ (bit 15), DAZ (bit 6)
  ~FlushDenormals() { _mm_setcsr(saved_); }
#else
  FlushDenormals() = default;
#endif
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;

 private:
  [[maybe_unused]] unsigned saved_ = 0;
};

void AtrousPlanes::resize(int w, int h) {
  // Only a new size allocates (and zeroes the padding): every pass writes the interior alone, or
  // the padding's own value (AtrousRows), so the padding stays 0. Zeroing 17 planes every frame was
  // 7 ms of a 1080p frame.
  if (w == width && h == height && depth.size() > 0) return;
  width = w, height = h, stride = w + 2 * kPad;
  // (+ kPad: the last row's lanes past its end, a vector at most, read taps up to 2 x 16 further.)
  const std::size_t n = static_cast<std::size_t>(stride) * static_cast<std::size_t>(h + 2 * kPad) + kPad;
  for (auto* plane : {&depth, &nx, &ny, &nz, &hit, &gradX, &gradY, &r, &g, &b, &variance, &moment1, &temporalVariance, &historyLength, &luminance,
                      &id, &historyR, &historyG, &historyB})
    plane->assign(n, 0.0f);
}

void atrousIteration(AtrousPlanes& p, int step, const AtrousWeights& weights, AtrousPlanes& out, const Remodulation* remodulation) {
  if (out.width != p.width || out.height != p.height) {
    // Only the planes an iteration writes: the rest would be 12 idle planes.
    out.width = p.width, out.height = p.height, out.stride = p.stride;
    for (auto* plane : {&out.r, &out.g, &out.b, &out.variance, &out.luminance}) plane->assign(p.r.size(), 0.0f);
  }
  const int w = p.width, h = p.height;
  // The variance's prefilter reads clamped coordinates: the padding's columns next to the image
  // repeat its edge (the kernel's taps there weigh 0, whatever they hold).
  float* variance = p.variance.data();
  for (int y = 0; y < h; ++y) variance[p.at(-1, y)] = variance[p.at(0, y)], variance[p.at(w, y)] = variance[p.at(w - 1, y)];
  const AtrousArgs args{p.depth.data(), p.nx.data(),   p.ny.data(),       p.nz.data(),         p.hit.data(),       p.gradX.data(),
                        p.gradY.data(), p.r.data(),    p.g.data(),        p.b.data(),          p.variance.data(),  p.luminance.data(),
                        out.r.data(),   out.g.data(),  out.b.data(),      out.variance.data(), out.luminance.data(), w,
                        h,              p.stride,      step,              weights.sigmaZ,      weights.sigmaL,      remodulation};
  core::useMachineIndependentSimd();
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
    const FlushDenormals flush;
    HWY_DYNAMIC_DISPATCH(AtrousRows)(&args, rows.begin(), rows.end());
  });
}

void estimateVariance(AtrousPlanes& p, float sigmaZ, float momentsSigmaL) {
  const int w = p.width, h = p.height;
  const MomentsArgs args{p.depth.data(),    p.nx.data(),      p.ny.data(),         p.nz.data(),       p.hit.data(),
                         p.gradX.data(),    p.gradY.data(),   p.luminance.data(),    p.moment1.data(),  p.temporalVariance.data(),
                         p.historyLength.data(), p.variance.data(), w,             p.stride,          sigmaZ,
                         momentsSigmaL};
  core::useMachineIndependentSimd();
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 8), [&](const tbb::blocked_range<int>& rows) {
    const FlushDenormals flush;
    HWY_DYNAMIC_DISPATCH(MomentsRows)(&args, rows.begin(), rows.end());
  });
}

}  // namespace dynbench::evaluate::svgf
#endif
