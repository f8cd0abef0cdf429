// ꟻLIP from [HPG20] and [EG21] (flip.h). Filters are applied separably: every kernel here is a
// Gaussian or a sum of Gaussians in x and y, which factor exactly (the sum term by term).
#include "evaluate/flip.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <tbb/parallel_for.h>

namespace dynbench::evaluate::flip {
namespace {

using std::numbers::pi;

// Linear sRGB -> XYZ from the sRGB primaries and the D65 white (x, y) = (0.3127, 0.3290) of
// IEC 61966-2-1, to seven digits; the inverse is computed from it so that a round trip is exact to
// rounding.
const glm::dmat3& rgbToXyzMatrix() {
  // glm is column-major: each row below is a column (R, G, B).
  static const glm::dmat3 m(0.4123908, 0.2126390, 0.0193308,   //
                            0.3575843, 0.7151687, 0.1191948,   //
                            0.1804808, 0.0721923, 0.9505322);
  return m;
}
const glm::dmat3& xyzToRgbMatrix() {
  static const glm::dmat3 m = glm::inverse(rgbToXyzMatrix());
  return m;
}
// The reference white: XYZ of linear RGB (1, 1, 1).
const glm::dvec3& whitePoint() {
  static const glm::dvec3 white = rgbToXyzMatrix() * glm::dvec3(1.0);
  return white;
}

// CIELAB's f(t) and its inverse (CIE 15:2004, delta = 6/29).
double labF(double t) {
  constexpr double delta = 6.0 / 29.0;
  return t > delta * delta * delta ? std::cbrt(t) : t / (3.0 * delta * delta) + 4.0 / 29.0;
}

// One plane of w x h floats.
using Plane = std::vector<float>;

// Correlates each row (horizontal) or each column (vertical) with a kernel of odd length,
// clamping at the edges, as the authors' tool does.
void filterHorizontal(const Plane& in, Plane& out, int w, int h, const std::vector<float>& kernel) {
  const int r = static_cast<int>(kernel.size() / 2);
  out.assign(in.size(), 0.0f);
  tbb::parallel_for(0, h, [&](int y) {
    const float* row = in.data() + static_cast<std::size_t>(y) * w;
    float* dst = out.data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (int k = -r; k <= r; ++k) sum += kernel[k + r] * row[std::clamp(x + k, 0, w - 1)];
      dst[x] = sum;
    }
  });
}
void filterVertical(const Plane& in, Plane& out, int w, int h, const std::vector<float>& kernel) {
  const int r = static_cast<int>(kernel.size() / 2);
  out.assign(in.size(), 0.0f);
  tbb::parallel_for(0, h, [&](int y) {
    float* dst = out.data() + static_cast<std::size_t>(y) * w;
    for (int k = -r; k <= r; ++k) {
      const float weight = kernel[k + r];
      const float* row = in.data() + static_cast<std::size_t>(std::clamp(y + k, 0, h - 1)) * w;
      for (int x = 0; x < w; ++x) dst[x] += weight * row[x];
    }
  });
}
Plane separable(const Plane& in, int w, int h, const std::vector<float>& kx, const std::vector<float>& ky) {
  Plane tmp, out;
  filterHorizontal(in, tmp, w, h, kx);
  filterVertical(tmp, out, w, h, ky);
  return out;
}

// The contrast sensitivity functions of [HPG20] §4.1 (after Mannos & Sakrison / Johnson &
// Fairchild), as spatial filters: A(f) = a1 exp(-b1 f^2) + a2 exp(-b2 f^2) per channel of YCxCz,
// whose inverse Fourier transform is sum_i a_i sqrt(pi / b_i) exp(-pi^2 x^2 / b_i), x in degrees.
// Table 1 of [HPG20]: achromatic a1 = 1, b1 = 0.0047; red-green a1 = 1, b1 = 0.0053; blue-yellow
// a1 = 34.1, b1 = 0.04, a2 = 13.5, b2 = 0.025.
struct CsfGaussian {
  double a, b;
};
constexpr CsfGaussian kAchromatic{1.0, 0.0047}, kRedGreen{1.0, 0.0053}, kBlueYellow1{34.1, 0.04}, kBlueYellow2{13.5, 0.025};

// The filter radius in pixels: 3 standard deviations of the widest Gaussian (sigma^2 = b / (2 pi^2)).
int spatialRadius(double ppd) {
  const double widest = std::max({kAchromatic.b, kRedGreen.b, kBlueYellow1.b, kBlueYellow2.b});
  return static_cast<int>(std::ceil(3.0 * std::sqrt(widest / (2.0 * pi * pi)) * ppd));
}
// exp(-pi^2 x^2 / b) at pixel offsets -r..r (x = offset / ppd degrees), unnormalised; its sum.
std::vector<float> csfKernel(const CsfGaussian& g, int radius, double ppd, double* sum) {
  std::vector<float> k(2 * radius + 1);
  *sum = 0.0;
  for (int i = -radius; i <= radius; ++i) {
    const double x = i / ppd;
    k[i + radius] = static_cast<float>(std::exp(-pi * pi * x * x / g.b));
    *sum += k[i + radius];
  }
  return k;
}
std::vector<float> scaled(std::vector<float> k, double factor) {
  for (float& v : k) v = static_cast<float>(v * factor);
  return k;
}

// YCxCz planes of an image (linear RGB clamped to [0, 1]) and its luminance.
struct Opponent {
  Plane y, cx, cz, luminance;
};
Opponent toOpponent(const RgbImage& image) {
  Opponent o;
  const std::size_t n = image.pixelCount();
  o.y.resize(n), o.cx.resize(n), o.cz.resize(n), o.luminance.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 rgb = glm::clamp(glm::dvec3(image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]), 0.0, 1.0);
    const glm::dvec3 xyz = linearRgbToXyz(rgb);
    const glm::dvec3 v = xyzToYcxcz(xyz);
    o.y[i] = static_cast<float>(v.x), o.cx[i] = static_cast<float>(v.y), o.cz[i] = static_cast<float>(v.z);
    // (Y + 16) / 116 of YCxCz: the luminance relative to white, the feature detector's input.
    o.luminance[i] = static_cast<float>(xyz.y / whitePoint().y);
  }
  return o;
}

