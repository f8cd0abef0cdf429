// The pixel reconstruction filter (render/pixel_filter.h) against closed forms: the
// Blackman-Harris window's integral, a box's, and the image of a straight emissive edge, whose
// every pixel is the share of the filter on the lit side.
#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"
#include "gltf_builder.h"
#include "render/path_tracer.h"
#include "render/pixel_filter.h"
#include "scene/load.h"

namespace dynbench::render {
namespace {

using nlohmann::json;

// The CDF of the Blackman-Harris window of half-width r, in closed form: with s = pi v / r + pi,
// the integral of a0 - a1 cos s + a2 cos 2s - a3 cos 3s from -r is
// (r / pi)(a0 s - a1 sin s + a2 sin 2s / 2 - a3 sin 3s / 3), and the whole window's is 2 r a0.
double blackmanHarrisCdf(double v, double r) {
  if (v <= -r) return 0.0;
  if (v >= r) return 1.0;
  const double a0 = 0.35875, a1 = 0.48829, a2 = 0.14128, a3 = 0.01168;
  const double s = kPi * v / r + kPi;
  return (a0 * s - a1 * std::sin(s) + a2 * std::sin(2 * s) / 2 - a3 * std::sin(3 * s) / 3) / (2 * kPi * a0);
}

TEST(PixelFilter, BlackmanHarrisOffsetsInvertTheWindowsClosedFormCdf) {
  for (const double width : {1.5, 2.0, 0.75}) {
    const PixelFilter filter({PixelFilterType::kBlackmanHarris, width});
    EXPECT_DOUBLE_EQ(filter.radius(), width);  // Cycles' filter_width: the reach on each side
    double largest = 0.0;
    for (int k = 0; k < 10000; ++k) {
      const double u = (k + 0.5) / 10000.0;
      const double v = filter.offset({u, u}).x;
      ASSERT_GE(v, -width);
      ASSERT_LE(v, width);
      largest = std::max(largest, std::abs(blackmanHarrisCdf(v, width) - u));
    }
    // The table's cells are 2 width / 4096 wide; within one the sampled CDF is linear, the true one
    // curved: their difference is far below a sample's statistical weight.
    EXPECT_LT(largest, 2e-6) << "width " << width;
    EXPECT_NEAR(filter.offset({0.5, 0.5}).x, 0.0, 1e-9);  // symmetric
    EXPECT_NEAR(filter.weight(0.0), 1.0, 1e-12);          // the window's peak
    EXPECT_LT(filter.weight(width * 0.999), 1e-4);        // and its feet
    EXPECT_EQ(filter.weight(width * 1.001), 0.0);
  }
}

TEST(PixelFilter, BoxOffsetsAreUniformOverItsWidthAndTheCentreHasNone) {
  const PixelFilter box({PixelFilterType::kBox, 1.0});
  EXPECT_DOUBLE_EQ(box.offset({0.0, 1.0}).x, -0.5);
  EXPECT_DOUBLE_EQ(box.offset({0.0, 1.0}).y, 0.5);
  EXPECT_DOUBLE_EQ(box.offset({0.25, 0.75}).x, -0.25);
  const PixelFilter centre({PixelFilterType::kCentre, 0.0});
  EXPECT_TRUE(centre.atCentre());
  EXPECT_EQ(centre.offset({0.1, 0.9}), glm::dvec2(0.0));
  EXPECT_FALSE(parsePixelFilter("gaussian"));
  EXPECT_EQ(*parsePixelFilter("blackman-harris"), PixelFilterType::kBlackmanHarris);
}

// An emissive half-plane x >= xEdge at z = -1 facing a camera at the origin that looks down -Z:
// its edge is a vertical line in the image. A pixel's filtered radiance is the share of the
// filter's x marginal on the lit side, 1 - CDF(edge - centre).
TEST(PixelFilter, AnEmissiveEdgeRendersAsTheFiltersShareOfEachPixel) {
  constexpr int kW = 16, kH = 8;
  constexpr double kYfov = 0.5;
  const double edgePixel = kW / 2 + 0.5 - 0.3;  // 0.3 px left of column 8's centre
  const double tanHalf = std::tan(kYfov / 2), aspect = static_cast<double>(kW) / kH;
  const auto xEdge = static_cast<float>((2.0 * edgePixel / kW - 1.0) * tanHalf * aspect);
  test::GltfBuilder b;
  b.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}}}, {"emissiveFactor", {1.0, 1.0, 1.0}}});
  const std::vector<float> p{xEdge, -5, -1, 5, -5, -1, 5, 5, -1, xEdge, 5, -1};
  b.doc["meshes"].push_back({{"primitives", json::array({{{"attributes", {{"POSITION", b.accessor(p, "VEC3")}}},
                                                            {"indices", b.indices({0, 1, 2, 0, 2, 3})},
                                                            {"material", 0}}})}});
  b.node({{"mesh", 0}});
  auto s = scene::loadScene(b.write(test::freshDir("pixel_filter_edge"), "edge"));
  ASSERT_TRUE(s) << s.error().message;
  scene::Camera lens;
  lens.yfov = kYfov;
  lens.znear = 0.01;
  const RenderCamera camera(glm::dmat4(1.0), lens, kW, kH);
  for (const auto& spec : {PixelFilterSpec{PixelFilterType::kBlackmanHarris, 1.5}, PixelFilterSpec{PixelFilterType::kBox, 1.0},
                           PixelFilterSpec{PixelFilterType::kCentre, 0.0}}) {
    RenderSettings settings;
    settings.width = kW, settings.height = kH;
    settings.samplesPerPixel = 4096;
    settings.bounces = 0;
    settings.useEnvironment = false;
    settings.pixelFilter = spec;
    std::vector<std::string> warnings;
    auto tracer = PathTracer::create(*s, settings, warnings);
    ASSERT_TRUE(tracer) << tracer.error().message;
    ASSERT_TRUE((*tracer)->setTime(0.0, 0.0));
    const FrameBuffers f = (*tracer)->render(0, camera, camera);
    const PixelFilter filter(spec);
    for (int x = 0; x < kW; ++x) {
      const double v = edgePixel - (x + 0.5);
      double expected = 0.0;
      switch (spec.type) {
        case PixelFilterType::kBlackmanHarris: expected = 1.0 - blackmanHarrisCdf(v, spec.width); break;
        case PixelFilterType::kBox: expected = std::clamp(0.5 - v, 0.0, 1.0); break;
        case PixelFilterType::kCentre: expected = v <= 0 ? 1.0 : 0.0; break;
      }
      double mean = 0.0, variance = 0.0;
      for (int y = 0; y < kH; ++y) {
        const std::size_t i = static_cast<std::size_t>(y * kW + x);
        mean += f.direct[3 * i] / kH;
        variance += f.directVariance[i] / (kH * kH);
      }
      // 5 standard errors of the column's mean (binomial: each sample sees the emitter or not).
      EXPECT_NEAR(mean, expected, 5.0 * std::sqrt(variance) + 1e-6) << pixelFilterName(spec.type) << " column " << x;
    }
    // The geometry buffers stay the centre's: a pixel is on the emitter exactly when its centre is.
    for (int x = 0; x < kW; ++x) EXPECT_EQ(f.hit[static_cast<std::size_t>(x)], x + 0.5 >= edgePixel ? 1.0f : 0.0f) << x;
  }
}

}  // namespace
}  // namespace dynbench::render

