// ꟻLIP from [HPG20] and [EG21] (flip.h). Filters are applied separably: every kernel here is a
// Gaussian or a sum of Gaussians in x and y, which factor exactly (the sum term by term).
#include "evaluate/flip.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <type_traits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "core/math.h"
#include "evaluate/vector_loops.h"

namespace dynbench::evaluate::flip {
namespace {

using std::numbers::pi;

// Linear sRGB -> XYZ (D65) as the ꟻLIP authors define it (FLIP.h, LinearRGBToXYZ, after
// image-engineering.de's technote 958): the exact fractions below. The inverse is computed from
// it, so a round trip is exact to rounding; it equals their XYZToLinearRGB to 1e-8. (The sRGB
// standard's seven-digit matrix differs from these by up to 1e-4 relative, in the white's Z: that
// moved every ꟻLIP mean by about 1e-5 relative against the authors' tool.) glm is column-major:
// each row below is a column (R, G, B).
const glm::dmat3 kRgbToXyz(10135552.0 / 24577794.0, 2613072.0 / 12288897.0, 1425312.0 / 73733382.0,  //
                           8788810.0 / 24577794.0, 8788810.0 / 12288897.0, 8788810.0 / 73733382.0,   //
                           4435075.0 / 24577794.0, 887015.0 / 12288897.0, 70074185.0 / 73733382.0);
const glm::dmat3 kXyzToRgb = glm::inverse(kRgbToXyz);
// The reference white: XYZ of linear RGB (1, 1, 1).
const glm::dvec3 kWhite = kRgbToXyz * glm::dvec3(1.0);

const glm::dvec3& whitePoint() { return kWhite; }

template <typename T>
using Vec3 = glm::vec<3, T, glm::defaultp>;

// The cube root of a positive float: the exponent divided by 3 in the bits (a guess within 4 %),
// then two steps of Halley's iteration y <- y (y^3 + 2x) / (2y^3 + x), cubically convergent:
// within 2.4e-7 relative (3 ulp of cbrtf) over [0.008, 2], checked on every float there. glibc's
// cbrtf, not vectorised, with frexpf and scalbnf was a sixth of ꟻLIP's time.
float cubeRoot(float x) {
  const float y0 = std::bit_cast<float>(std::bit_cast<std::uint32_t>(x) / 3u + 709921077u);
  const float c0 = y0 * y0 * y0, y1 = y0 * (c0 + 2.0f * x) / (2.0f * c0 + x);
  const float c1 = y1 * y1 * y1;
  return y1 * (c1 + 2.0f * x) / (2.0f * c1 + x);
}
double cubeRoot(double x) { return std::cbrt(x); }

// CIELAB's f(t) (CIE 15:2004, delta = 6/29); t > delta^3 > 0 where the cube root is taken.
template <typename T>
T labF(T t) {
  constexpr T delta = T(6) / T(29);
  return t > delta * delta * delta ? cubeRoot(t) : t / (T(3) * delta * delta) + T(4) / T(29);
}
// The colour pipeline for double (the tested per-step functions below) and float (the per-pixel
// path): one definition of each step, the constants with it.
template <typename T>
struct ColourSpace {
  glm::mat<3, 3, T, glm::defaultp> rgbToXyz, xyzToRgb;
  Vec3<T> white;

