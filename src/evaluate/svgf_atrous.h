#pragma once
// SVGF's spatial filters, the à-trous wavelet filter ([S17] §4.3-4.4, Eqs. 1-5) one iteration at a
// time and the variance estimate's 7x7 bilateral filter (§4.2), in single precision over SIMD lanes (Google's Highway picks SSE4, AVX2 or AVX-512 at run time, as in
// render/bsdf_batch.cpp). Their 25 and 49 taps a pixel with two exponentials each, in double
// precision and one pixel at a time, were nearly all of `svgf`'s time (5 s a 1080p frame; issue 34).
//
// The planes are structure of arrays, padded by kPad pixels on every side whose `hit` and normal are 0, so a
// tap outside the image weighs nothing, as the scalar filter skipped it, and a row of lanes reads
// its taps with plain unaligned loads.
#include <cstddef>
#include <vector>

namespace dynbench::evaluate::svgf {

struct AtrousPlanes {
  static constexpr int kPad = 32;  // two taps of the largest step, 16
  int width = 0, height = 0, stride = 0;
  // Per frame: depth, shading normal (0 where the pixel hit nothing: the filters' normal weight
  // is then 0, which is how they skip such taps), hit (1 or 0), depth gradient (per pixel, a
  // pixel's step).
  std::vector<float> depth, nx, ny, nz, hit, gradX, gradY;
  // Per iteration: the illumination being filtered, its variance and its luminance (Rec. 709).
  std::vector<float> r, g, b, variance, luminance;
  // For the variance estimate: the temporally accumulated luminance moment m1, the variance
  // m2 - m1^2 of the accumulated moments (computed in double) and the history length.
  std::vector<float> moment1, temporalVariance, historyLength;
  // For the next frame's temporal pass: the instance id and the illumination after the first
  // iteration ([S17] §4.1: the colour history).
  std::vector<float> id, historyR, historyG, historyB;

  void resize(int w, int h);
  std::size_t at(int x, int y) const {
    return static_cast<std::size_t>(y + kPad) * static_cast<std::size_t>(stride) + static_cast<std::size_t>(x + kPad);
  }
};

struct AtrousWeights {
  float sigmaZ = 1.0f, sigmaL = 4.0f;  // [S17] §4.4 (sigma_n = 128 is fixed: seven squarings)
};

// The last iteration's output remodulated with the albedo ([S17] §3), instead of its planes: RGB
// interleaved and unpadded (width x height x 3), each channel times max(diffuseShare x base +
// specularShare, floor) where the pixel hit a surface, times 1 elsewhere (the method's demodulation,
// method_svgf.cpp, whose constants these are).
struct Remodulation {
  const float* baseColour;  // RGB interleaved, unpadded
  float diffuseShare, specularShare, floor;
  float* rgb;
};

// One iteration with taps `step` pixels apart: r, g, b and variance of `planes` filtered into
// those of `out`, with the luminance of the result (those five planes resized to match, its others
// left alone; `planes`' variance padding is written). Pixels that hit nothing are copied. The
// variance's 3x3 Gaussian prefilter of the luminance weight ([S17] Eq. 5) reads clamped
// coordinates, as the scalar filter did. `planes.luminance` must be that of r, g, b (each
// iteration writes its output's).
// With `remodulation`, the result goes there and `out` is not written.
void atrousIteration(AtrousPlanes& planes, int step, const AtrousWeights& weights, AtrousPlanes& out, const Remodulation* remodulation = nullptr);

// The variance estimate of [S17] §4.2 into `planes.variance`: where the history is 4 frames or
// longer, the temporal moments' m2 - m1^2; where shorter, the moments of the 7x7 neighbourhood
// weighted by the depth, normal and luminance edge-stopping weights (sigma_l = 10 on the
// illumination's luminance, [Falcor] SVGFFilterMoments; the centre weighs 1), boosted by
// 4 / length. Pixels that hit nothing get 0. Reads `planes.luminance`, which the caller fills
// with that of r, g, b.
void estimateVariance(AtrousPlanes& planes, float sigmaZ, float momentsSigmaL);

}  // namespace dynbench::evaluate::svgf
