#include "frames/preview.h"

#include <algorithm>

#include "core/math.h"

namespace dynbench::frames {
namespace {

glm::dvec3 radiance(const FeatureFrame& f, std::size_t i) {
  return glm::dvec3(f.direct[3 * i], f.direct[3 * i + 1], f.direct[3 * i + 2]) +
         glm::dvec3(f.indirect[3 * i], f.indirect[3 * i + 1], f.indirect[3 * i + 2]);
}

}  // namespace

PreviewToneMap::PreviewToneMap(const FeatureFrame& frame) {
  const std::size_t n = frame.pixelCount();
  double mean = 0;
  for (std::size_t i = 0; i < n; ++i) mean += luminance(radiance(frame, i));
  mean = std::max(mean / static_cast<double>(std::max<std::size_t>(n, 1)), 1e-12);
  exposure_ = 0.18 / mean;
}

glm::dvec3 PreviewToneMap::operator()(const FeatureFrame& frame, std::size_t pixel) const {
  glm::dvec3 c = radiance(frame, pixel) * exposure_;
  c = c / (1.0 + c);
  return glm::pow(glm::clamp(c, 0.0, 1.0), glm::dvec3(1.0 / 2.2));
}

std::vector<float> previewImage(const FeatureFrame& frame) { return previewImage(frame, PreviewToneMap(frame)); }

std::vector<float> previewImage(const FeatureFrame& frame, const PreviewToneMap& map) {
  std::vector<float> rgb(3 * frame.pixelCount());
  for (std::size_t i = 0; i < frame.pixelCount(); ++i) {
    const glm::dvec3 c = map(frame, i);
    for (int k = 0; k < 3; ++k) rgb[3 * i + static_cast<std::size_t>(k)] = static_cast<float>(c[k]);
  }
  return rgb;
}

}  // namespace dynbench::frames