  Vec3<T> linearRgbToXyz(Vec3<T> rgb) const { return rgbToXyz * rgb; }
  Vec3<T> xyzToLinearRgb(Vec3<T> xyz) const { return xyzToRgb * xyz; }
  Vec3<T> xyzToYcxcz(Vec3<T> xyz) const {
    const Vec3<T> n = xyz / white;
    return {T(116) * n.y - T(16), T(500) * (n.x - n.y), T(200) * (n.y - n.z)};
  }
  Vec3<T> ycxczToXyz(Vec3<T> v) const {
    const T y = (v.x + T(16)) / T(116);
    return Vec3<T>(y + v.y / T(500), y, y - v.z / T(200)) * white;
  }
  Vec3<T> xyzToLab(Vec3<T> xyz) const {
    const Vec3<T> n = xyz / white;
    const T fx = labF(n.x), fy = labF(n.y), fz = labF(n.z);
    return {T(116) * fy - T(16), T(500) * (fx - fy), T(200) * (fy - fz)};
  }
  static Vec3<T> huntAdjust(Vec3<T> lab) { return {lab.x, T(0.01) * lab.x * lab.y, T(0.01) * lab.x * lab.z}; }
};
// In double for the tested steps; in single precision for the per-pixel path (as the authors' tool
// computes).
const ColourSpace<double> kColour{kRgbToXyz, kXyzToRgb, kWhite};
const ColourSpace<float> kColourF{glm::mat3(kRgbToXyz), glm::mat3(kXyzToRgb), glm::vec3(kWhite)};

// One plane of w x h floats.
using Plane = std::vector<float>;

// The separable filters, in two passes. Each output row is accumulated one kernel tap at a time
// over a contiguous row (addScaled, vector_loops.h): the previous form, a clamped gather of every
// tap for every output pixel, did not vectorise and was most of ꟻLIP's time. Edges are clamped,
// as the authors' tool does. All kernels of a pass have one length.
// Rows: every row of `in` correlated with each kernel, into out[first + k] for kernel k (planes
// reused from call to call: fresh ones cost a page fault every 4 KiB).
void rowPass(const Plane& in, int w, int h, std::initializer_list<const std::vector<float>*> kernels, std::vector<Plane>& out,
             std::size_t first = 0) {
  const int r = static_cast<int>((*kernels.begin())->size() / 2);
  if (out.size() < first + kernels.size()) out.resize(first + kernels.size());
  for (std::size_t k = 0; k < kernels.size(); ++k) out[first + k].resize(in.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    std::vector<float> padded(static_cast<std::size_t>(w + 2 * r));
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const float* src = in.data() + static_cast<std::size_t>(y) * w;
      for (int x = 0; x < w + 2 * r; ++x) padded[static_cast<std::size_t>(x)] = src[std::clamp(x - r, 0, w - 1)];
      std::size_t k = first;
      for (const std::vector<float>* kernel : kernels) {
        float* dst = out[k++].data() + static_cast<std::size_t>(y) * w;
        std::fill(dst, dst + w, 0.0f);
        for (int t = 0; t <= 2 * r; ++t) addScaled(dst, padded.data() + t, (*kernel)[static_cast<std::size_t>(t)], w);
      }
    }
  });
}
// Columns, for one output row y: out[x] = sum_t kernel[t] in[clamp(y + t - r)][x].
void columnAt(const Plane& in, int w, int h, int y, const std::vector<float>& kernel, float* out) {
  const int r = static_cast<int>(kernel.size() / 2);
  std::fill(out, out + w, 0.0f);
  for (int t = 0; t <= 2 * r; ++t)
    addScaled(out, in.data() + static_cast<std::size_t>(std::clamp(y + t - r, 0, h - 1)) * w, kernel[static_cast<std::size_t>(t)], w);
}
// The column pass of several filters at once: for each block of rows, `rows` scratch rows of w
// floats and a callback per output row.
template <typename PerRow>
void columnPass(int w, int h, std::size_t rows, PerRow&& perRow) {
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& block) {
    std::vector<float> scratch(rows * static_cast<std::size_t>(w));
    for (int y = block.begin(); y < block.end(); ++y) perRow(y, scratch.data());
  });
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

// Narkowicz's fit (a x^2 + b x) / (c x^2 + d x + e) with a = 2.51, b = 0.03, c = 2.43, d = 0.59,
// e = 0.14, applied to 0.6 x: [EG21] §3 cancels the fit's built-in 0.6 pre-exposure so that an
// exposure of 0 shows the radiance as is.
template <typename T>
T acesToneMapT(T x) {
  const T s = T(0.6) * x;
  return (T(2.51) * s * s + T(0.03) * s) / (T(2.43) * s * s + T(0.59) * s + T(0.14));
}

// HyAB distance |dL| + ||d(a, b)|| of two Hunt-adjusted L*a*b* colours ([HPG20] Eq. 3), from
// their differences.
template <typename T>
T hyabT(T dl, T da, T db) {
  return std::abs(dl) + std::sqrt(da * da + db * db);
}

// [HPG20] Eq. 4 for either precision, given c_max (maxColorDistance).
template <typename T>
T remapColorErrorT(T hyabDistance, T cmax) {
  const T d = std::pow(hyabDistance, T(kQc)), breakPoint = T(kPc) * cmax;
  if (d < breakPoint) return d * T(kPt) / breakPoint;
  return std::min(T(1), T(kPt) + (d - breakPoint) / (cmax - breakPoint) * (T(1) - T(kPt)));
}

