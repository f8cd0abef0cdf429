// The renderer's parts against known answers and their scalar twins: sampling distributions
// (2D tables, GGX, the environment), the batched BSDF and environment mapping lane by lane, and
// texture mip levels with the ray-cone level of detail.
#include <cmath>

#include <gtest/gtest.h>

#include "core/image_io.h"
#include "core/math.h"
#include "gltf_builder.h"
#include "render/bsdf.h"
#include "render/bsdf_batch.h"
#include "render/equirect_batch.h"
#include "render/lights.h"
#include "render/sampling.h"
#include "render/textures.h"

namespace dynbench::render {
namespace {

namespace fs = std::filesystem;

TEST(Sampling, Distribution2DDensityMatchesItsSamples) {
  // Weights 1..6 on a 3 x 2 grid: the density of a cell is weight / mean weight.
  const std::vector<double> weights{1, 2, 3, 4, 5, 6};
  const Distribution2D d(weights, 3, 2);
  for (int k = 0; k < 6; ++k)
    EXPECT_NEAR(d.density({(k % 3 + 0.5) / 3, (k / 3 + 0.5) / 2}), weights[static_cast<std::size_t>(k)] / 3.5, 1e-12);
  Random rng(1, 0, 0, 0);
  std::vector<int> counts(6, 0);
  for (int i = 0; i < 210000; ++i) {
    double density = 0;
    const glm::dvec2 p = d.sample(rng.uniform2(), &density);
    const int cell = static_cast<int>(p.y * 2) * 3 + static_cast<int>(p.x * 3);
    ++counts[static_cast<std::size_t>(cell)];
    ASSERT_NEAR(density, d.density(p), 1e-12);
  }
  for (int k = 0; k < 6; ++k) {
    const double expected = 210000.0 * (k + 1) / 21.0;  // binomial: sigma = sqrt(n p (1 - p))
    EXPECT_NEAR(counts[static_cast<std::size_t>(k)], expected, 5 * std::sqrt(expected));
  }
}

TEST(Sampling, Distribution2DNeverPicksARowOrCellOfNoWeight) {
  // A 4 x 3 grid whose middle row has no usable weight (zero, negative, NaN, infinity) and whose
  // other rows each have one empty cell: the rows' column tables share one array, and a row the
  // row table cannot pick keeps default slots; no sample may land in it or in an empty cell.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<double> weights{1, 0, 2, 3, 0, -1, nan, inf, 4, 4, 0, 8};
  const Distribution2D d(weights, 4, 3);
  const std::vector<double> used{1, 0, 2, 3, 0, 0, 0, 0, 4, 4, 0, 8};  // as the distribution reads them
  const double mean = 22.0 / 12;
  Random rng(7, 0, 0, 0);
  std::vector<int> counts(12, 0);
  const int n = 220000;
  for (int i = 0; i < n; ++i) {
    std::size_t cell = 0;
    const glm::dvec2 p = d.sampleCell(rng.uniform2(), &cell);
    ASSERT_EQ(cell, static_cast<std::size_t>(p.y * 3) * 4 + static_cast<std::size_t>(p.x * 4));
    ASSERT_GT(used[cell], 0.0) << "cell " << cell;
    ++counts[cell];
  }
  for (std::size_t k = 0; k < 12; ++k) {
    EXPECT_NEAR(d.density({(k % 4 + 0.5) / 4, (k / 4 + 0.5) / 3}), used[k] / mean, 1e-12) << k;
    const double expected = n * used[k] / 22.0;
    EXPECT_NEAR(counts[k], expected, 5 * std::sqrt(expected) + 1e-9) << k;
  }
}

TEST(Sampling, GgxIsNormalisedAndItsSamplingPdfIntegratesToOne) {
  for (double alpha : {0.05, 0.3, 1.0}) {
    // Projected-area normalisation: integral of D(h) cos(theta_h) over the hemisphere = 1.
    double integral = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) {
      const double theta = (i + 0.5) / n * kPi / 2;
      integral += Bsdf::ggxD({std::sin(theta), 0, std::cos(theta)}, alpha) * std::cos(theta) * std::sin(theta) * (kPi / 2 / n) * 2 * kPi;
    }
    EXPECT_NEAR(integral, 1.0, 2e-3) << "alpha " << alpha;
  }
  // A rough metal BSDF: the estimate of integral of pdf over sampled directions, E[1/pdf * pdf]
  // is trivial, so test the other way: E[f cos / pdf] equals the same integral by uniform sampling.
  SurfaceMaterial m;
  m.baseColor = glm::dvec3(0.9);
  m.metallic = 0.5;
  m.roughness = 0.4;
  const Frame frame(glm::dvec3(0, 0, 1));
  const Bsdf bsdf(m, frame, glm::dvec3(0, 0, 1));
  const glm::dvec3 wo = glm::normalize(glm::dvec3(0.5, 0.2, 0.8));
  Random rng(3, 0, 0, 0);
  double importance = 0, uniform = 0, pdfIntegral = 0;
  int accepted = 0;
  const int n = 400000;
  for (int i = 0; i < n; ++i) {
    if (const auto s = bsdf.sample(wo, rng.uniform2(), rng.uniform())) {
      ++accepted;
      importance += luminance(s->value) * s->direction.z / s->pdf;
      EXPECT_NEAR(s->pdf, bsdf.pdf(wo, s->direction), 1e-9 * s->pdf);
    }
    const glm::dvec2 u = rng.uniform2();  // uniform hemisphere, pdf 1 / (2 pi)
    const double z = u.x, r = std::sqrt(1 - z * z);
    const glm::dvec3 wi(r * std::cos(2 * kPi * u.y), r * std::sin(2 * kPi * u.y), z);
    uniform += luminance(bsdf.eval(wo, wi)) * z * 2 * kPi;
    pdfIntegral += bsdf.pdf(wo, wi) * 2 * kPi;
  }
  EXPECT_NEAR(importance / n, uniform / n, 0.01);
  // Reflected microfacet samples that point below the surface are rejected, so the pdf over the
  // hemisphere integrates to the fraction of samples that succeed (just under 1).
  EXPECT_NEAR(pdfIntegral / n, double(accepted) / n, 0.01);
  EXPECT_GT(double(accepted) / n, 0.9);
  EXPECT_LT(importance / n, 1.0);           // no energy gain
}

// The SIMD batch computes what the scalar Bsdf computes, lane by lane, over random materials
// (metals, dielectrics, mirrors, coloured specular), shading frames tilted from the geometric
// normal, views from both sides and directions anywhere on the sphere: the same zeros (below the
// surface, no sample) and values within rounding (its sine and cosine are double, Bsdf's single).
TEST(BsdfBatch, EveryLaneComputesWhatTheScalarBsdfComputes) {
  Random rng(11, 0, 0, 0);
  auto unit = [&] {
    const glm::dvec2 u = rng.uniform2();
    const double z = 1 - 2 * u.x, r = std::sqrt(std::max(0.0, 1 - z * z));
    return glm::dvec3(r * std::cos(2 * kPi * u.y), r * std::sin(2 * kPi * u.y), z);
  };
  constexpr std::size_t kLanes = 37;  // not a whole number of vectors
  BsdfBatch batch;
  batch.reserve(kLanes);
  int evaluations = 0, samples = 0, agreedZero = 0;
  for (int round = 0; round < 400; ++round) {
    std::vector<Bsdf> bsdfs;
    std::vector<Bsdf::View> views;
    std::vector<glm::dvec3> wis;
    std::vector<glm::dvec2> us;
    std::vector<double> lobes;
    for (std::size_t k = 0; k < kLanes; ++k) {
      SurfaceMaterial m;
      m.baseColor = glm::dvec3(rng.uniform(), rng.uniform(), rng.uniform());
      m.metallic = rng.uniform() < 0.3 ? std::round(rng.uniform()) : rng.uniform();
      m.roughness = rng.uniform() < 0.1 ? 0.0 : rng.uniform();
      m.specular = rng.uniform();
      m.specularColor = glm::dvec3(rng.uniform(), 1.0, 2 * rng.uniform());
      // Shading normals anywhere (the frame's two branches, n.z of either sign), geometric normals
      // tilted from them, views mostly in front.
      const glm::dvec3 n = unit();
      const glm::dvec3 ng = glm::normalize(n + 0.3 * unit());
      const glm::dvec3 wo = glm::normalize(unit() + 0.5 * n);
      bsdfs.emplace_back(m, Frame(n), ng);
      views.push_back(bsdfs.back().view(wo));
      wis.push_back(unit());
      us.push_back(rng.uniform2());
      lobes.push_back(rng.uniform());
      batch.set(k, m, n, ng, wo);
      if (k % 5 == 4) batch.clearEvaluation(k);
      else batch.setEvaluation(k, wis.back());
      batch.setSample(k, us.back(), lobes.back());
    }
    batch.run(kLanes);
    for (std::size_t k = 0; k < kLanes; ++k) {
      const Bsdf::Evaluation expected = k % 5 == 4 ? Bsdf::Evaluation{} : bsdfs[k].evaluate(views[k], wis[k]);
      const Bsdf::Evaluation got = batch.evaluation(k);
      EXPECT_NEAR(got.pdf, expected.pdf, 1e-9 * (1 + expected.pdf)) << "lane " << k;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got.value[c], expected.value[c], 1e-9 * (1 + expected.value[c])) << "lane " << k;
      evaluations += expected.pdf > 0;
      BsdfSample expectedSample, gotSample;
      const bool expectedOk = bsdfs[k].sample(views[k], us[k], lobes[k], expectedSample);
      const bool gotOk = batch.sample(k, gotSample);
      // A sample exactly at the horizon may go either way within rounding.
      if (expectedOk != gotOk) {
        EXPECT_LT(std::min(expectedOk ? expectedSample.pdf : gotSample.pdf, 1.0), 1e-5) << "lane " << k;
        continue;
      }
      if (!expectedOk) {
        ++agreedZero;
        continue;
      }
      ++samples;
      // Bsdf's sine and cosine are single precision (sinCosSingle), the batch's double: at u.x near
      // 1 the visible-normal sample's sqrt(1 - p1^2 - p2^2) magnifies that rounding (by 1e3 at
      // u.x = 0.9999 with a mirror's alpha), so the directions agree less closely there.
      const double tolerance = us[k].x > 0.999 ? 1e-3 : 1e-5;
      EXPECT_LT(glm::length(gotSample.direction - expectedSample.direction), tolerance) << "lane " << k;
      if (us[k].x > 0.999) continue;
      EXPECT_NEAR(gotSample.pdf, expectedSample.pdf, 1e-4 * expectedSample.pdf) << "lane " << k;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(gotSample.value[c], expectedSample.value[c], 1e-4 * (1e-3 + expectedSample.value[c])) << "lane " << k;
    }
  }
  // Every case occurred: evaluations and samples, and lanes where both give none.
  EXPECT_GT(evaluations, 2000);
  EXPECT_GT(samples, 8000);
  EXPECT_GT(agreedZero, 500);
}