// The spatially filtered image in Hunt-adjusted L*a*b*, per pixel ([HPG20] §4.1, Fig. 3).
std::vector<glm::vec3> filteredHuntLab(const Opponent& o, int w, int h, double ppd) {
  const int radius = spatialRadius(ppd);
  double sumY = 0, sumCx = 0, sum1 = 0, sum2 = 0;
  const auto kY = csfKernel(kAchromatic, radius, ppd, &sumY);
  const auto kCx = csfKernel(kRedGreen, radius, ppd, &sumCx);
  const auto k1 = csfKernel(kBlueYellow1, radius, ppd, &sum1);
  const auto k2 = csfKernel(kBlueYellow2, radius, ppd, &sum2);
  // Single-Gaussian channels: the 2D kernel normalised to sum 1 is the product of two 1D
  // kernels normalised to sum 1.
  const Plane y = separable(o.y, w, h, scaled(kY, 1.0 / sumY), scaled(kY, 1.0 / sumY));
  const Plane cx = separable(o.cx, w, h, scaled(kCx, 1.0 / sumCx), scaled(kCx, 1.0 / sumCx));
  // Blue-yellow: sum_i A_i G_i(x) G_i(y) with A_i = a_i sqrt(pi / b_i), normalised by its 2D sum
  // S = sum_i A_i (sum_x G_i)^2.
  const double a1 = kBlueYellow1.a * std::sqrt(pi / kBlueYellow1.b), a2 = kBlueYellow2.a * std::sqrt(pi / kBlueYellow2.b);
  const double s = a1 * sum1 * sum1 + a2 * sum2 * sum2;
  const Plane cz1 = separable(o.cz, w, h, scaled(k1, a1 / s), k1);
  const Plane cz2 = separable(o.cz, w, h, scaled(k2, a2 / s), k2);

  std::vector<glm::vec3> lab(o.y.size());
  tbb::parallel_for(std::size_t(0), lab.size(), [&](std::size_t i) {
    const glm::dvec3 ycxcz(y[i], cx[i], static_cast<double>(cz1[i]) + cz2[i]);
    // Back to linear RGB, clamped to the display's gamut, then to L*a*b* and Hunt's adjustment.
    const glm::dvec3 rgb = glm::clamp(xyzToLinearRgb(ycxczToXyz(ycxcz)), 0.0, 1.0);
    lab[i] = glm::vec3(huntAdjust(xyzToLab(linearRgbToXyz(rgb))));
  });
  return lab;
}