// YCxCz planes of an image (linear RGB clamped to [0, 1]) and its luminance; with an exposure
// scale, of the image tone-mapped by HDR-ꟻLIP's ACES curve at that exposure first.
struct Opponent {
  Plane y, cx, cz, luminance;
};
void toOpponent(const RgbImage& image, std::optional<float> exposureScale, Opponent& o) {
  const std::size_t n = image.pixelCount();
  o.y.resize(n), o.cx.resize(n), o.cz.resize(n), o.luminance.resize(n);
  const float whiteY = static_cast<float>(whitePoint().y);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& range) {
    const ColourSpace<float> colour = kColourF;
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      glm::vec3 rgb(image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]);
      if (exposureScale) rgb = glm::vec3(acesToneMapT(*exposureScale * rgb.x), acesToneMapT(*exposureScale * rgb.y), acesToneMapT(*exposureScale * rgb.z));
      rgb = glm::clamp(rgb, 0.0f, 1.0f);
      const glm::vec3 xyz = colour.linearRgbToXyz(rgb);
      const glm::vec3 v = colour.xyzToYcxcz(xyz);
      o.y[i] = v.x, o.cx[i] = v.y, o.cz[i] = v.z;
      // (Y + 16) / 116 of YCxCz: the luminance relative to white, the feature detector's input.
      o.luminance[i] = xyz.y / whiteY;
    }
  });
}

// A row of filtered YCxCz (Cz as its two Gaussians' parts) back to linear RGB, clamped to the
// display's gamut, then to Hunt-adjusted L*a*b*.
void huntLabRow(const float* y, const float* cx, const float* cz1, const float* cz2, float* l, float* a, float* b, int n) {
  const ColourSpace<float> colour = kColourF;
  for (int x = 0; x < n; ++x) {
    const glm::vec3 rgb = glm::clamp(colour.xyzToLinearRgb(colour.ycxczToXyz(glm::vec3(y[x], cx[x], cz1[x] + cz2[x]))), 0.0f, 1.0f);
    const glm::vec3 hunt = colour.huntAdjust(colour.xyzToLab(colour.linearRgbToXyz(rgb)));
    l[x] = hunt.x, a[x] = hunt.y, b[x] = hunt.z;
  }
}

