#include "render/camera.h"

#include <cmath>

#include "core/math.h"

namespace dynbench::render {

RenderCamera::RenderCamera(const glm::dmat4& world, const scene::Camera& lens, int width, int height)
    : lens_(lens), width_(width), height_(height) {
  const RigidPose pose = decomposeRigid(world);
  world_ = glm::mat4_cast(pose.rotation);
  world_[3] = glm::dvec4(pose.position, 1.0);
  view_ = glm::inverse(world_);
  aspect_ = static_cast<double>(width) / height;
  tanHalf_ = std::tan(lens.yfov / 2.0);
  zfarUsed_ = lens.zfar > lens.znear ? lens.zfar : lens.znear * 1e6;
  const double n = lens.znear, f = zfarUsed_;
  projection_ = glm::dmat4(0.0);
  if (lens.type == scene::Camera::Type::kPerspective) {
    // glTF 2.0 §3.10.3 perspective projection (OpenGL conventions).
    projection_[0][0] = 1.0 / (aspect_ * tanHalf_);
    projection_[1][1] = 1.0 / tanHalf_;
    projection_[2][2] = (f + n) / (n - f);
    projection_[2][3] = -1.0;
    projection_[3][2] = 2.0 * f * n / (n - f);
  } else {
    // Orthographic: the image spans ±ymag vertically and ±ymag·aspect horizontally.
    projection_[0][0] = 1.0 / (lens.ymag * aspect_);
    projection_[1][1] = 1.0 / lens.ymag;
    projection_[2][2] = 2.0 / (n - f);
    projection_[3][2] = (f + n) / (n - f);
    projection_[3][3] = 1.0;
  }
}

Ray RenderCamera::ray(double px, double py) const {
  const double x = 2.0 * px / width_ - 1.0, y = 1.0 - 2.0 * py / height_;
  const glm::dmat3 rotation(world_);
  Ray r;
  if (lens_.type == scene::Camera::Type::kPerspective) {
    r.origin = position();
    r.direction = glm::normalize(rotation * glm::dvec3(x * aspect_ * tanHalf_, y * tanHalf_, -1.0));
  } else {
    r.origin = position() + rotation * glm::dvec3(x * lens_.ymag * aspect_, y * lens_.ymag, 0.0);
    r.direction = rotation * glm::dvec3(0.0, 0.0, -1.0);
  }
  return r;
}

PixelProjection RenderCamera::project(const glm::dvec3& world) const {
  const glm::dvec4 viewPoint = view_ * glm::dvec4(world, 1.0);
  const glm::dvec4 clip = projection_ * viewPoint;
  PixelProjection p;
  p.viewDepth = -viewPoint.z;
  p.inFront = p.viewDepth > 0.0;
  if (clip.w == 0.0) return p;
  const glm::dvec3 ndc = glm::dvec3(clip) / clip.w;
  p.pixel = {(ndc.x + 1.0) * 0.5 * width_, (1.0 - ndc.y) * 0.5 * height_};
  return p;
}

frames::FrameCamera RenderCamera::frameCamera() const {
  frames::FrameCamera c;
  c.world = world_;
  c.view = view_;
  c.projection = projection_;
  c.position = position();
  c.yfov = yfov();
  c.znear = znear();
  c.zfar = zfar();
  c.width = width_;
  c.height = height_;
  return c;
}

}  // namespace dynbench::render