// 1D Gaussian, first and second derivative kernels of the feature detector ([HPG20] §4.2).
struct FeatureKernels {
  std::vector<float> gaussian, first, second;
};
FeatureKernels featureKernels(double ppd) {
  const double sigma = 0.5 * kFeatureWidth * ppd;  // pixels
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  FeatureKernels k;
  std::vector<double> g, d1, d2;
  double gSum = 0, d1Pos = 0, d1Neg = 0, d2Pos = 0, d2Neg = 0;
  for (int i = -radius; i <= radius; ++i) {
    const double x = i, gi = std::exp(-x * x / (2.0 * sigma * sigma));
    g.push_back(gi), d1.push_back(-x * gi), d2.push_back((x * x / (sigma * sigma) - 1.0) * gi);
    gSum += gi;
    (d1.back() > 0 ? d1Pos : d1Neg) += std::abs(d1.back());
    (d2.back() > 0 ? d2Pos : d2Neg) += std::abs(d2.back());
  }
  // Positive weights sum to 1 and negative weights to -1, so a derivative filter answers 1 to a
  // unit step whatever sigma is.
  for (std::size_t i = 0; i < g.size(); ++i) {
    k.gaussian.push_back(static_cast<float>(g[i] / gSum));
    k.first.push_back(static_cast<float>(d1[i] / (d1[i] > 0 ? d1Pos : d1Neg)));
    k.second.push_back(static_cast<float>(d2[i] / (d2[i] > 0 ? d2Pos : d2Neg)));
  }
  return k;
}

}  // namespace

double defaultPixelsPerDegree() { return 0.7 * (3840.0 / 0.7) * (pi / 180.0); }

glm::dvec3 srgbToLinear(glm::dvec3 s) {
  auto f = [](double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
  return {f(s.x), f(s.y), f(s.z)};
}
glm::dvec3 linearToSrgb(glm::dvec3 l) {
  auto f = [](double c) { return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055; };
  return {f(l.x), f(l.y), f(l.z)};
}
glm::dvec3 linearRgbToXyz(glm::dvec3 rgb) { return rgbToXyzMatrix() * rgb; }
glm::dvec3 xyzToLinearRgb(glm::dvec3 xyz) { return xyzToRgbMatrix() * xyz; }

glm::dvec3 xyzToYcxcz(glm::dvec3 xyz) {
  const glm::dvec3 n = xyz / whitePoint();
  return {116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z)};
}
glm::dvec3 ycxczToXyz(glm::dvec3 v) {
  const double y = (v.x + 16.0) / 116.0;
  return glm::dvec3(y + v.y / 500.0, y, y - v.z / 200.0) * whitePoint();
}
glm::dvec3 xyzToLab(glm::dvec3 xyz) {
  const glm::dvec3 n = xyz / whitePoint();
  const double fx = labF(n.x), fy = labF(n.y), fz = labF(n.z);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}
