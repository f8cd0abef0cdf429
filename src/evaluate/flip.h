#pragma once
// ꟻLIP, the image difference evaluator of Andersson et al.:
//   [HPG20] "ꟻLIP: A Difference Evaluator for Alternating Images", HPG 2020 (LDR-ꟻLIP);
//   [EG21]  "Visualizing Errors in Rendered High Dynamic Range Images", Eurographics 2021 short
//           papers (HDR-ꟻLIP: exposure range, tone mapper, per-pixel maximum);
//   [RTG2]  "Visualizing and Communicating Errors in Rendered Images", Ray Tracing Gems II, ch. 19
//           (pooling: mean, weighted median and quartiles).
// No packaged implementation exists in Debian or npm, so it is written here from those papers;
// docs/metrics.md says how it was checked against the authors' own tool. Each step is a function
// of its own so that the tests can check it with answers worked by hand.
#include <memory>
#include <vector>

#include <glm/glm.hpp>

namespace dynbench::evaluate {

// An RGB image: 3 floats per pixel, row 0 at the top.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;
  std::size_t pixelCount() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
};

namespace flip {

// The authors' default viewing condition: a 0.7 m wide 3840-pixel display seen from 0.7 m,
// 0.7 x 3840 / 0.7 x pi / 180 = 67.02 pixels per degree.
double defaultPixelsPerDegree();

// Constants of [HPG20] §4-5: colour exponent q_c, break point p_c and its target p_t, feature
// width w (degrees) and feature exponent q_f.
inline constexpr double kQc = 0.7, kPc = 0.4, kPt = 0.95, kFeatureWidth = 0.082, kQf = 0.5;

// ---- the colour pipeline ([HPG20] §4.1) -----------------------------------------------------
// sRGB transfer function (IEC 61966-2-1), per channel.
glm::dvec3 srgbToLinear(glm::dvec3 srgb);
glm::dvec3 linearToSrgb(glm::dvec3 linear);
// Linear sRGB (D65) <-> CIE XYZ, Y = relative luminance (white (1,1,1) -> Y = 1).
glm::dvec3 linearRgbToXyz(glm::dvec3 rgb);
glm::dvec3 xyzToLinearRgb(glm::dvec3 xyz);
// The opponent space YCxCz of Zhang & Wandell's S-CIELAB, relative to the D65 white:
// Y = 116 y - 16, Cx = 500 (x - y), Cz = 200 (y - z) on white-normalised XYZ (CIELAB without its
// cube root, so that it is linear and can be filtered).
glm::dvec3 xyzToYcxcz(glm::dvec3 xyz);
glm::dvec3 ycxczToXyz(glm::dvec3 ycxcz);
// CIELAB (D65).
glm::dvec3 xyzToLab(glm::dvec3 xyz);
// Hunt-adjusted L*a*b*: a and b scaled by 0.01 L ([HPG20] Eq. 2), so that dark colours differ less.
glm::dvec3 huntAdjust(glm::dvec3 lab);
// HyAB distance |dL| + ||d(a, b)|| ([HPG20] Eq. 3).
double hyab(glm::dvec3 a, glm::dvec3 b);
// The largest Hunt-adjusted HyAB distance between two colours of the gamut, that of green (0,1,0)
// and blue (0,0,1), raised to q_c: c_max of [HPG20] Eq. 4.
double maxColorDistance();
// A HyAB distance to a colour error in [0, 1] ([HPG20] Eq. 4): d = hyab^q_c, then d < p_c c_max
// maps linearly to [0, p_t) and the rest linearly to [p_t, 1].
double remapColorError(double hyabDistance);

// ---- the feature detector ([HPG20] §4.2) -----------------------------------------------------
// Edge (first derivative of a Gaussian) and point (second derivative) responses of a luminance
// image, as magnitudes of the x and y responses. The Gaussian has sigma = w/2 degrees; each 1D
// kernel's positive weights sum to 1 and its negative weights to -1. Edges are clamped.
struct FeatureResponse {
  std::vector<float> edge, point;
};
FeatureResponse featureResponse(const std::vector<float>& luminance, int width, int height, double pixelsPerDegree);

// ---- LDR-ꟻLIP ---------------------------------------------------------------------------------
// Per-pixel error in [0, 1] of two images in linear RGB, clamped to [0, 1] (an LDR image already
// decoded from sRGB). [HPG20] Eq. 5: e = e_c ^ (1 - e_f).
std::vector<float> ldrFlip(const RgbImage& reference, const RgbImage& test, double pixelsPerDegree);

// ---- HDR-ꟻLIP ([EG21]) -------------------------------------------------------------------------
// The ACES filmic curve fitted by Narkowicz, with the authors' 0.6 pre-exposure folded in, per
// channel (not clamped).
double acesToneMap(double x);
// The exposures evaluated: from start (the reference's brightest luminance maps to where the tone
// mapper reaches 0.85) to stop (its median does), ceil(stop - start) of them, at least 2.
struct ExposureRange {
  double start = 0.0, stop = 0.0;  // stops (log2 of the scale applied to radiance)
  int count = 2;
  double xMax = 0.0;  // the radiance the tone mapper maps to 0.85
};
ExposureRange hdrExposureRange(const RgbImage& reference);
struct HdrFlipResult {
  std::vector<float> error;  // per pixel, the maximum of LDR-ꟻLIP over the exposures
  ExposureRange exposures;
};
HdrFlipResult hdrFlip(const RgbImage& reference, const RgbImage& test, double pixelsPerDegree);
// The reference's half of HDR-ꟻLIP, its exposure range and its filtered colours and features at
// every exposure, computed once for many test images (evaluate scores each method's output of a
// frame against one reference). compare(test) equals hdrFlip(reference, test, ppd).
class HdrFlipReference {
 public:
  HdrFlipReference(const RgbImage& reference, double pixelsPerDegree);
  HdrFlipResult compare(const RgbImage& test) const;

 private:
  struct State;
  std::shared_ptr<const State> state_;
};

// ---- pooling ([RTG2] §19.4) ------------------------------------------------------------------
// The mean (the authors' recommended single number), and the median and quartiles of the error
// weighted by itself (the value where the running sum of sorted errors passes 50 %, 25 %, 75 % of
// their total), which say where the visible error is.
struct Pooled {
  double mean = 0.0, weightedMedian = 0.0, weightedQ1 = 0.0, weightedQ3 = 0.0, max = 0.0;
};
Pooled pool(const std::vector<float>& error);

}  // namespace flip
}  // namespace dynbench::evaluate
