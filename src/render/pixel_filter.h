#pragma once
// The pixel reconstruction filter of `render --pixel-filter`: where in and around a pixel its
// radiance samples' camera rays go (docs/feature-buffers.md, "Radiance over the pixel").
//
// Filter importance sampling (Ernst et al. 2006; what Cycles does): each sample's offset from the
// pixel centre is drawn with a density proportional to the filter, so every sample has the same
// weight and the pixel's value is their plain mean. The mean then estimates the filtered radiance
// (integral of f(x - c) L(x) dx over the filter's support, f normalised), and the sample variance
// still gives the variance of that mean (the variance channels, adaptive sampling).
//
// Separable, as Cycles' is: the x and y offsets are drawn independently from the 1D filter.
//   box, width w:               f(v) = 1 on [-w/2, w/2]
//   Blackman-Harris, width w:   f(v) = 0.35875 - 0.48829 cos(s) + 0.14128 cos(2s) - 0.01168 cos(3s),
//                               s = 2 pi (v / (2w) + 1/2), on [-w, w]
// Width as Cycles' `filter_width` means it: Cycles' table doubles a Blackman-Harris width before
// evaluating the window, so its default 1.5 px reaches 1.5 px from the centre on each side.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"

namespace dynbench::render {

enum class PixelFilterType {
  kCentre,          // no filter: every sample through the pixel centre (radiance at the centre's hit)
  kBox,             // a box of `width` pixels
  kBlackmanHarris,  // Cycles' default (width 1.5)
};

struct PixelFilterSpec {
  PixelFilterType type = PixelFilterType::kBlackmanHarris;
  double width = 1.5;  // pixels; ignored by kCentre
};

// "centre", "box", "blackman-harris"
const char* pixelFilterName(PixelFilterType type);
Expected<PixelFilterType> parsePixelFilter(const std::string& name);
// 1.5 for Blackman-Harris (Cycles' default), 1 for a box (the pixel's own square), 0 for the centre.
double defaultPixelFilterWidth(PixelFilterType type);

// Where a pixel's radiance samples fall in [0, 1)^2 before the filter maps them to offsets: sample
// `sample`'s point of a (0,2)-sequence in base 2 (the first two dimensions of Sobol's sequence: the
// index's radical inverse, and its image under the Pascal matrix mod 2), shifted toroidally by the
// pixel's `shift` (Cranley-Patterson rotation). With a shift uniform in [0, 1)^2 each point is
// uniform, so the pixel's mean still estimates the filtered radiance without bias; and the first
// 2^k points of a pixel fall one in each elementary interval of area 2^-k, so the filter's spread
// over textures and edges averages out faster than with independent points (two_towers frame 108
// at 32 paths: the direct light's RMS difference between two seeds 23,500 -> 10,000 cd/m²).
glm::dvec2 stratifiedPoint(std::uint32_t sample, glm::dvec2 shift);

class PixelFilter {
 public:
  explicit PixelFilter(const PixelFilterSpec& spec);
  // The offset from the pixel centre, in pixels, of the sample drawn with uniforms u in [0, 1)^2.
  glm::dvec2 offset(glm::dvec2 u) const { return {sample1D(u.x), sample1D(u.y)}; }
  // The filter's unnormalised 1D weight at offset v (0 outside its support).
  double weight(double v) const;
  double radius() const { return radius_; }  // the support is [-radius, radius]
  bool atCentre() const { return spec_.type == PixelFilterType::kCentre; }
  const PixelFilterSpec& spec() const { return spec_; }

 private:
  double sample1D(double u) const;
  PixelFilterSpec spec_;
  double radius_ = 0.0;
  // Blackman-Harris: the CDF at kTable + 1 evenly spaced offsets over the support; a sample inverts
  // it by binary search and linear interpolation, i.e. samples the piecewise-linear CDF exactly
  // (its density is the filter averaged over each of the kTable cells).
  std::vector<double> cdf_;
  // guide_[b] = the binary search's answer for u = b / kGuideCells (b = 0 .. kGuideCells): the
  // answer for any u in [b, b + 1) / kGuideCells lies between guide_[b] and guide_[b + 1], so the
  // search runs over those few cells instead of all of them, with the same result (the CDF is
  // monotone; b / kGuideCells is exact for a power of two). Found by `perf`: the 12-step search
  // over 4,097 cells was 2.6 % of a demo frame.
  static constexpr int kGuideCells = 256;
  std::vector<std::uint32_t> guide_;
};

}  // namespace dynbench::render