glm::dvec3 huntAdjust(glm::dvec3 lab) { return {lab.x, 0.01 * lab.x * lab.y, 0.01 * lab.x * lab.z}; }
double hyab(glm::dvec3 a, glm::dvec3 b) {
  return std::abs(a.x - b.x) + std::hypot(a.y - b.y, a.z - b.z);
}
double maxColorDistance() {
  static const double cmax = [] {
    const glm::dvec3 green = huntAdjust(xyzToLab(linearRgbToXyz({0.0, 1.0, 0.0})));
    const glm::dvec3 blue = huntAdjust(xyzToLab(linearRgbToXyz({0.0, 0.0, 1.0})));
    return std::pow(hyab(green, blue), kQc);
  }();
  return cmax;
}
double remapColorError(double hyabDistance) {
  const double cmax = maxColorDistance(), d = std::pow(hyabDistance, kQc), breakPoint = kPc * cmax;
  if (d < breakPoint) return d * kPt / breakPoint;
  return std::min(1.0, kPt + (d - breakPoint) / (cmax - breakPoint) * (1.0 - kPt));
}

FeatureResponse featureResponse(const std::vector<float>& luminance, int w, int h, double ppd) {
  const FeatureKernels k = featureKernels(ppd);
  // x derivatives smoothed in y, y derivatives smoothed in x.
  const Plane dx = separable(luminance, w, h, k.first, k.gaussian), dy = separable(luminance, w, h, k.gaussian, k.first);
  const Plane ddx = separable(luminance, w, h, k.second, k.gaussian), ddy = separable(luminance, w, h, k.gaussian, k.second);
  FeatureResponse r;
  r.edge.resize(luminance.size()), r.point.resize(luminance.size());
  for (std::size_t i = 0; i < luminance.size(); ++i) {
    r.edge[i] = std::hypot(dx[i], dy[i]);
    r.point[i] = std::hypot(ddx[i], ddy[i]);
  }
  return r;
}

std::vector<float> ldrFlip(const RgbImage& reference, const RgbImage& test, double ppd) {
  const int w = reference.width, h = reference.height;
  const Opponent ref = toOpponent(reference), tst = toOpponent(test);
  const std::vector<glm::vec3> refLab = filteredHuntLab(ref, w, h, ppd), tstLab = filteredHuntLab(tst, w, h, ppd);
  const FeatureResponse refF = featureResponse(ref.luminance, w, h, ppd), tstF = featureResponse(tst.luminance, w, h, ppd);
  std::vector<float> error(refLab.size());
  tbb::parallel_for(std::size_t(0), error.size(), [&](std::size_t i) {
    const double colour = remapColorError(hyab(glm::dvec3(refLab[i]), glm::dvec3(tstLab[i])));
    // [HPG20] Eq. 6: the feature difference, max of edge and point, over sqrt(2), to the q_f.
    const double edge = std::abs(refF.edge[i] - tstF.edge[i]), point = std::abs(refF.point[i] - tstF.point[i]);
    const double feature = std::pow(std::max(edge, point) / std::numbers::sqrt2, kQf);
    error[i] = static_cast<float>(std::pow(colour, 1.0 - feature));  // [HPG20] Eq. 5
  });
  return error;
}

double acesToneMap(double x) {
  // Narkowicz's fit (a x^2 + b x) / (c x^2 + d x + e) with a = 2.51, b = 0.03, c = 2.43, d = 0.59,
  // e = 0.14, applied to 0.6 x: [EG21] §3 cancels the fit's built-in 0.6 pre-exposure so that an
  // exposure of 0 shows the radiance as is.
  const double s = 0.6 * x;
  return (2.51 * s * s + 0.03 * s) / (2.43 * s * s + 0.59 * s + 0.14);
}