// A lane's result does not depend on its neighbours or on the batch's length (the image does not
// depend on RenderSettings::pathBatch).
TEST(BsdfBatch, ALaneDoesNotDependOnTheOtherLanes) {
  SurfaceMaterial m;
  m.baseColor = {0.8, 0.5, 0.2};
  m.metallic = 0.3;
  m.roughness = 0.35;
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.1, 0.2, 1)), ng(0, 0, 1), wo = glm::normalize(glm::dvec3(0.4, -0.3, 0.8));
  BsdfBatch alone, crowded;
  alone.reserve(1);
  crowded.reserve(20);
  alone.set(0, m, n, ng, wo);
  alone.setEvaluation(0, glm::normalize(glm::dvec3(-0.2, 0.1, 0.9)));
  alone.setSample(0, {0.3, 0.7}, 0.2);
  alone.run(1);
  SurfaceMaterial other;
  other.metallic = 1.0;
  other.roughness = 0.05;
  for (std::size_t k = 0; k < 20; ++k) {
    crowded.set(k, other, glm::dvec3(0, 0, 1), glm::dvec3(0, 0, 1), glm::normalize(glm::dvec3(0.1 * static_cast<double>(k), 0, 1)));
    crowded.setEvaluation(k, glm::dvec3(0, 0, 1));
    crowded.setSample(k, {0.9, 0.1}, 0.9);
  }
  crowded.set(13, m, n, ng, wo);
  crowded.setEvaluation(13, glm::normalize(glm::dvec3(-0.2, 0.1, 0.9)));
  crowded.setSample(13, {0.3, 0.7}, 0.2);
  crowded.run(20);
  EXPECT_EQ(alone.evaluation(0).pdf, crowded.evaluation(13).pdf);
  EXPECT_EQ(alone.evaluation(0).value, crowded.evaluation(13).value);
  BsdfSample a, b;
  ASSERT_TRUE(alone.sample(0, a));
  ASSERT_TRUE(crowded.sample(13, b));
  EXPECT_EQ(a.direction, b.direction);
  EXPECT_EQ(a.value, b.value);
  EXPECT_EQ(a.pdf, b.pdf);
  EXPECT_GT(a.pdf, 0.0);
}

