#include "render/pixel_filter.h"

#include <algorithm>
#include <cmath>

#include "core/math.h"

namespace dynbench::render {

glm::dvec2 stratifiedPoint(std::uint32_t sample, glm::dvec2 shift) {
  // Column k of the radical inverse is bit 31 - k; column k of the Pascal matrix mod 2 is
  // v_k = v_{k-1} xor (v_{k-1} >> 1) from v_0 = 2^31 (Sobol's second dimension).
  std::uint32_t x = 0, y = 0, column = 1u << 31;
  for (std::uint32_t i = sample, k = 0; i != 0; i >>= 1, ++k) {
    if (i & 1u) x ^= 1u << (31 - k), y ^= column;
    column ^= column >> 1;
  }
  return glm::fract(glm::dvec2(x * 0x1p-32, y * 0x1p-32) + shift);
}
namespace {

constexpr int kTable = 4096;

}  // namespace

const char* pixelFilterName(PixelFilterType type) {
  switch (type) {
    case PixelFilterType::kCentre: return "centre";
    case PixelFilterType::kBox: return "box";
    case PixelFilterType::kBlackmanHarris: return "blackman-harris";
  }
  return "?";
}

Expected<PixelFilterType> parsePixelFilter(const std::string& name) {
  for (const auto type : {PixelFilterType::kCentre, PixelFilterType::kBox, PixelFilterType::kBlackmanHarris})
    if (name == pixelFilterName(type)) return type;
  return fail(ErrorCode::kUsage, "--pixel-filter {}: expected centre, box or blackman-harris", name);
}

double defaultPixelFilterWidth(PixelFilterType type) {
  switch (type) {
    case PixelFilterType::kCentre: return 0.0;
    case PixelFilterType::kBox: return 1.0;
    case PixelFilterType::kBlackmanHarris: return 1.5;
  }
  return 0.0;
}

PixelFilter::PixelFilter(const PixelFilterSpec& spec) : spec_(spec) {
  switch (spec.type) {
    case PixelFilterType::kCentre: radius_ = 0.0; break;
    case PixelFilterType::kBox: radius_ = 0.5 * spec.width; break;
    case PixelFilterType::kBlackmanHarris: radius_ = spec.width; break;
  }
  if (spec.type != PixelFilterType::kBlackmanHarris) return;
  // The CDF by the trapezoidal rule on kTable cells (the window is smooth: the rule's error at
  // 4096 cells is far below a sample's float precision), normalised to end at 1.
  cdf_.assign(kTable + 1, 0.0);
  const double step = 2.0 * radius_ / kTable;
  for (int i = 1; i <= kTable; ++i) {
    const double a = -radius_ + (i - 1) * step, b = -radius_ + i * step;
    cdf_[static_cast<std::size_t>(i)] = cdf_[static_cast<std::size_t>(i - 1)] + 0.5 * step * (weight(a) + weight(b));
  }
  const double total = cdf_.back();
  for (double& c : cdf_) c /= total;
  guide_.resize(kGuideCells + 1);
  for (int b = 0; b <= kGuideCells; ++b)
    guide_[static_cast<std::size_t>(b)] = static_cast<std::uint32_t>(
        std::upper_bound(cdf_.begin(), cdf_.end(), static_cast<double>(b) / kGuideCells) - cdf_.begin());
}

double PixelFilter::weight(double v) const {
  switch (spec_.type) {
    case PixelFilterType::kCentre: return v == 0.0 ? 1.0 : 0.0;
    case PixelFilterType::kBox: return std::abs(v) <= radius_ ? 1.0 : 0.0;
    case PixelFilterType::kBlackmanHarris: {
      if (std::abs(v) > radius_) return 0.0;
      // Cycles' filter_func_blackman_harris(v, 2 width): the four-term window over [-width, width].
      const double s = 2.0 * kPi * (v / (2.0 * radius_) + 0.5);
      return std::max(0.0, 0.35875 - 0.48829 * std::cos(s) + 0.14128 * std::cos(2.0 * s) - 0.01168 * std::cos(3.0 * s));
    }
  }
  return 0.0;
}

double PixelFilter::sample1D(double u) const {
  switch (spec_.type) {
    case PixelFilterType::kCentre: return 0.0;
    case PixelFilterType::kBox: return (2.0 * u - 1.0) * radius_;
    case PixelFilterType::kBlackmanHarris: break;
  }
  // The cell whose CDF range holds u, then linear within it.
  const auto cell = static_cast<std::size_t>(std::clamp(std::floor(u * kGuideCells), 0.0, kGuideCells - 1.0));
  const auto it = std::upper_bound(cdf_.begin() + guide_[cell], cdf_.begin() + guide_[cell + 1], u);
  const auto i = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(it - cdf_.begin(), 1, kTable));
  const double lo = cdf_[i - 1], hi = cdf_[i];
  const double t = hi > lo ? (u - lo) / (hi - lo) : 0.5;
  const double step = 2.0 * radius_ / kTable;
  return -radius_ + (static_cast<double>(i - 1) + std::clamp(t, 0.0, 1.0)) * step;
}

}  // namespace dynbench::render