namespace dynbench::render {
namespace {

// stratifiedPoint is a (0,2)-sequence (unshifted): for every k up to 10, the first 2^k points put
// exactly one point in each elementary interval [i / 2^a, (i + 1) / 2^a) x [j / 2^b, (j + 1) / 2^b)
// with a + b = k (Niederreiter's definition), so no shape of cell of that area gets two; and the
// shift moves every point by the same amount, modulo 1.
TEST(PixelFilter, StratifiedPointsAreAZeroTwoSequenceShiftedTogether) {
  for (int k = 0; k <= 10; ++k) {
    const std::uint32_t n = 1u << k;
    for (int a = 0; a <= k; ++a) {
      const int b = k - a;
      std::vector<int> count(n, 0);
      for (std::uint32_t i = 0; i < n; ++i) {
        const glm::dvec2 p = stratifiedPoint(i, glm::dvec2(0.0));
        ASSERT_GE(p.x, 0.0);
        ASSERT_LT(p.x, 1.0);
        ASSERT_GE(p.y, 0.0);
        ASSERT_LT(p.y, 1.0);
        const auto cx = static_cast<std::uint32_t>(p.x * (1u << a)), cy = static_cast<std::uint32_t>(p.y * (1u << b));
        ++count[(cy << a) | cx];
      }
      for (std::uint32_t c = 0; c < n; ++c) ASSERT_EQ(count[c], 1) << "k " << k << ", a " << a << ", cell " << c;
    }
  }
  const glm::dvec2 shift(0.7, 0.45);
  for (std::uint32_t i = 0; i < 64; ++i) {
    const glm::dvec2 p = stratifiedPoint(i, glm::dvec2(0.0)), q = stratifiedPoint(i, shift);
    EXPECT_NEAR(q.x, std::fmod(p.x + shift.x, 1.0), 1e-15);
    EXPECT_NEAR(q.y, std::fmod(p.y + shift.y, 1.0), 1e-15);
  }
  // A few known points: 0, 1/2, then (1/4, 3/4), (3/4, 1/4).
  EXPECT_EQ(stratifiedPoint(0, glm::dvec2(0.0)), glm::dvec2(0.0, 0.0));
  EXPECT_EQ(stratifiedPoint(1, glm::dvec2(0.0)), glm::dvec2(0.5, 0.5));
  EXPECT_EQ(stratifiedPoint(2, glm::dvec2(0.0)), glm::dvec2(0.25, 0.75));
  EXPECT_EQ(stratifiedPoint(3, glm::dvec2(0.0)), glm::dvec2(0.75, 0.25));
}

}  // namespace
}  // namespace dynbench::render