TEST(EquirectBatch, EveryLaneMapsAsTheScalarMappingDoes) {
  // 37 lanes (not a whole number of vectors) at a time: random image points and directions, then
  // the awkward ones: the poles, the seam at u = 0 / 1 (phi = +-pi), the axes, signed zeros (which
  // pick the side of the seam in std::atan2), and directions that are not of unit length.
  Random rng(11, 0, 0, 0);
  std::vector<glm::dvec2> points;
  std::vector<glm::dvec3> directions;
  for (int i = 0; i < 3700; ++i) {
    points.push_back(rng.uniform2());
    const double z = 1 - 2 * rng.uniform(), phi = 2 * kPi * rng.uniform(), r = std::sqrt(std::max(0.0, 1 - z * z));
    directions.push_back(glm::dvec3(r * std::cos(phi), z, r * std::sin(phi)) * (i % 3 == 0 ? 3.5 : 1.0));
  }
  for (const glm::dvec2 p : {glm::dvec2(0, 0), glm::dvec2(1, 1), glm::dvec2(0.5, 0), glm::dvec2(0.5, 1), glm::dvec2(0, 0.5),
                             glm::dvec2(1, 0.5), glm::dvec2(0.25, 0.5), glm::dvec2(0.75, 0.25)})
    points.push_back(p);
  for (const double a : {0.0, -0.0, 1.0, -1.0})
    for (const double b : {0.0, -0.0, 1.0, -1.0})
      for (const double c : {0.0, -0.0, 1e-300, -2.0})
        if (a != 0 || b != 0 || c != 0) directions.push_back({a, b, c});
  EquirectBatch batch;
  batch.reserve(37);
  double worstDirection = 0, worstPoint = 0;
  for (std::size_t first = 0; first < points.size(); first += 37) {
    const std::size_t count = std::min<std::size_t>(37, points.size() - first);
    for (std::size_t k = 0; k < count; ++k) batch.setPoint(k, points[first + k]);
    batch.directions(count);
    for (std::size_t k = 0; k < count; ++k) {
      const glm::dvec2 p = points[first + k];
      double sinTheta = 0, expectedSinTheta = 0;
      const glm::dvec3 expected = equirectDirection(p.x, p.y, &expectedSinTheta);
      const glm::dvec3 got = batch.direction(k, &sinTheta);
      worstDirection = std::max({worstDirection, glm::length(got - expected), std::abs(sinTheta - expectedSinTheta)});
      ASSERT_LT(glm::length(got - expected), 1e-14) << p.x << "," << p.y;
      ASSERT_NEAR(sinTheta, expectedSinTheta, 1e-14) << p.x << "," << p.y;
    }
  }
  for (std::size_t first = 0; first < directions.size(); first += 37) {
    const std::size_t count = std::min<std::size_t>(37, directions.size() - first);
    for (std::size_t k = 0; k < count; ++k) batch.setDirection(k, directions[first + k]);
    batch.coordinates(count);
    for (std::size_t k = 0; k < count; ++k) {
      const glm::dvec3 d = directions[first + k];
      double sinTheta = 0, expectedSinTheta = 0;
      const glm::dvec2 expected = equirectCoordinates(d, &expectedSinTheta);
      const glm::dvec2 got = batch.point(k, &sinTheta);
      worstPoint = std::max({worstPoint, glm::length(got - expected), std::abs(sinTheta - expectedSinTheta)});
      ASSERT_LT(glm::length(got - expected), 1e-14) << d.x << "," << d.y << "," << d.z << " (signs " << std::signbit(d.x) << std::signbit(d.z) << ")";
      ASSERT_NEAR(sinTheta, expectedSinTheta, 1e-15) << d.x << "," << d.y << "," << d.z;
    }
  }
  std::printf("largest difference from the scalar mapping: %.2g (directions), %.2g (image points)\n", worstDirection, worstPoint);
}

