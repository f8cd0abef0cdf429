#pragma once
// The render camera: a scene camera at time t turned into primary rays and into the view and
// projection matrices of the feature-buffer contract (docs/feature-buffers.md).
//
// Conventions: pixel (px, py) covers [px, px+1) x [py, py+1), row 0 at the top; NDC x = 2 px / W - 1,
// y = 1 - 2 py / H; OpenGL-style right-handed view space (camera looks down -Z, +Y up) and clip
// space (depth -1 at znear, +1 at zfar). The image's width / height is the aspect ratio used,
// whatever the glTF camera's aspectRatio says (a renderer fills the image it is asked for).
#include <optional>

#include <glm/glm.hpp>

#include "core/error.h"
#include "frames/feature_frame.h"
#include "scene/scene.h"

namespace dynbench::render {

struct Ray {
  glm::dvec3 origin{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  // unit length
};

struct PixelProjection {
  glm::dvec2 pixel{0.0};  // continuous pixel coordinates (pixel centres at +0.5)
  double viewDepth = 0.0;  // distance along the viewing axis (-z in view space)
  bool inFront = false;    // in front of the camera
};

class RenderCamera {
 public:
  // The camera node's world matrix (scale removed) and the glTF camera's lens.
  RenderCamera(const glm::dmat4& world, const scene::Camera& lens, int width, int height);

  // The ray through a point of the image (pixel coordinates, e.g. px + 0.5 for a pixel centre).
  Ray ray(double px, double py) const;
  // Thesis Eq. (2.2)-(2.3): clip = P V p, NDC = clip / w, then to pixel coordinates.
  PixelProjection project(const glm::dvec3& world) const;

  const glm::dmat4& view() const { return view_; }
  const glm::dmat4& projection() const { return projection_; }
  const glm::dmat4& world() const { return world_; }
  glm::dvec3 position() const { return glm::dvec3(world_[3]); }
  int width() const { return width_; }
  int height() const { return height_; }
  double yfov() const { return lens_.yfov; }
  double znear() const { return lens_.znear; }
  double zfar() const { return zfarUsed_; }  // glTF's infinite far plane becomes 1e6 x znear
  // What a frame's sidecar records of this camera.
  frames::FrameCamera frameCamera() const;

 private:
  glm::dmat4 world_, view_, projection_;
  scene::Camera lens_;
  int width_, height_;
  double aspect_, tanHalf_, zfarUsed_;
};

}  // namespace dynbench::render
