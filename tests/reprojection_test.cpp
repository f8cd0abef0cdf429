// Reprojection (src/reprojection): bilinear taps and the projection of points and directions.
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include "core/math.h"
#include "render/camera.h"
#include "render_scenes.h"
#include "reprojection/reprojection.h"

namespace dynbench::reprojection {
namespace {

using render::yawCamera;

TEST(Reprojection, BilinearSamplingAtCentresEdgesAndCorners) {
  // A 3 x 2 image with value = 10 x column + row.
  std::vector<float> v{0, 10, 20, 1, 11, 21};
  auto at = [&](double x, double y) { return sample1(v, bilinearTaps(x, y, 3, 2)); };
  EXPECT_DOUBLE_EQ(at(0.5, 0.5), 0.0);   // pixel centres are exact
  EXPECT_DOUBLE_EQ(at(2.5, 1.5), 21.0);
  EXPECT_DOUBLE_EQ(at(1.0, 0.5), 5.0);   // half-way between two centres
  EXPECT_DOUBLE_EQ(at(1.5, 1.0), 10.5);
  EXPECT_DOUBLE_EQ(at(1.0, 1.0), 5.5);   // the middle of four
  EXPECT_DOUBLE_EQ(at(0.0, 0.0), 0.0);   // the image corner clamps to the corner pixel
  EXPECT_DOUBLE_EQ(at(3.0, 2.0), 21.0);
  EXPECT_DOUBLE_EQ(at(3.0, 1.0), 20.5);  // the right edge clamps horizontally, interpolates vertically
}

TEST(Reprojection, ReprojectionRoundTripsThroughThePixelDirection) {
  const auto cam = yawCamera(25.0, 320, 180, 40.0);
  const FrameCamera fc = cam.frameCamera();
  for (double x : {0.5, 100.25, 319.5})
    for (double y : {0.5, 90.0, 179.5}) {
      const auto q = reprojectDirection(fc, pixelDirection(fc, x, y));
      ASSERT_TRUE(q);
      EXPECT_NEAR(q->x, x, 1e-7);
      EXPECT_NEAR(q->y, y, 1e-7);
      const auto p = reproject(fc, cam.position() + 7.0 * pixelDirection(fc, x, y));
      ASSERT_TRUE(p);
      EXPECT_NEAR(p->x, x, 1e-7);
    }
}

}  // namespace
}  // namespace dynbench::reprojection