TEST(EquirectBatch, ALaneDoesNotDependOnTheOtherLanes) {
  EquirectBatch alone, crowded;
  alone.reserve(1);
  crowded.reserve(20);
  const glm::dvec2 point(0.3, 0.7);
  const glm::dvec3 direction = glm::normalize(glm::dvec3(-0.2, 0.5, 0.9));
  alone.setPoint(0, point);
  alone.setDirection(0, direction);
  for (std::size_t k = 0; k < 20; ++k) {
    crowded.setPoint(k, {0.05 * static_cast<double>(k), 0.9});
    crowded.setDirection(k, {0, -1, 0.1 * static_cast<double>(k)});
  }
  crowded.setPoint(13, point);
  crowded.setDirection(13, direction);
  // Directions first: they overwrite the direction fields, so set those again before coordinates.
  alone.directions(1);
  crowded.directions(20);
  double a = 0, b = 0;
  EXPECT_EQ(alone.direction(0, &a), crowded.direction(13, &b));
  EXPECT_EQ(a, b);
  alone.setDirection(0, direction);
  crowded.setDirection(13, direction);
  for (std::size_t k = 0; k < 20; ++k)
    if (k != 13) crowded.setDirection(k, {0, -1, 0.1 * static_cast<double>(k)});
  alone.coordinates(1);
  crowded.coordinates(20);
  EXPECT_EQ(alone.point(0, &a), crowded.point(13, &b));
  EXPECT_EQ(a, b);
  EXPECT_GT(a, 0.0);
}