// The spatially filtered image in Hunt-adjusted L*a*b*, per pixel ([HPG20] §4.1, Fig. 3), as
// three planes.
void filteredHuntLab(const Opponent& o, int w, int h, double ppd, std::vector<Plane>& rows, std::array<Plane, 3>& lab) {
  const int radius = spatialRadius(ppd);
  double sumY = 0, sumCx = 0, sum1 = 0, sum2 = 0;
  const auto kY = csfKernel(kAchromatic, radius, ppd, &sumY);
  const auto kCx = csfKernel(kRedGreen, radius, ppd, &sumCx);
  const auto k1 = csfKernel(kBlueYellow1, radius, ppd, &sum1);
  const auto k2 = csfKernel(kBlueYellow2, radius, ppd, &sum2);
  // Single-Gaussian channels: the 2D kernel normalised to sum 1 is the product of two 1D
  // kernels normalised to sum 1. Blue-yellow: sum_i A_i G_i(x) G_i(y) with A_i = a_i sqrt(pi /
  // b_i), normalised by its 2D sum S = sum_i A_i (sum_x G_i)^2.
  const auto kYn = scaled(kY, 1.0 / sumY), kCxn = scaled(kCx, 1.0 / sumCx);
  const double a1 = kBlueYellow1.a * std::sqrt(pi / kBlueYellow1.b), a2 = kBlueYellow2.a * std::sqrt(pi / kBlueYellow2.b);
  const double s = a1 * sum1 * sum1 + a2 * sum2 * sum2;
  const auto k1s = scaled(k1, a1 / s), k2s = scaled(k2, a2 / s);
  rowPass(o.y, w, h, {&kYn}, rows, 0);
  rowPass(o.cx, w, h, {&kCxn}, rows, 1);
  rowPass(o.cz, w, h, {&k1s, &k2s}, rows, 2);
  const Plane &ry = rows[0], &rcx = rows[1], &rcz1 = rows[2], &rcz2 = rows[3];
  for (Plane& p : lab) p.resize(o.y.size());
  columnPass(w, h, 4, [&](int y, float* scratch) {
    float *fy = scratch, *fcx = scratch + w, *fcz1 = scratch + 2 * w, *fcz2 = scratch + 3 * w;
    columnAt(ry, w, h, y, kYn, fy);
    columnAt(rcx, w, h, y, kCxn, fcx);
    columnAt(rcz1, w, h, y, k1, fcz1);
    columnAt(rcz2, w, h, y, k2, fcz2);
    const std::size_t row = static_cast<std::size_t>(y) * w;
    huntLabRow(fy, fcx, fcz1, fcz2, lab[0].data() + row, lab[1].data() + row, lab[2].data() + row, w);
  });
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

glm::dvec3 srgbToLinear(glm::dvec3 s) { return {dynbench::srgbToLinear(s.x), dynbench::srgbToLinear(s.y), dynbench::srgbToLinear(s.z)}; }
glm::dvec3 linearToSrgb(glm::dvec3 l) { return {dynbench::linearToSrgb(l.x), dynbench::linearToSrgb(l.y), dynbench::linearToSrgb(l.z)}; }
glm::dvec3 linearRgbToXyz(glm::dvec3 rgb) { return kColour.linearRgbToXyz(rgb); }
glm::dvec3 xyzToLinearRgb(glm::dvec3 xyz) { return kColour.xyzToLinearRgb(xyz); }
glm::dvec3 xyzToYcxcz(glm::dvec3 xyz) { return kColour.xyzToYcxcz(xyz); }
glm::dvec3 ycxczToXyz(glm::dvec3 v) { return kColour.ycxczToXyz(v); }
glm::dvec3 xyzToLab(glm::dvec3 xyz) { return kColour.xyzToLab(xyz); }
glm::dvec3 huntAdjust(glm::dvec3 lab) { return ColourSpace<double>::huntAdjust(lab); }
double hyab(glm::dvec3 a, glm::dvec3 b) { return hyabT(a.x - b.x, a.y - b.y, a.z - b.z); }
double maxColorDistance() {
  static const double cmax = [] {
    const glm::dvec3 green = huntAdjust(xyzToLab(linearRgbToXyz({0.0, 1.0, 0.0})));
    const glm::dvec3 blue = huntAdjust(xyzToLab(linearRgbToXyz({0.0, 0.0, 1.0})));
    return std::pow(hyab(green, blue), kQc);
  }();
  return cmax;
}
double remapColorError(double hyabDistance) { return remapColorErrorT(hyabDistance, maxColorDistance()); }

namespace {

void featureResponseInto(const std::vector<float>& luminance, int w, int h, double ppd, std::vector<Plane>& rows, FeatureResponse& r) {
  const FeatureKernels k = featureKernels(ppd);
  // The rows' Gaussian, first and second derivative in one pass; then the columns: x derivatives
  // smoothed in y, y derivatives smoothed in x, and their magnitudes, in another.
  rowPass(luminance, w, h, {&k.gaussian, &k.first, &k.second}, rows);
  r.edge.resize(luminance.size()), r.point.resize(luminance.size());
  columnPass(w, h, 4, [&](int y, float* scratch) {
    float *dx = scratch, *dy = scratch + w, *ddx = scratch + 2 * w, *ddy = scratch + 3 * w;
    columnAt(rows[1], w, h, y, k.gaussian, dx);
    columnAt(rows[0], w, h, y, k.first, dy);
    columnAt(rows[2], w, h, y, k.gaussian, ddx);
    columnAt(rows[0], w, h, y, k.second, ddy);
    float* edge = r.edge.data() + static_cast<std::size_t>(y) * w;
    float* point = r.point.data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      edge[x] = std::sqrt(dx[x] * dx[x] + dy[x] * dy[x]);
      point[x] = std::sqrt(ddx[x] * ddx[x] + ddy[x] * ddy[x]);
    }
  });
}

}  // namespace

FeatureResponse featureResponse(const std::vector<float>& luminance, int w, int h, double ppd) {
  std::vector<Plane> rows;
  FeatureResponse r;
  featureResponseInto(luminance, w, h, ppd, rows, r);
  return r;
}