ExposureRange hdrExposureRange(const RgbImage& reference) {
  ExposureRange range;
  // x_max: the radiance the tone mapper takes to 0.85, the positive root of
  // (0.36 * 2.51 - 0.85 * 0.36 * 2.43) x^2 + (0.6 * 0.03 - 0.85 * 0.6 * 0.59) x - 0.85 * 0.14 = 0.
  const double t = 0.85, a = 0.36 * 2.51 - t * 0.36 * 2.43, b = 0.6 * 0.03 - t * 0.6 * 0.59, c = -t * 0.14;
  range.xMax = (-b + std::sqrt(b * b - 4.0 * a * c)) / (2.0 * a);
  std::vector<float> luminance(reference.pixelCount());
  float maxLuminance = 0.0f;
  for (std::size_t i = 0; i < luminance.size(); ++i) {
    luminance[i] = static_cast<float>(0.2126 * reference.rgb[3 * i] + 0.7152 * reference.rgb[3 * i + 1] + 0.0722 * reference.rgb[3 * i + 2]);
    maxLuminance = std::max(maxLuminance, luminance[i]);
  }
  if (!(maxLuminance > 0.0f)) return range;  // a black reference: one exposure is as good as any
  // [EG21] Eq. 2: the median of all pixels (the upper one of an even count, as the authors' tool).
  // Where more than half the image is black the median is 0, and then the median of the lit
  // pixels is used (the authors' tool would give an infinite stop exposure there).
  auto middle = luminance.begin() + static_cast<std::ptrdiff_t>(luminance.size() / 2);
  std::nth_element(luminance.begin(), middle, luminance.end());
  double median = *middle;
  if (!(median > 0.0)) {
    std::vector<float> lit;
    for (float l : luminance) if (l > 0.0f) lit.push_back(l);
    auto m = lit.begin() + static_cast<std::ptrdiff_t>(lit.size() / 2);
    std::nth_element(lit.begin(), m, lit.end());
    median = *m;
  }
  range.start = std::log2(range.xMax / maxLuminance);
  range.stop = std::log2(range.xMax / median);
  range.count = static_cast<int>(std::max(2.0, std::ceil(range.stop - range.start)));
  return range;
}

HdrFlipResult hdrFlip(const RgbImage& reference, const RgbImage& test, double ppd) {
  HdrFlipResult result;
  result.exposures = hdrExposureRange(reference);
  result.error.assign(reference.pixelCount(), 0.0f);
  const ExposureRange& r = result.exposures;
  for (int e = 0; e < r.count; ++e) {
    const double exposure = r.start + e * (r.stop - r.start) / (r.count - 1);
    const double scale = std::exp2(exposure);
    auto expose = [&](const RgbImage& in) {
      RgbImage out = in;
      for (float& v : out.rgb) v = static_cast<float>(std::clamp(acesToneMap(scale * v), 0.0, 1.0));
      return out;
    };
    const std::vector<float> ldr = ldrFlip(expose(reference), expose(test), ppd);
    for (std::size_t i = 0; i < ldr.size(); ++i) result.error[i] = std::max(result.error[i], ldr[i]);  // [EG21] Eq. 3
  }
  return result;
}

Pooled pool(const std::vector<float>& error) {
  Pooled p;
  if (error.empty()) return p;
  std::vector<float> sorted = error;
  std::sort(sorted.begin(), sorted.end());
  double total = 0.0;
  for (float e : sorted) total += e;
  p.mean = total / static_cast<double>(sorted.size());
  p.max = sorted.back();
  auto weighted = [&](double fraction) {
    double running = 0.0;
    for (float e : sorted) {
      running += e;
      if (running > fraction * total) return static_cast<double>(e);
    }
    return 0.0;  // every error is 0
  };
  p.weightedQ1 = weighted(0.25), p.weightedMedian = weighted(0.5), p.weightedQ3 = weighted(0.75);
  return p;
}

}  // namespace dynbench::evaluate::flip