TEST(Sampling, EnvironmentPdfMatchesItsSamples) {
  // A 16 x 8 environment with one bright pixel: samples land there with the probability its
  // weight says, and the solid-angle pdf integrates to 1 over the sphere.
  const fs::path dir = test::freshDir("environment");
  FloatImage image;
  image.width = 16;
  image.height = 8;
  image.channels = 3;
  image.pixels.assign(16 * 8 * 3, 0.1f);
  for (int c = 0; c < 3; ++c) image.pixels[(3 * 16 + 5) * 3 + static_cast<std::size_t>(c)] = 50.0f;
  ASSERT_TRUE(writeImage(dir / "env.hdr", image));
  scene::Environment e;
  e.file = dir / "env.hdr";
  e.intensity = 2.0f;
  auto env = EnvironmentLight::load(e);
  ASSERT_TRUE(env) << env.error().message;
  EXPECT_NEAR(env->radiance(equirectDirection((5 + 0.5) / 16, (3 + 0.5) / 8)).r, 100.0, 1e-4);
  Random rng(5, 0, 0, 0);
  double integral = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const glm::dvec2 u = rng.uniform2();
    const double z = 1 - 2 * u.x, r = std::sqrt(1 - z * z);
    integral += env->pdf({r * std::cos(2 * kPi * u.y), z, r * std::sin(2 * kPi * u.y)}) * 4 * kPi;
    double pdf = 0;
    const glm::dvec3 d = env->sample(rng.uniform2(), &pdf);
    ASSERT_NEAR(pdf, env->pdf(d), 1e-6 * pdf);
  }
  EXPECT_NEAR(integral / n, 1.0, 0.02);
}

TEST(Textures, MipLevelsAverageTheLevelBelowAndTheLodCountsTexelsPerCone) {
  // A one-texel checker of 0.2 and 0.8, 8 x 4 texels: level 1 (4 x 2) is 0.5 everywhere, the top
  // (1 x 1) too; level 0 keeps its texels.
  Texture t;
  t.width = 8, t.height = 4;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) t.texels.push_back(glm::vec4((x + y) % 2 ? 0.8f : 0.2f, 0.5f, 0.5f, 1.0f));
  t.buildMips();
  ASSERT_EQ(t.mips.size(), 3u);  // 4 x 2, 2 x 1, 1 x 1
  EXPECT_EQ(t.mips[0].width, 4);
  EXPECT_EQ(t.mips[0].height, 2);
  for (const auto& texel : t.mips[0].texels) EXPECT_NEAR(texel.r, 0.5f, 1e-6f);
  EXPECT_NEAR(t.mips.back().texels[0].r, 0.5f, 1e-6f);
  // At a texel centre, level 0 returns the texel; at level 1 and above the average; halfway
  // between levels 0 and 1, half of each.
  const glm::dvec2 centre((2 + 0.5) / 8.0, (1 + 0.5) / 4.0);  // texel (2, 1): 0.8
  const double perTexel = -0.5 * std::log2(8.0 * 4.0);      // the lod at which the level is 0
  EXPECT_NEAR(t.sample(centre, -1e9).r, 0.8, 1e-6);
  EXPECT_NEAR(t.sample(centre, perTexel + 1.0).r, 0.5, 1e-6);
  EXPECT_NEAR(t.sample(centre, perTexel + 0.5).r, 0.65, 1e-6);
  EXPECT_NEAR(t.sample(centre, perTexel + 10.0).r, 0.5, 1e-6);
  // Ray cones: a 256 x 256 texture over a 2 x 2 quad is 128 texels a unit; a cone 1/16 unit wide
  // meeting it head on covers 8 texels: level 3. At 60 degrees off the normal it covers twice as
  // many along the surface: level 4.
  const double texture = 0.5 * std::log2(256.0 * 256.0);
  EXPECT_NEAR(textureLod(1.0 / 16.0, 1.0, 0.5, 2.0) + texture, 3.0, 1e-12);
  EXPECT_NEAR(textureLod(1.0 / 16.0, 0.5, 0.5, 2.0) + texture, 4.0, 1e-12);
  EXPECT_TRUE(std::isinf(textureLod(0.0, 1.0, 0.5, 2.0)));  // no cone: level 0
}

}  // namespace
}  // namespace dynbench::render
