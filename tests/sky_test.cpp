// The generated environment: Preetham sky and ESRA sun, checked against values worked out by hand,
// and the HDR file read back through OpenImageIO.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "convert/sky.h"
#include "core/image_io.h"
#include "core/math.h"
#include "gltf_builder.h"

namespace dynbench::convert {
namespace {

double luminance(const SkyImage& s, int row, int col) {
  const float* p = &s.rgb[(static_cast<std::size_t>(row) * s.width + col) * 3];
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];  // Rec.709 Y
}

TEST(Sky, ZenithLuminanceIsPreethamsFormula) {
  // T = 3, sun zenith 45 deg: chi = (4/9 - 3/120)(pi - pi/2) = 0.658862, tan chi = 0.774283,
  // Y_z = (4.0453*3 - 4.9710)*0.774283 - 0.2155*3 + 2.4192 = 7.32036 kcd/m^2.
  SkyParameters p;
  p.turbidity = 3.0;
  p.sunElevationDegrees = 45.0;
  const SkyImage s = preethamSky(p);
  EXPECT_NEAR(s.zenithLuminance, 7320.36, 0.05);
  // The top row is 0.18 degrees from the zenith: within 0.5 % of Y_z.
  for (int col = 0; col < s.width; col += 97) EXPECT_NEAR(luminance(s, 0, col) / s.zenithLuminance, 1.0, 0.005) << col;
}

TEST(Sky, SunIlluminanceIsTheEsraDirectBeam) {
  // Sun at the zenith: Kasten-Young air mass m = 0.99971, Rayleigh depth 1/(6.6296 + 1.7513m - ...)
  // = 0.120968, B_n = 1361 exp(-0.8662 * 3 * m * 0.120968) = 993.98 W/m^2, x 93 lm/W = 92 440 lux.
  SkyParameters p;
  p.turbidity = 3.0;
  p.sunElevationDegrees = 90.0;
  const SkyImage s = preethamSky(p);
  EXPECT_NEAR(s.sunIlluminanceLux, 92440.16, 0.5);
  // Hazier and lower suns give less.
  p.turbidity = 6.0;
  EXPECT_LT(preethamSky(p).sunIlluminanceLux, s.sunIlluminanceLux);
  p.turbidity = 3.0;
  p.sunElevationDegrees = 10.0;
  EXPECT_LT(preethamSky(p).sunIlluminanceLux, 0.7 * s.sunIlluminanceLux);
}

TEST(Sky, SunDiscCarriesTheSunsIlluminance) {
  SkyParameters p;
  p.sunElevationDegrees = 30.0;
  p.sunAzimuthDegrees = -60.0;
  const SkyImage s = preethamSky(p);
  // Disc pixels outshine any sky pixel a hundredfold; their luminance x solid angle adds up to the
  // sun's illuminance (plus the little sky under the disc).
  double sum = 0.0;
  glm::dvec3 brightest(0.0);
  double peak = 0.0;
  for (int row = 0; row < s.height; ++row)
    for (int col = 0; col < s.width; ++col) {
      const double y = luminance(s, row, col);
      if (y < 100.0 * s.zenithLuminance) continue;
      sum += y * equirectPixelSolidAngle(row, s.width, s.height);
      if (y > peak) {
        peak = y;
        brightest = equirectDirection((col + 0.5) / s.width, (row + 0.5) / s.height);
      }
    }
  EXPECT_NEAR(sum / s.sunIlluminanceLux, 1.0, 0.01);
  EXPECT_LT(degrees(std::acos(glm::dot(brightest, s.sunDirection))), 0.6);  // within about one pixel
  EXPECT_NEAR(degrees(std::asin(s.sunDirection.y)), 30.0, 1e-9);
}

TEST(Sky, SymmetricAboutTheSunsVerticalPlaneAndBrighterTowardsIt) {
  SkyParameters p;
  p.sunAzimuthDegrees = 0.0;  // the sun above -Z, the image centre column
  p.sunElevationDegrees = 40.0;
  const SkyImage s = preethamSky(p);
  const int row = s.height / 4;  // 45 degrees above the horizon
  for (int offset = 10; offset < s.width / 2; offset += 50) {
    const double left = luminance(s, row, s.width / 2 - 1 - offset), right = luminance(s, row, s.width / 2 + offset);
    EXPECT_NEAR(left / right, 1.0, 1e-5) << offset;
  }
  // Circumsolar brightening: towards the sun (centre) brighter than away from it (edge).
  EXPECT_GT(luminance(s, s.height / 3, s.width / 2), 1.5 * luminance(s, s.height / 3, 0));
}

TEST(Sky, EquirectMapping) {
  const glm::dvec3 centre = equirectDirection(0.5, 0.5);
  EXPECT_NEAR(centre.z, -1.0, 1e-12);  // u = 0.5 looks down -Z
  EXPECT_NEAR(equirectDirection(0.75, 0.5).x, 1.0, 1e-12);  // u grows towards +X
  EXPECT_NEAR(equirectDirection(0.3, 0.0).y, 1.0, 1e-12);   // top row: straight up
  // Solid angles of all pixels sum to the sphere.
  double total = 0.0;
  for (int row = 0; row < 64; ++row) total += 128 * equirectPixelSolidAngle(row, 128, 64);
  EXPECT_NEAR(total, 4.0 * kPi, 1e-9);
}

// sinCosSingle (the BSDF's sampled angles): single precision, widened.
TEST(Sky, SinCosSingleIsTheSinglePrecisionSineAndCosine) {
  for (const double angle : {0.0, 0.3, 1.0, 2.5, 4.0, 6.2}) {
    const SinCos s = sinCosSingle(angle);
    EXPECT_EQ(s.sin, static_cast<double>(static_cast<float>(s.sin)));  // a float, widened
    EXPECT_EQ(s.cos, static_cast<double>(static_cast<float>(s.cos)));
    EXPECT_NEAR(s.sin, std::sin(angle), 3e-7);
    EXPECT_NEAR(s.cos, std::cos(angle), 3e-7);
  }
  const SinCos quarter = sinCosSingle(kPi / 2);
  EXPECT_NEAR(quarter.sin, 1.0, 1e-7);
  EXPECT_NEAR(quarter.cos, 0.0, 1e-7);
}

TEST(Sky, HdrFileRoundTripsThroughOpenImageIO) {
  SkyParameters p;
  p.width = 256;
  const SkyImage s = preethamSky(p);
  const auto file = test::freshDir("sky_hdr") / "sky.hdr";
  ASSERT_TRUE(writeImage(file, FloatImage{s.width, s.height, 3, s.rgb}));
  auto back = readImage(file);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(back->width, 256);
  EXPECT_EQ(back->height, 128);
  ASSERT_EQ(back->channels, 3);
  // RGBE shares one exponent per pixel: each channel keeps 8 bits relative to the pixel's largest
  // channel, so the error is below 1/128 of that channel.
  for (std::size_t i = 0; i < s.rgb.size(); i += 331) {
    const std::size_t px = i / 3 * 3;
    const float largest = std::max({s.rgb[px], s.rgb[px + 1], s.rgb[px + 2]});
    EXPECT_NEAR(back->pixels[i], s.rgb[i], largest / 128.0f) << i;
  }
  auto header = readImageHeader(test::freshDir("sky_bad") / "missing.hdr");
  EXPECT_FALSE(header);
}

}  // namespace
}  // namespace dynbench::convert
