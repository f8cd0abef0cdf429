#pragma once
// Reprojection (thesis Eqs. 2.2, 2.3): where a point of one frame lands in another frame's image,
// and how that frame's buffers are read there (bilinear and Catmull-Rom taps). Used by discard
// (Table 6.7) and by the temporal methods (evaluate), below both.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "frames/feature_frame.h"

namespace dynbench::reprojection {

using frames::FrameCamera;

// A bilinear sample of `channels` interleaved values at continuous pixel coordinates (x, y), pixel
// centres at +0.5, clamped at the image's edges. Also returns the weights of the four taps.
struct BilinearTaps {
  std::size_t index[4];
  double weight[4];
};
// The indices are into a buffer whose rows are `rowStride` apart from `origin` (a padded plane's);
// by default the image's own. Inline: SVGF's temporal pass calls it per pixel (issue 34).
inline BilinearTaps bilinearTaps(double x, double y, int width, int height, std::size_t rowStride = 0, std::size_t origin = 0) {
  // Texel space: pixel (i, j)'s centre is at (i + 0.5, j + 0.5).
  const double u = std::clamp(x - 0.5, 0.0, static_cast<double>(width - 1));
  const double v = std::clamp(y - 0.5, 0.0, static_cast<double>(height - 1));
  const int x0 = std::min(static_cast<int>(u), width - 1), y0 = std::min(static_cast<int>(v), height - 1);
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const double tx = u - x0, ty = v - y0;
  const std::size_t stride = rowStride ? rowStride : static_cast<std::size_t>(width);
  auto index = [&](int px, int py) { return origin + static_cast<std::size_t>(py) * stride + static_cast<std::size_t>(px); };
  return BilinearTaps{{index(x0, y0), index(x1, y0), index(x0, y1), index(x1, y1)},
                      {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty}};
}
// Pixel `index`'s value in a buffer of three interleaved channels (P, N, radiance).
inline glm::dvec3 at3(const std::vector<float>& buffer, std::size_t index) {
  return {buffer[3 * index], buffer[3 * index + 1], buffer[3 * index + 2]};
}
glm::dvec3 sample3(const std::vector<float>& buffer, const BilinearTaps& taps);
double sample1(const std::vector<float>& buffer, const BilinearTaps& taps);
// The Catmull-Rom cubic's 4 x 4 taps around continuous pixel coordinates (x, y) (Keys' a = -0.5,
// weights summing to 1, some negative), clamped at the image's edges; `inside` when none was.
struct CubicTaps {
  std::size_t index[16];
  double weight[16];
  bool inside;
};
CubicTaps catmullRomTaps(double x, double y, int width, int height);
glm::dvec3 sample3(const std::vector<float>& buffer, const CubicTaps& taps);

// A frame camera's projection x view and its inverse, multiplied once for the many points of a
// frame reprojected into it (reproject, reprojectDirection and pixelDirection below, which
// multiplied them for every pixel).
struct Projector {
  explicit Projector(const FrameCamera& camera);
  std::optional<glm::dvec2> point(const glm::dvec3& p) const;
  std::optional<glm::dvec2> direction(const glm::dvec3& direction) const;
  glm::dvec3 pixelDirection(double x, double y) const;
  glm::dmat4 viewProjection, inverseViewProjection;
  int width = 0, height = 0;
};

// Where world point p lands in a frame's image, in continuous pixel coordinates; nullopt behind
// the camera (clip w <= 0). Eq. (2.2) then perspective division and Eq. (2.3).
std::optional<glm::dvec2> reproject(const FrameCamera& camera, const glm::dvec3& p);
// The same for a direction (a point at infinity: the background).
std::optional<glm::dvec2> reprojectDirection(const FrameCamera& camera, const glm::dvec3& direction);
// The world direction of the ray through continuous pixel coordinates of a frame's camera.
glm::dvec3 pixelDirection(const FrameCamera& camera, double x, double y);

}  // namespace dynbench::reprojection
