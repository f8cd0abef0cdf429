#pragma once
// Preview tone mapping of a frame's radiance (direct + indirect), for thumbnails, discard masks and
// videos: Reinhard's global operator on colour, c / (1 + c), after scaling so that the frame's
// mean luminance maps to middle grey 0.18 (Reinhard et al. 2002, Eq. 2 with key a = 0.18, using the
// arithmetic rather than the log-average mean), then display gamma 1/2.2.
#include <vector>

#include <glm/glm.hpp>

#include "frames/feature_frame.h"

namespace dynbench::frames {

class PreviewToneMap {
 public:
  explicit PreviewToneMap(const FeatureFrame& frame);
  // A fixed exposure, e.g. one for every frame of a video, so that it does not flicker.
  explicit PreviewToneMap(double exposure) : exposure_(exposure) {}
  // Display RGB in [0, 1] of pixel i.
  glm::dvec3 operator()(const FeatureFrame& frame, std::size_t pixel) const;
  double exposure() const { return exposure_; }  // the scale applied to radiance

 private:
  double exposure_ = 1.0;
};

// The whole frame tone-mapped: 3 floats per pixel in [0, 1], row 0 at the top; with the frame's
// own exposure, or with `map`'s.
std::vector<float> previewImage(const FeatureFrame& frame);
std::vector<float> previewImage(const FeatureFrame& frame, const PreviewToneMap& map);

}  // namespace dynbench::frames
