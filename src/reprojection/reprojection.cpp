#include "reprojection/reprojection.h"

#include <cmath>
#include <iterator>

#include "core/math.h"

namespace dynbench::reprojection {
namespace {

// Sum of weight x value over a set of taps (bilinear or cubic).
template <typename Taps>
glm::dvec3 weightedSum3(const std::vector<float>& buffer, const Taps& taps) {
  glm::dvec3 s(0.0);
  for (std::size_t k = 0; k < std::size(taps.weight); ++k) s += taps.weight[k] * at3(buffer, taps.index[k]);
  return s;
}

}  // namespace

glm::dvec3 sample3(const std::vector<float>& buffer, const BilinearTaps& taps) { return weightedSum3(buffer, taps); }
glm::dvec3 sample3(const std::vector<float>& buffer, const CubicTaps& taps) { return weightedSum3(buffer, taps); }

CubicTaps catmullRomTaps(double x, double y, int width, int height) {
  // Texel space: pixel (i, j)'s centre at (i + 0.5, j + 0.5); the taps are the 4 x 4 centres
  // around, the first one pixel left of and above the bilinear cell's.
  const double u = x - 0.5, v = y - 0.5;
  const double fx = std::floor(u), fy = std::floor(v);
  const auto wx = catmullRomWeights(u - fx), wy = catmullRomWeights(v - fy);
  const int x0 = static_cast<int>(fx) - 1, y0 = static_cast<int>(fy) - 1;
  CubicTaps taps{};
  taps.inside = x0 >= 0 && y0 >= 0 && x0 + 3 < width && y0 + 3 < height;
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) {
      const auto tap = static_cast<std::size_t>(4 * j + k);
      taps.index[tap] = static_cast<std::size_t>(std::clamp(y0 + j, 0, height - 1)) * static_cast<std::size_t>(width) +
                        static_cast<std::size_t>(std::clamp(x0 + k, 0, width - 1));
      taps.weight[tap] = wx[static_cast<std::size_t>(k)] * wy[static_cast<std::size_t>(j)];
    }
  return taps;
}

double sample1(const std::vector<float>& buffer, const BilinearTaps& taps) {
  double s = 0;
  for (int k = 0; k < 4; ++k) s += taps.weight[k] * buffer[taps.index[k]];
  return s;
}

namespace {

// Clip coordinates to continuous pixel coordinates: perspective division and Eq. (2.3), row 0 at
// the top; nullopt behind the camera (clip w <= 0).
std::optional<glm::dvec2> toPixels(const glm::dvec4& clip, int width, int height) {
  if (clip.w <= 0) return std::nullopt;
  const glm::dvec2 ndc(clip.x / clip.w, clip.y / clip.w);
  return glm::dvec2((ndc.x + 1.0) * 0.5 * width, (1.0 - ndc.y) * 0.5 * height);
}

}  // namespace

Projector::Projector(const FrameCamera& camera)
    : viewProjection(camera.projection * camera.view), inverseViewProjection(glm::inverse(viewProjection)), width(camera.width), height(camera.height) {}

std::optional<glm::dvec2> Projector::point(const glm::dvec3& p) const { return toPixels(viewProjection * glm::dvec4(p, 1.0), width, height); }  // Eq. (2.2)

std::optional<glm::dvec2> Projector::direction(const glm::dvec3& d) const { return toPixels(viewProjection * glm::dvec4(d, 0.0), width, height); }

glm::dvec3 Projector::pixelDirection(double x, double y) const {
  // The direction from the near to the far plane through the pixel coordinates.
  const glm::dvec2 ndc(2.0 * x / width - 1.0, 1.0 - 2.0 * y / height);
  const glm::dvec4 near = inverseViewProjection * glm::dvec4(ndc, -1.0, 1.0), far = inverseViewProjection * glm::dvec4(ndc, 1.0, 1.0);
  return glm::normalize(glm::dvec3(far) / far.w - glm::dvec3(near) / near.w);
}

std::optional<glm::dvec2> reproject(const FrameCamera& camera, const glm::dvec3& p) { return Projector(camera).point(p); }

std::optional<glm::dvec2> reprojectDirection(const FrameCamera& camera, const glm::dvec3& direction) {
  return Projector(camera).direction(direction);
}

glm::dvec3 pixelDirection(const FrameCamera& camera, double x, double y) { return Projector(camera).pixelDirection(x, y); }

}  // namespace dynbench::reprojection