namespace {

// What ꟻLIP needs of one image: its filtered Hunt-adjusted L*a*b* and its feature responses.
struct Prepared {
  std::array<Plane, 3> lab;
  FeatureResponse features;
};
// The planes of the intermediate steps, kept from one image (and exposure) to the next.
struct Workspace {
  Opponent opponent;
  std::vector<Plane> rows;
};
void prepare(const RgbImage& image, std::optional<float> exposureScale, double ppd, Workspace& work, Prepared& out) {
  toOpponent(image, exposureScale, work.opponent);
  featureResponseInto(work.opponent.luminance, image.width, image.height, ppd, work.rows, out.features);
  filteredHuntLab(work.opponent, image.width, image.height, ppd, work.rows, out.lab);
}

// [HPG20] Eqs. 5-6 per pixel, passed to combine(i, error).
template <typename Combine>
void pixelErrors(const Prepared& ref, const Prepared& test, Combine&& combine) {
  static_assert(kQf == 0.5, "the feature exponent is a square root below");
  const float cmax = static_cast<float>(maxColorDistance());
  const std::size_t n = ref.lab[0].size();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      const float dl = ref.lab[0][i] - test.lab[0][i], da = ref.lab[1][i] - test.lab[1][i], db = ref.lab[2][i] - test.lab[2][i];
      const float colour = remapColorErrorT(hyabT(dl, da, db), cmax);
      // Eq. 6: the feature difference, max of edge and point, over sqrt(2), to the q_f.
      const float edge = std::abs(ref.features.edge[i] - test.features.edge[i]);
      const float point = std::abs(ref.features.point[i] - test.features.point[i]);
      const float feature = std::sqrt(std::max(edge, point) / std::numbers::sqrt2_v<float>);
      combine(i, std::pow(colour, 1.0f - feature));  // Eq. 5
    }
  });
}

}  // namespace

std::vector<float> ldrFlip(const RgbImage& reference, const RgbImage& test, double ppd) {
  std::vector<float> error(reference.pixelCount());
  Workspace work;
  Prepared ref, tst;
  prepare(reference, std::nullopt, ppd, work, ref);
  prepare(test, std::nullopt, ppd, work, tst);
  pixelErrors(ref, tst, [&](std::size_t i, float e) { error[i] = e; });
  return error;
}

double acesToneMap(double x) { return acesToneMapT(x); }

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

struct HdrFlipReference::State {
  ExposureRange exposures;
  std::vector<float> scales;       // 2^exposure, one per exposure
  std::vector<Prepared> prepared;  // the reference at each exposure
  double ppd = 0.0;
};

HdrFlipReference::HdrFlipReference(const RgbImage& reference, double ppd) {
  auto state = std::make_shared<State>();
  state->exposures = hdrExposureRange(reference);
  state->ppd = ppd;
  const ExposureRange& r = state->exposures;
  Workspace work;
  state->prepared.resize(static_cast<std::size_t>(r.count));
  for (int e = 0; e < r.count; ++e) {
    const double exposure = r.start + e * (r.stop - r.start) / (r.count - 1);
    state->scales.push_back(static_cast<float>(std::exp2(exposure)));
    prepare(reference, state->scales.back(), ppd, work, state->prepared[static_cast<std::size_t>(e)]);
  }
  state_ = std::move(state);
}

HdrFlipResult HdrFlipReference::compare(const RgbImage& test) const {
  HdrFlipResult result;
  result.exposures = state_->exposures;
  result.error.assign(test.pixelCount(), 0.0f);
  Workspace work;
  Prepared tst;
  for (std::size_t e = 0; e < state_->prepared.size(); ++e) {
    prepare(test, state_->scales[e], state_->ppd, work, tst);
    // [EG21] Eq. 3: the per-pixel maximum over the exposures.
    pixelErrors(state_->prepared[e], tst, [&](std::size_t i, float error) { result.error[i] = std::max(result.error[i], error); });
  }
  return result;
}

HdrFlipResult hdrFlip(const RgbImage& reference, const RgbImage& test, double ppd) { return HdrFlipReference(reference, ppd).compare(test); }

Pooled pool(const std::vector<float>& error) {
  Pooled p;
  if (error.empty()) return p;
  std::vector<float> sorted = error;
  tbb::parallel_sort(sorted.begin(), sorted.end());  // the same order as std::sort: floats, no ties that differ
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
