// Image metrics (evaluate/flip.h, evaluate/image_metrics.h, evaluate/compare.h): known answers
// worked by hand for each step of ꟻLIP, identities, and bad inputs.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include <gtest/gtest.h>

#include "core/image_io.h"
#include "evaluate/compare.h"
#include "evaluate/flip.h"
#include "evaluate/image_metrics.h"

namespace dynbench::evaluate {
namespace {

namespace fs = std::filesystem;

RgbImage constant(int w, int h, glm::vec3 c) {
  RgbImage img{w, h, {}};
  for (int i = 0; i < w * h; ++i) img.rgb.insert(img.rgb.end(), {c.r, c.g, c.b});
  return img;
}

fs::path scratch(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("dynbench_compare_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write(const fs::path& path, const RgbImage& img, std::vector<std::string> names = {}) {
  FloatImage f;
  f.width = img.width, f.height = img.height, f.channels = 3, f.pixels = img.rgb, f.channelNames = std::move(names);
  ASSERT_TRUE(writeImage(path, f).has_value()) << path;
}

TEST(Flip, ColourPipelineRoundTripsAndMatchesHandValues) {
  // sRGB 0.5 decodes to ((0.5 + 0.055) / 1.055)^2.4 = 0.2140411.
  EXPECT_NEAR(flip::srgbToLinear(glm::dvec3(0.5)).x, 0.2140411, 1e-7);
  // White is Y = 100, Cx = Cz = 0; mid grey's Y is 116 x 0.2140411 - 16 = 8.82877.
  const glm::dvec3 white = flip::xyzToYcxcz(flip::linearRgbToXyz(glm::dvec3(1.0)));
  EXPECT_NEAR(white.x, 100.0, 1e-9);
  EXPECT_NEAR(white.y, 0.0, 1e-9);
  EXPECT_NEAR(white.z, 0.0, 1e-9);
  EXPECT_NEAR(flip::xyzToYcxcz(flip::linearRgbToXyz(flip::srgbToLinear(glm::dvec3(0.5)))).x, 8.82877, 1e-4);
  // sRGB -> linear -> XYZ -> YCxCz -> XYZ -> linear -> sRGB gives back the colour.
  const glm::dvec3 colour(0.2, 0.5, 0.9);
  const glm::dvec3 back =
      flip::linearToSrgb(flip::xyzToLinearRgb(flip::ycxczToXyz(flip::xyzToYcxcz(flip::linearRgbToXyz(flip::srgbToLinear(colour))))));
  EXPECT_NEAR(glm::length(back - colour), 0.0, 1e-9);
  // The published CIELAB of sRGB red (D65): L 53.24, a 80.09, b 67.20.
  const glm::dvec3 red = flip::xyzToLab(flip::linearRgbToXyz({1, 0, 0}));
  EXPECT_NEAR(red.x, 53.24, 0.01);
  EXPECT_NEAR(red.y, 80.09, 0.01);
  EXPECT_NEAR(red.z, 67.20, 0.01);
  // The white's XYZ is the reciprocal of the authors' INV_DEFAULT_ILLUMINANT (FLIP.h: 1.052156925,
  // 1, 0.918357670): 0.9504285, 1, 1.0889004. The sRGB standard's seven-digit matrix gives
  // 0.9504559, 1.0000025, 1.0890578 instead, which moved every mean by about 1e-5 relative.
  const glm::dvec3 whiteXyz = flip::linearRgbToXyz(glm::dvec3(1.0));
  EXPECT_NEAR(whiteXyz.x, 1.0 / 1.052156925, 1e-7);  // (their constant is a float)
  EXPECT_NEAR(whiteXyz.y, 1.0, 1e-9);
  EXPECT_NEAR(whiteXyz.z, 1.0 / 0.918357670, 1e-7);
}

TEST(Flip, HuntAdjustedHyabOfConstantColoursMatchesHandValues) {
  // Red against black, by hand: Hunt's a = 0.01 x 53.237 x 80.090 = 42.638, b = 0.01 x 53.237 x
  // 67.203 = 35.777; HyAB = |53.237 - 0| + sqrt(42.638^2 + 35.777^2) = 53.237 + 55.660 = 108.897.
  const glm::dvec3 red = flip::huntAdjust(flip::xyzToLab(flip::linearRgbToXyz({1, 0, 0})));
  const glm::dvec3 black = flip::huntAdjust(flip::xyzToLab(flip::linearRgbToXyz({0, 0, 0})));
  EXPECT_NEAR(red.y, 42.638, 0.002);
  EXPECT_NEAR(red.z, 35.777, 0.002);
  EXPECT_NEAR(flip::hyab(red, black), 108.897, 0.002);
  // c_max from green (87.736, -75.612, 72.984) and blue (32.301, 25.581, -34.838) after Hunt:
  // 55.435 + sqrt(101.193^2 + 107.822^2) = 55.435 + 147.870 = 203.305; ^0.7 = 41.2766.
  EXPECT_NEAR(flip::maxColorDistance(), 41.2766, 1e-3);
  // Two constant images, red and black: the filters leave them constant and there are no
  // features, so every pixel's error is the remapped colour error: 108.897^0.7 = 26.663 is past
  // the break point 0.4 x 41.2766 = 16.511, so 0.95 + (26.663 - 16.511) / (41.277 - 16.511) x 0.05
  // = 0.97050.
  const std::vector<float> e = flip::ldrFlip(constant(24, 16, {1, 0, 0}), constant(24, 16, {0, 0, 0}), flip::defaultPixelsPerDegree());
  for (float v : e) ASSERT_NEAR(v, 0.97050, 2e-5);
}

TEST(Flip, ErrorRemappingIsContinuousAtItsBreakPoint) {
  const double cmax = flip::maxColorDistance(), breakHyab = std::pow(flip::kPc * cmax, 1.0 / flip::kQc);
  // At the break point both branches give p_t = 0.95.
  EXPECT_NEAR(flip::remapColorError(breakHyab), 0.95, 1e-12);
  EXPECT_NEAR(flip::remapColorError(breakHyab * (1 - 1e-9)), 0.95, 1e-7);
  // Half way to the break point (in d = hyab^q_c): 0.475; c_max itself: 1; beyond: clamped to 1.
  EXPECT_NEAR(flip::remapColorError(std::pow(0.5 * flip::kPc * cmax, 1.0 / flip::kQc)), 0.475, 1e-12);
  EXPECT_NEAR(flip::remapColorError(std::pow(cmax, 1.0 / flip::kQc)), 1.0, 1e-12);
  EXPECT_EQ(flip::remapColorError(1e6), 1.0);
  EXPECT_EQ(flip::remapColorError(0.0), 0.0);
}

TEST(Flip, FeatureDetectorAnswersOneToAUnitStep) {
  // A vertical step from 0 to 1 between columns 19 and 20. The first-derivative kernel's positive
  // weights sum to 1, so the two columns beside the step see all of one sign: edge = 1 there, and
  // 0 farther than the kernel's radius ceil(3 x 0.5 x 0.082 x 67.02) = 9 pixels.
  const int w = 40, h = 30;
  std::vector<float> step(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) step[y * w + x] = x >= 20 ? 1.0f : 0.0f;
  const flip::FeatureResponse r = flip::featureResponse(step, w, h, flip::defaultPixelsPerDegree());
  for (int y = 0; y < h; ++y) {
    EXPECT_NEAR(r.edge[y * w + 19], 1.0, 1e-5);
    EXPECT_NEAR(r.edge[y * w + 20], 1.0, 1e-5);
    EXPECT_LT(r.edge[y * w + 18], 1.0);
    EXPECT_NEAR(r.edge[y * w + 9], 0.0, 1e-6);
    EXPECT_NEAR(r.edge[y * w + 30], 0.0, 1e-6);
    // The point detector is odd about the step: the same magnitude on both sides.
    EXPECT_NEAR(r.point[y * w + 19], r.point[y * w + 20], 1e-5);
    EXPECT_GT(r.point[y * w + 19], 0.1);
    EXPECT_NEAR(r.point[y * w + 5], 0.0, 1e-6);
  }
}

TEST(Flip, HdrExposureRangeFollowsMaximumAndMedian) {
  // Grey pixels of luminance 1, 2, 4 and 16: maximum 16, median (the upper of an even count) 4.
  // x_max solves ACES(x) = 0.85, by hand the positive root of 0.16002 x^2 - 0.28290 x - 0.119 = 0:
  // 2.11887. start = log2(2.11887 / 16) = -2.91670, stop = log2(2.11887 / 4) = -0.91670, and
  // ceil(stop - start) = 2 exposures.
  RgbImage img{4, 1, {1, 1, 1, 2, 2, 2, 4, 4, 4, 16, 16, 16}};
  const flip::ExposureRange r = flip::hdrExposureRange(img);
  EXPECT_NEAR(r.xMax, 2.11887, 1e-5);
  EXPECT_NEAR(flip::acesToneMap(r.xMax), 0.85, 1e-12);
  EXPECT_NEAR(r.start, -2.91670, 1e-5);
  EXPECT_NEAR(r.stop, -0.91670, 1e-5);
  EXPECT_EQ(r.count, 2);
  // ACES at 0 is 0 and saturates towards 2.51 / 2.43 > 1 (clamped by HDR-ꟻLIP).
  EXPECT_EQ(flip::acesToneMap(0.0), 0.0);
  EXPECT_NEAR(flip::acesToneMap(1e9), 2.51 / 2.43, 1e-6);
}

TEST(Compare, IdenticalImagesScoreZeroErrorAndPerfectSimilarity) {
  RgbImage img = constant(32, 24, {0.3f, 0.6f, 0.1f});
  for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] *= static_cast<float>(1 + (i * 7919 % 13));  // texture, HDR values
  for (bool hdr : {true, false}) {
    RgbImage in = img;
    if (!hdr)
      for (float& v : in.rgb) v = std::min(v / 13.0f, 1.0f);
    const ScoredImage s = scoreImage(in, in, hdr, flip::defaultPixelsPerDegree());
    EXPECT_EQ(s.scores.flip.mean, 0.0);
    EXPECT_EQ(s.scores.flip.max, 0.0);
    EXPECT_EQ(s.scores.relMse, 0.0);
    EXPECT_EQ(s.scores.smape, 0.0);
    EXPECT_TRUE(std::isinf(s.scores.psnr));
    ASSERT_TRUE(s.scores.ssim.has_value());
    EXPECT_NEAR(*s.scores.ssim, 1.0, 1e-12);
  }
}

TEST(Compare, KnownAnswersOfPsnrRelMseSmapeAndPooling) {
  // Display values 0.5 against 0.6: MSE 0.01, PSNR 20 dB.
  EXPECT_NEAR(psnr(constant(4, 4, glm::vec3(0.5f)), constant(4, 4, glm::vec3(0.6f))), 20.0, 1e-5);
  // Linear 1 against 2: relMSE 1 / (1 + 0.01), SMAPE 1 / (3 + 0.01).
  EXPECT_NEAR(relMse(constant(2, 2, glm::vec3(1)), constant(2, 2, glm::vec3(2))), 1.0 / 1.01, 1e-9);
  EXPECT_NEAR(smape(constant(2, 2, glm::vec3(1)), constant(2, 2, glm::vec3(2))), 1.0 / 3.01, 1e-9);
  // SSIM of a constant shift c on flat images: (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1).
  const double a = 0.5, b = 0.6, c1 = 1e-4;
  EXPECT_NEAR(*ssim(constant(16, 16, glm::vec3(0.5f)), constant(16, 16, glm::vec3(0.6f))), (2 * a * b + c1) / (a * a + b * b + c1), 1e-6);
  EXPECT_FALSE(ssim(constant(10, 16, glm::vec3(0.5f)), constant(10, 16, glm::vec3(0.5f))).has_value());
  // Weighted pooling: errors 0.1, 0.2, 0.3, 0.4 (sum 1) have running sums 0.1, 0.3, 0.6, 1.0, which
  // first exceed 0.25 at 0.2, 0.5 at 0.3 and 0.75 at 0.4.
  const flip::Pooled p = flip::pool({0.3f, 0.1f, 0.4f, 0.2f});
  EXPECT_NEAR(p.mean, 0.25, 1e-7);
  EXPECT_NEAR(p.weightedQ1, 0.2, 1e-7);
  EXPECT_NEAR(p.weightedMedian, 0.3, 1e-7);
  EXPECT_NEAR(p.weightedQ3, 0.4, 1e-7);
  EXPECT_NEAR(p.max, 0.4, 1e-7);
}

TEST(Compare, WritesJsonAndMagmaHeatmapsThroughTheCommand) {
  const fs::path dir = scratch("files");
  RgbImage ref = constant(32, 24, {0.5f, 0.5f, 0.5f}), test = ref;
  for (int y = 6; y < 18; ++y)
    for (int x = 8; x < 24; ++x)
      for (int k = 0; k < 3; ++k) test.rgb[3 * (y * 32 + x) + k] = 0.0f;  // a black block on grey
  write(dir / "ref.exr", ref), write(dir / "test.exr", test), write(dir / "same.exr", ref);
  CompareOptions o;
  o.reference = dir / "ref.exr", o.tests = {dir / "test.exr", dir / "same.exr"}, o.json = dir / "s.json", o.heatmapDir = dir / "heat";
  auto r = runCompare(o);
  ASSERT_TRUE(r.has_value()) << r.error().message;
  ASSERT_EQ(r->scores.size(), 2u);
  EXPECT_GT(r->scores[0].flip.mean, 0.0);
  EXPECT_TRUE(r->scores[0].hdr);
  EXPECT_EQ(r->scores[1].flip.mean, 0.0);
  auto heat = readImage(dir / "heat" / "flip_test.png");
  ASSERT_TRUE(heat.has_value());
  // Error 0 is magma's first colour (almost black); the block is bright.
  const glm::vec3 zero = magmaColour(0.0f);
  EXPECT_NEAR(heat->pixels[0], zero.r, 1.0 / 255);
  EXPECT_NEAR(heat->pixels[2], zero.b, 1.0 / 255);
  EXPECT_GT(heat->pixels[3 * (12 * 32 + 15)], 0.5f);
}

TEST(Compare, BadInputsGiveClearErrors) {
  const fs::path dir = scratch("bad");
  write(dir / "ref.exr", constant(16, 16, glm::vec3(0.5f)));
  write(dir / "small.exr", constant(8, 16, glm::vec3(0.5f)));
  write(dir / "names.exr", constant(16, 16, glm::vec3(0.5f)), {"X", "Y", "Z"});
  RgbImage nan = constant(16, 16, glm::vec3(0.5f));
  nan.rgb[3 * (2 * 16 + 5) + 1] = std::numeric_limits<float>::quiet_NaN();
  write(dir / "nan.exr", nan);
  {
    std::ofstream junk(dir / "junk.exr");
    junk << "not an image";
  }
  auto expectError = [&](const std::string& test, const std::string& fragment) {
    CompareOptions o;
    o.reference = dir / "ref.exr", o.tests = {dir / test};
    auto r = runCompare(o);
    ASSERT_FALSE(r.has_value()) << test;
    EXPECT_NE(r.error().message.find(fragment), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(test), std::string::npos) << r.error().message;
  };
  expectError("small.exr", "8x16 pixels, but the reference");
  expectError("names.exr", "no channel R");
  expectError("nan.exr", "pixel (5, 2) channel G is nan");
  expectError("junk.exr", "junk.exr");
  expectError("missing.exr", "missing.exr");
}

}  // namespace
}  // namespace dynbench::evaluate
