// The render camera: rays and projection agree with each other and with hand-worked values.
#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"
#include "render/camera.h"

namespace dynbench::render {
namespace {

scene::Camera lens(double yfovDegrees) {
  scene::Camera c;
  c.yfov = radians(yfovDegrees);
  c.znear = 0.1;
  c.zfar = 100.0;
  return c;
}

TEST(RenderCamera, CentreRayLooksDownMinusZAndEdgesSpanTheFieldOfView) {
  const RenderCamera cam(glm::dmat4(1.0), lens(90.0), 200, 100);
  const Ray centre = cam.ray(100.0, 50.0);
  EXPECT_NEAR(centre.direction.z, -1.0, 1e-12);
  // Top edge of the image: 45 degrees up (yfov 90). Right edge: atan(2 x tan 45) horizontally.
  const Ray top = cam.ray(100.0, 0.0);
  EXPECT_NEAR(degrees(std::atan2(top.direction.y, -top.direction.z)), 45.0, 1e-9);
  const Ray right = cam.ray(200.0, 50.0);
  EXPECT_NEAR(std::atan2(right.direction.x, -right.direction.z), std::atan(2.0), 1e-9);
}

TEST(RenderCamera, ProjectingAPointOnARayGivesItsPixelBack) {
  glm::dmat4 world = glm::mat4_cast(quatFromYawPitchRoll(radians(30.0), radians(-10.0), radians(5.0)));
  world[3] = glm::dvec4(1, 2, 3, 1);
  const RenderCamera cam(world, lens(60.0), 320, 180);
  for (double px : {0.5, 17.25, 160.0, 319.5})
    for (double py : {0.5, 90.0, 179.5}) {
      const Ray r = cam.ray(px, py);
      const PixelProjection p = cam.project(r.origin + 7.0 * r.direction);
      EXPECT_TRUE(p.inFront);
      EXPECT_NEAR(p.pixel.x, px, 1e-7);
      EXPECT_NEAR(p.pixel.y, py, 1e-7);
    }
  // View depth of a point 5 units straight ahead.
  const glm::dvec3 ahead = cam.position() + 5.0 * glm::dvec3(glm::dmat3(cam.world()) * glm::dvec3(0, 0, -1));
  EXPECT_NEAR(cam.project(ahead).viewDepth, 5.0, 1e-9);
  EXPECT_FALSE(cam.project(cam.position() - (ahead - cam.position())).inFront);
}

TEST(RenderCamera, ScaleOnTheCameraNodeIsIgnored) {
  glm::dmat4 world(1.0);
  world[0] *= 3.0;
  world[1] *= 3.0;
  world[2] *= 3.0;
  const RenderCamera cam(world, lens(60.0), 100, 100);
  EXPECT_NEAR(cam.ray(50, 50).direction.z, -1.0, 1e-12);
  EXPECT_NEAR(cam.project({0, 0, -10}).pixel.x, 50.0, 1e-9);
}

TEST(RenderCamera, Orthographic) {
  scene::Camera c;
  c.type = scene::Camera::Type::kOrthographic;
  c.xmag = c.ymag = 2.0;
  c.znear = 0.1;
  c.zfar = 50.0;
  const RenderCamera cam(glm::dmat4(1.0), c, 100, 100);
  const Ray corner = cam.ray(0.0, 0.0);
  EXPECT_NEAR(corner.origin.x, -2.0, 1e-12);
  EXPECT_NEAR(corner.origin.y, 2.0, 1e-12);
  EXPECT_NEAR(corner.direction.z, -1.0, 1e-12);
  EXPECT_NEAR(cam.project({1.0, -1.0, -5.0}).pixel.x, 75.0, 1e-9);
  EXPECT_NEAR(cam.project({1.0, -1.0, -5.0}).pixel.y, 75.0, 1e-9);
}

}  // namespace
}  // namespace dynbench::render
