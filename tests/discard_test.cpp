// Reprojection discard against answers derived by hand: a static view discards nothing, a yaw
// turn discards exactly the columns that leave the frustum, a sliding quad discards its covered
// and uncovered area, noise alone is not change with --noise-aware, a light switched off discards
// the lit area; bilinear sampling at centres, edges and corners; bad frames folders.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "core/files.h"
#include "core/image_io.h"
#include "core/math.h"
#include "discard/discard.h"
#include "gltf_builder.h"
#include "render/camera.h"
#include "render_scenes.h"
#include "frames/frame_io.h"
#include "golden.h"
#include "run_cli.h"

namespace dynbench::discard {
namespace {

namespace fs = std::filesystem;

using render::yawCamera;

// What a frame sees: the hit point along a ray (or nothing), its normal and radiances.
struct Surface {
  bool hit = false;
  glm::dvec3 position{0.0}, normal{0.0}, direct{0.0}, indirect{0.0};
};

// Geometry at the pixel's centre; radiance there, or with `subpixels` > 1 the mean of an n x n
// grid of rays over the pixel (radiance integrated over the pixel with a box filter).
template <typename Scene>
FeatureFrame makeFrame(long index, const render::RenderCamera& cam, Scene&& scene, int subpixels = 1) {
  FeatureFrame f;
  f.frame = index;
  f.width = cam.width();
  f.height = cam.height();
  f.camera = cam.frameCamera();
  const auto n = static_cast<std::size_t>(f.width) * f.height;
  for (auto* b : {&f.position, &f.normal, &f.direct, &f.indirect}) b->assign(3 * n, 0.0f);
  f.hit.assign(n, 0.0f);
  f.directVariance.assign(n, 0.0f);
  f.indirectVariance.assign(n, 0.0f);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const auto i = static_cast<std::size_t>(y * f.width + x);
      const render::Ray ray = cam.ray(x + 0.5, y + 0.5);
      Surface s = scene(ray, x, y);
      if (subpixels > 1) {
        s.direct = s.indirect = glm::dvec3(0.0);
        for (int sy = 0; sy < subpixels; ++sy)
          for (int sx = 0; sx < subpixels; ++sx) {
            const Surface sub = scene(cam.ray(x + (sx + 0.5) / subpixels, y + (sy + 0.5) / subpixels), x, y);
            s.direct += sub.direct / double(subpixels * subpixels);
            s.indirect += sub.indirect / double(subpixels * subpixels);
          }
      }
      f.hit[i] = s.hit ? 1.0f : 0.0f;
      for (int c = 0; c < 3; ++c) {
        f.position[3 * i + c] = static_cast<float>(s.position[c]);
        f.normal[3 * i + c] = static_cast<float>(s.normal[c]);
        f.direct[3 * i + c] = static_cast<float>(s.direct[c]);
        f.indirect[3 * i + c] = static_cast<float>(s.indirect[c]);
      }
    }
  return f;
}

// A sphere of radius 50 around the origin, seen from inside.
Surface farSphere(const render::Ray& ray, int, int) {
  return {true, ray.origin + 50.0 * ray.direction, -ray.direction, glm::dvec3(1.0), glm::dvec3(0.5)};
}

// The thesis's test (bilinear sample, position in scene units), whose answers these tests derive.
Thresholds absolute(double position, double normal, double direct, double indirect) {
  Thresholds t;
  t.geometryTest = Thresholds::GeometryTest::kBilinear;
  t.position = position;
  t.normal = normal;
  t.direct = direct;
  t.indirect = indirect;
  t.absoluteRadiance = true;
  return t;
}

TEST(Discard, StaticCameraAndSceneDiscardNothing) {
  const auto cam = yawCamera(30.0, 64, 36, 50.0);
  const FeatureFrame a = makeFrame(0, cam, farSphere), b = makeFrame(1, cam, farSphere);
  const auto r = discardFrame(b, a, absolute(1e-3, 1e-3, 1e-3, 1e-3));
  EXPECT_EQ(r.percentages.frustum, 0.0);
  EXPECT_EQ(r.percentages.position, 0.0);
  EXPECT_EQ(r.percentages.normal, 0.0);
  EXPECT_EQ(r.percentages.direct, 0.0);
  EXPECT_EQ(r.percentages.indirect, 0.0);
}

TEST(Discard, YawTurnDiscardsTheColumnsThatLeaveTheFrustum) {
  // One row of 1000 pixels, 90 degrees across (tan(hfov/2) = 1). The previous camera looked 10
  // degrees further left (yaw +10). A pixel at angle phi right of the axis (tan phi = 2(x + 0.5)/w - 1)
  // was at phi + 10 degrees in the previous image, i.e. at pixel index w/2 (1 + tan(phi + 10)) - 0.5.
  // It is outside (Eq. 3.3) when that exceeds w - 1: tan(phi + 10) > 0.999, phi > 44.9713 - 10
  // = 34.9713 degrees, tan phi > 0.69946, x + 0.5 > 849.73: columns 850..999, 150 pixels = 15.0%.
  // A single row keeps the vertical coordinate at the centre (y_cam = 0) whatever the yaw.
  const int w = 1000, h = 1;
  const double yfov = degrees(2.0 * std::atan(1.0 / w));  // square pixels: tan(yfov/2) = tan(hfov/2) h / w
  const auto now = yawCamera(0.0, w, h, yfov), before = yawCamera(10.0, w, h, yfov);
  for (bool background : {false, true}) {
    auto scene = [&](const render::Ray& ray, int x, int y) { return background ? Surface{} : farSphere(ray, x, y); };
    const auto r = discardFrame(makeFrame(1, now, scene), makeFrame(0, before, scene), absolute(1e-2, 1e-2, 1e-2, 1e-2));
    EXPECT_NEAR(r.percentages.frustum, 15.0, 1e-9) << (background ? "background" : "geometry");
    for (int x = 0; x < w; ++x) EXPECT_EQ((r.mask[static_cast<std::size_t>(x)] & kFrustum) != 0, x >= 850) << x;
    if (!background) EXPECT_EQ(r.percentages.position, 0.0);  // the rest has valid history
  }
}

TEST(Discard, SlidingQuadDiscardsItsCoveredAndUncoveredArea) {
  // A static camera looking down -Z at a wall at z = -10 and a 2 x 2 quad at z = -5 that moves
  // 0.5 to the right between the frames. With a static camera every pixel reprojects onto itself,
  // so the history of a pixel is what that pixel saw before. Where the quad covers a pixel in both
  // frames the ray meets the quad's plane at the same world point, so only the area it newly
  // covers (wall before, quad now) and the area it uncovers (quad before, wall now) is discarded.
  const int w = 80, h = 60;
  const auto cam = yawCamera(0.0, w, h, 60.0);
  auto quadAt = [](double cx) {
    return [cx](const render::Ray& ray, int, int) {
      const double tq = (-5.0 - ray.origin.z) / ray.direction.z;
      const glm::dvec3 q = ray.origin + tq * ray.direction;
      if (std::abs(q.x - cx) <= 1.0 && std::abs(q.y) <= 1.0) return Surface{true, q, {0, 0, 1}, glm::dvec3(1.0), glm::dvec3(0.1)};
      const double tw = (-10.0 - ray.origin.z) / ray.direction.z;
      return Surface{true, ray.origin + tw * ray.direction, {0, 0, 1}, glm::dvec3(1.0), glm::dvec3(0.1)};
    };
  };
  const auto r = discardFrame(makeFrame(1, cam, quadAt(0.5)), makeFrame(0, cam, quadAt(0.0)), absolute(0.1, 0.1, 0.1, 0.1));
  int expected = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const render::Ray ray = cam.ray(x + 0.5, y + 0.5);
      const glm::dvec3 q = ray.origin + ((-5.0 - ray.origin.z) / ray.direction.z) * ray.direction;
      const bool now = std::abs(q.x - 0.5) <= 1.0 && std::abs(q.y) <= 1.0, before = std::abs(q.x) <= 1.0 && std::abs(q.y) <= 1.0;
      expected += now != before;
      EXPECT_EQ((r.mask[static_cast<std::size_t>(y * w + x)] & kPosition) != 0, now != before) << x << "," << y;
    }
  EXPECT_GT(expected, 50);
  EXPECT_NEAR(r.percentages.position, 100.0 * expected / (w * h), 1e-9);
  EXPECT_EQ(r.percentages.normal, 0.0);  // the same normal everywhere
  EXPECT_EQ(r.percentages.frustum, 0.0);
}

TEST(Discard, NoiseAloneIsNotChangeWhenNoiseAware) {
  // Both frames show the same surface with radiance 1 + Gaussian noise of standard deviation 0.05
  // per pixel, and say so in their variance channels (0.05^2). A threshold of 0.02 discards most
  // pixels; --noise-aware asks for 3 standard deviations of the difference (sqrt(2) x 0.05), which
  // noise exceeds with probability 0.27%.
  const auto cam = yawCamera(0.0, 100, 100, 50.0);
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  auto noisy = [&](const render::Ray& ray, int x, int y) {
    Surface s = farSphere(ray, x, y);
    const double d = 1.0 + noise(random), i = 0.5 + noise(random);
    s.direct = glm::dvec3(d);
    s.indirect = glm::dvec3(i);
    return s;
  };
  FeatureFrame a = makeFrame(0, cam, noisy), b = makeFrame(1, cam, noisy);
  for (auto* f : {&a, &b}) {
    std::fill(f->directVariance.begin(), f->directVariance.end(), 0.0025f);
    std::fill(f->indirectVariance.begin(), f->indirectVariance.end(), 0.0025f);
  }
  Thresholds t = absolute(0.1, 0.1, 0.02, 0.02);
  t.radianceTest = discard::Thresholds::RadianceTest::kPlain;
  const auto plain = discardFrame(b, a, t);
  t.radianceTest = discard::Thresholds::RadianceTest::kNoiseAware;
  const auto aware = discardFrame(b, a, t);
  EXPECT_GT(plain.percentages.direct, 60.0);  // |N(0, 0.0707^2)| * sqrt(3) > 0.02: about 83%
  EXPECT_GT(plain.percentages.indirect, 60.0);
  EXPECT_LT(aware.percentages.direct, 1.0);
  EXPECT_LT(aware.percentages.indirect, 1.0);
}

TEST(Discard, ExpectedTestCountsEachPixelWithTheProbabilityOfARealChange) {
  // Noise-free values, but variance channels saying each frame's pixel has luminance variance
  // sigma^2 / 6, so the difference's luminance has sigma^2 / 3: on the thresholds' RGB scale (a
  // grey change, x sqrt(3)) sigma. The grey change delta has that scale's size d = sqrt(3) delta =
  // tau + sigma: each pixel counts P(|N(d, sigma^2)| > tau) = Phi(1) + Phi(-(2 tau + sigma) /
  // sigma) = Phi(1) + Phi(-5), and the 95 % interval is 1.96 sqrt(N p (1 - p)) / N.
  const int w = 50, h = 40;
  const auto cam = yawCamera(0.0, w, h, 50.0);
  const double tau = 0.1, sigma = 0.05, delta = (tau + sigma) / std::sqrt(3.0);
  auto grey = [](double value) {
    return [value](const render::Ray& ray, int x, int y) {
      Surface s = farSphere(ray, x, y);
      s.direct = glm::dvec3(value);
      s.indirect = glm::dvec3(0.5);
      return s;
    };
  };
  FeatureFrame before = makeFrame(0, cam, grey(1.0)), now = makeFrame(1, cam, grey(1.0 + delta));
  for (auto* f : {&before, &now}) std::fill(f->directVariance.begin(), f->directVariance.end(), static_cast<float>(sigma * sigma / 6));
  std::size_t hits = 0;
  for (float v : now.hit) hits += v > 0;
  ASSERT_EQ(hits, static_cast<std::size_t>(w * h));  // the far sphere fills the image
  const auto r = discardFrame(now, before, absolute(1.0, 1.0, tau, tau));
  const double p = 0.8413447460685429 + 2.866515718791939e-7;
  const double n = w * h;
  EXPECT_NEAR(r.percentages.direct, 100.0 * p, 1e-4);  // float variance channels: about 1e-7 relative
  ASSERT_TRUE(r.percentages.directInterval);
  const double half = 1.959963984540054 * std::sqrt(n * p * (1 - p)) / n * 100.0;
  EXPECT_NEAR(r.percentages.directInterval->low, 100.0 * p - half, 1e-3);
  EXPECT_NEAR(r.percentages.directInterval->high, 100.0 * p + half, 1e-3);
  // The noise on the thresholds' scale is sigma = tau / 2 here, at the edge of "uncertain": a
  // little less and no pixel is, a little more and every pixel is.
  for (const double scale : {0.9, 1.1}) {
    FeatureFrame a = now, b = before;
    for (auto* f : {&a, &b}) std::fill(f->directVariance.begin(), f->directVariance.end(), static_cast<float>(scale * sigma * sigma / 6));
    EXPECT_EQ(discardFrame(a, b, absolute(1.0, 1.0, tau, tau)).percentages.directNoisy, scale < 1 ? 0.0 : 100.0) << scale;
  }
  {
    FeatureFrame noisier = now, noisierBefore = before;
    for (auto* f : {&noisier, &noisierBefore})
      std::fill(f->directVariance.begin(), f->directVariance.end(), static_cast<float>(1.1 * sigma * sigma / 6));
    // Only the left half of the current frame: its noise is the sum of both frames', so the right
    // half (variance 0 in the current frame) stays below half the threshold.
    for (int y = 0; y < h; ++y)
      for (int x = w / 2; x < w; ++x) noisier.directVariance[static_cast<std::size_t>(y * w + x)] = 0.0f;
    const auto noisy = discardFrame(noisier, noisierBefore, absolute(1.0, 1.0, tau, tau));
    EXPECT_NEAR(noisy.percentages.directNoisy, 50.0, 1e-9);
    EXPECT_EQ(noisy.percentages.indirectNoisy, 0.0);
  }
  // Indirect did not change and has no noise: exactly 0, an interval of width 0.
  EXPECT_EQ(r.percentages.indirect, 0.0);
  EXPECT_EQ(r.percentages.indirectInterval->halfWidth(), 0.0);
  // The mask shows the likelier outcome: every pixel (p > 0.5).
  std::size_t masked = 0;
  for (auto bits : r.mask) masked += (bits & kDirect) != 0;
  EXPECT_EQ(masked, hits);
  // As the noise vanishes the expected test becomes the plain one (for a grey change): every pixel.
  for (auto* f : {&before, &now}) std::fill(f->directVariance.begin(), f->directVariance.end(), 0.0f);
  EXPECT_EQ(discardFrame(now, before, absolute(1.0, 1.0, tau, tau)).percentages.direct, 100.0);
  // A change of hue at constant luminance is no change to the expected test; the plain test's RGB
  // distance sees it.
  auto hue = [](bool red) {
    return [red](const render::Ray& ray, int x, int y) {
      Surface s = farSphere(ray, x, y);
      s.direct = red ? glm::dvec3(1.0 / 0.2126, 0, 0) : glm::dvec3(0, 1.0 / 0.7152, 0);
      return s;
    };
  };
  const FeatureFrame red = makeFrame(0, cam, hue(true)), green = makeFrame(1, cam, hue(false));
  Thresholds t = absolute(1.0, 1.0, tau, tau);
  EXPECT_NEAR(discardFrame(green, red, t).percentages.direct, 0.0, 1e-9);
  t.radianceTest = Thresholds::RadianceTest::kPlain;
  EXPECT_EQ(discardFrame(green, red, t).percentages.direct, 100.0);
}

TEST(Discard, ALightSwitchedOffDiscardsTheLitArea) {
  // The left half of the image was lit (direct 1) and is dark now: 100% of the lit area, 50% of
  // the image, is a direct-radiance discard; nothing else changed.
  const int w = 64, h = 32;
  const auto cam = yawCamera(0.0, w, h, 50.0);
  auto lit = [](bool on) {
    return [on](const render::Ray& ray, int x, int y) {
      Surface s = farSphere(ray, x, y);
      s.direct = glm::dvec3(on && x < 32 ? 1.0 : 0.0);
      return s;
    };
  };
  const auto r = discardFrame(makeFrame(1, cam, lit(false)), makeFrame(0, cam, lit(true)), absolute(0.1, 0.1, 0.5, 0.1));
  EXPECT_NEAR(r.percentages.direct, 50.0, 1e-9);
  for (int x = 0; x < w; ++x) EXPECT_EQ((r.mask[static_cast<std::size_t>(x)] & kDirect) != 0, x < 32);
  EXPECT_EQ(r.percentages.indirect, 0.0);
  EXPECT_EQ(r.percentages.position, 0.0);
}

// A floor y = 0 under a camera at height `height` looking `pitch` degrees down, yawed by `yaw`,
// and a ball of radius 0.5 at (0, 0.5, -4): the taps test's scene. Radiance is a smooth function
// of position, the same whatever the scale `unit` the scene is built in.
// A floor and a ball of radius 0.5 four units ahead; the ball's direct radiance is ballDirect
// times the floor's pattern, radiance integrated over `subpixels`^2 rays a pixel (makeFrame).
FeatureFrame floorAndBall(long index, double unit, double x, double yawDegrees, int w, int h, bool ball = true, double ballDirect = 1.0,
                          int subpixels = 1) {
  glm::dmat4 world = glm::mat4_cast(quatFromYawPitchRoll(radians(yawDegrees), radians(-25.0), 0.0));
  world[3] = glm::dvec4(unit * x, unit * 1.5, 0.0, 1.0);
  scene::Camera lens;
  lens.yfov = radians(50.0);
  lens.znear = 0.01 * unit;
  lens.zfar = 1000 * unit;
  const render::RenderCamera cam(world, lens, w, h);
  const glm::dvec3 centre = unit * glm::dvec3(0.0, 0.5, -4.0);
  const double radius = 0.5 * unit;
  return makeFrame(index, cam, [&](const render::Ray& ray, int, int) {
    Surface s;
    double t = 1e30;
    const glm::dvec3 oc = ray.origin - centre;
    const double b = glm::dot(oc, ray.direction), c = glm::dot(oc, oc) - radius * radius, disc = b * b - c;
    double brightness = 1.0;
    if (ball && disc > 0 && -b - std::sqrt(disc) > 0) {
      t = -b - std::sqrt(disc);
      s.normal = (ray.origin + t * ray.direction - centre) / radius;
      brightness = ballDirect;
    }
    if (ray.direction.y < 0 && -ray.origin.y / ray.direction.y < t) {
      t = -ray.origin.y / ray.direction.y;
      s.normal = glm::dvec3(0, 1, 0);
      brightness = 1.0;
    }
    if (t >= 1e30) return s;
    s.hit = true;
    s.position = ray.origin + t * ray.direction;
    const glm::dvec3 q = s.position / unit;
    s.direct = brightness * glm::dvec3(1.0 + 0.2 * std::sin(q.x) + 0.1 * q.z * 0.1);
    s.indirect = glm::dvec3(0.3);
    return s;
  }, subpixels);
}

TEST(Discard, TapsTestIsFreeOfSceneUnits) {
  // The same view built in metres and in centimetres: the taps test measures plane distance as a
  // share of the view depth, so every column is the same; the bilinear test's 0.05 units are
  // 5 cm in one and 0.5 mm in the other.
  Thresholds taps;
  taps.direct = taps.indirect = 0.1;
  DiscardResult r[2];
  for (int k = 0; k < 2; ++k) {
    const double unit = k ? 100.0 : 1.0;
    const FeatureFrame a = floorAndBall(0, unit, 0.0, 0.0, 96, 54), b = floorAndBall(1, unit, 0.3, 1.0, 96, 54);
    r[k] = discardFrame(b, a, absoluteThresholds(taps, b, 0.0));
  }
  EXPECT_GT(r[0].percentages.position, 0.05);  // the floor the ball uncovers
  EXPECT_LT(r[0].percentages.position, 5.0);
  EXPECT_EQ(r[0].mask, r[1].mask);
  EXPECT_NEAR(r[0].percentages.direct, r[1].percentages.direct, 1e-9);
}

TEST(Discard, TapsOfASmoothSurfaceAreKeptWhereTheBilinearSampleMixesTwo) {
  // A sideways step of the camera past the ball (about 3 pixels of parallax against the floor
  // behind it at 96x54, 12 at 384x216). On the floor, every tap lies on the floor's plane: no
  // position or normal discard, at any resolution. At the ball's silhouette the bilinear sample
  // mixes ball and floor (the thesis's test discards a band about a pixel wide there); the taps
  // test keeps a pixel with one tap of its own surface, so its column is the disocclusion alone
  // and shrinks less with resolution than the band's.
  Thresholds taps;
  double tapsPosition[2], bilinearPosition[2];
  for (int k = 0; k < 2; ++k) {
    const int w = k ? 384 : 96, h = k ? 216 : 54;
    const FeatureFrame a = floorAndBall(0, 1.0, 0.0, 0.0, w, h), b = floorAndBall(1, 1.0, 0.3, 0.3, w, h);
    const auto rt = discardFrame(b, a, absoluteThresholds(taps, b, 0.0));
    const auto rb = discardFrame(b, a, absolute(0.05, 0.1, 1e9, 1e9));
    tapsPosition[k] = rt.percentages.position;
    bilinearPosition[k] = rb.percentages.position;
    // The floor alone, seen at a grazing angle, moved by a fraction of a pixel: nothing.
    const FeatureFrame fa = floorAndBall(0, 1.0, 0.0, 0.0, w, h, false), fb = floorAndBall(1, 1.0, 0.003, 0.05, w, h, false);
    const auto floor = discardFrame(fb, fa, absoluteThresholds(taps, fb, 0.0));
    EXPECT_EQ(floor.percentages.position, 0.0) << w << "x" << h;
    EXPECT_EQ(floor.percentages.normal, 0.0) << w << "x" << h;
  }
  std::printf("position discard, taps: %.3f %% at 96x54, %.3f %% at 384x216; bilinear: %.3f %%, %.3f %%\n", tapsPosition[0],
              tapsPosition[1], bilinearPosition[0], bilinearPosition[1]);
  // The bilinear band halves with the pixel's size; the taps' disocclusion converges from below
  // (a strip a few pixels wide loses a pixel to taps of the floor beside it) and moves far less.
  EXPECT_GT(tapsPosition[0], 0.0);
  EXPECT_LT(tapsPosition[0], bilinearPosition[0]);
  EXPECT_LT(std::abs(tapsPosition[1] - tapsPosition[0]), 0.25 * std::abs(bilinearPosition[1] - bilinearPosition[0]));
}

TEST(Discard, ACurvedSurfaceAFewPixelsWideKeepsItsNormalHistory) {
  // The ball is about 5 pixels wide at 32x18, so its normal turns by some 20-40 degrees from one
  // pixel to the next. The camera moves sideways by 0.4 pixels at the ball: no tap's normal is
  // within 5.7 degrees of a point between the taps, but the interpolation of the taps' normals
  // is, as the ball's normal there was in the previous frame. Measured: 0.87 % normal discard at
  // 32x18 (5 silhouette pixels, whose taps of the ball are off its tangent plane), 3.1 % (the
  // whole ball) with single taps only; 0.008 % at 384x216.
  Thresholds taps;
  auto ballShare = [](const FeatureFrame& f) {
    std::size_t ball = 0;
    for (std::size_t i = 0; i < f.hit.size(); ++i) ball += f.hit[i] > 0 && f.normal[3 * i + 1] < 0.999f ? 1 : 0;
    return 100.0 * static_cast<double>(ball) / static_cast<double>(f.hit.size());
  };
  for (int k = 0; k < 2; ++k) {
    const int w = k ? 384 : 32, h = k ? 216 : 18;
    const double pixelsPerUnit = h / (2.0 * 4.0 * std::tan(radians(25.0)));  // at the ball's distance
    const FeatureFrame a = floorAndBall(0, 1.0, 0.0, 0.0, w, h), b = floorAndBall(1, 1.0, 0.4 / pixelsPerUnit, 0.0, w, h);
    const auto r = discardFrame(b, a, absoluteThresholds(taps, b, 0.0));
    std::printf("%dx%d: normal discard %.3f %%, ball %.3f %%\n", w, h, r.percentages.normal, ballShare(b));
    EXPECT_LT(r.percentages.normal, k ? 0.01 : 0.3 * ballShare(b)) << w << "x" << h;
  }
  // The test still sees a turned normal: each of the ball's normals turned by 10 degrees (towards
  // a tangent), at 384x216 where neighbouring taps differ by a degree or less.
  const FeatureFrame a = floorAndBall(0, 1.0, 0.0, 0.0, 384, 216);
  FeatureFrame b = floorAndBall(1, 1.0, 0.004, 0.02, 384, 216);
  const double c = std::cos(radians(10.0)), s = std::sin(radians(10.0));
  std::size_t ball = 0;
  for (std::size_t i = 0; i < b.hit.size(); ++i) {
    glm::dvec3 n(b.normal[3 * i], b.normal[3 * i + 1], b.normal[3 * i + 2]);
    if (b.hit[i] <= 0 || n.y > 0.999) continue;  // the floor
    ++ball;
    glm::dvec3 tangent = glm::cross(n, glm::dvec3(1, 0, 0));
    if (glm::length(tangent) < 0.5) tangent = glm::cross(n, glm::dvec3(0, 1, 0));
    n = c * n + s * glm::normalize(tangent);
    for (int k = 0; k < 3; ++k) b.normal[3 * i + static_cast<std::size_t>(k)] = static_cast<float>(n[k]);
  }
  const auto turned = discardFrame(b, a, absoluteThresholds(taps, b, 0.0));
  ASSERT_GT(ball, 1000u);
  EXPECT_GE(turned.percentages.normal, 0.9 * 100.0 * static_cast<double>(ball) / static_cast<double>(b.hit.size()));
}

TEST(Discard, APixelFilteredSilhouetteIsNoChangeOfLighting) {
  // A bright ball (4x the floor) over the floor, radiance integrated over each pixel (4 x 4 rays),
  // the camera moved sideways by 0.4 pixels at the ball. The silhouette's pixels mix ball and
  // floor in proportions that move with it: against the history's Catmull-Rom or bilinear sample
  // they differ by up to the whole contrast (a band a pixel wide, 1/resolution of the frame), but
  // each lies within the range of the taps around its point, so none is a change of lighting, at
  // either resolution. The ball's light halved is a change: its pixels are discarded.
  Thresholds taps;
  for (int k = 0; k < 2; ++k) {
    const int w = k ? 192 : 48, h = k ? 108 : 27;
    const double pixelsPerUnit = h / (2.0 * 4.0 * std::tan(radians(25.0)));
    const FeatureFrame a = floorAndBall(0, 1.0, 0.0, 0.0, w, h, true, 4.0, 4);
    const FeatureFrame b = floorAndBall(1, 1.0, 0.4 / pixelsPerUnit, 0.0, w, h, true, 4.0, 4);
    const auto moved = discardFrame(b, a, absoluteThresholds(taps, b, 0.0));
    EXPECT_LT(moved.percentages.direct, 0.1) << w << "x" << h;
    const FeatureFrame dimmed = floorAndBall(1, 1.0, 0.4 / pixelsPerUnit, 0.0, w, h, true, 2.0, 4);
    const auto changed = discardFrame(dimmed, a, absoluteThresholds(taps, dimmed, 0.0));
    std::size_t ball = 0;
    for (std::size_t i = 0; i < b.hit.size(); ++i) ball += b.hit[i] > 0 && b.normal[3 * i + 1] < 0.999f ? 1 : 0;
    const double ballShare = 100.0 * static_cast<double>(ball) / static_cast<double>(b.hit.size());
    std::printf("%dx%d: direct discard %.3f %% moved, %.3f %% with the ball's light halved (ball %.3f %%)\n", w, h,
                moved.percentages.direct, changed.percentages.direct, ballShare);
    EXPECT_GT(changed.percentages.direct, 0.8 * ballShare) << w << "x" << h;
  }
}

// A frames folder written to the contract (through the renderer's own sidecar writer).
// The camera yaws 2 degrees a frame; from frame cutAt on it has jumped a further 40 degrees, and
// that frame's sidecar says cut.
void writeFrames(const fs::path& dir, int count, int w, int h, bool variance = true, int cutAt = -1) {
  for (int k = 0; k < count; ++k) {
    const auto cam = yawCamera(2.0 * k + (cutAt >= 0 && k >= cutAt ? 40.0 : 0.0), w, h, 50.0);
    const FeatureFrame f = makeFrame(k, cam, farSphere);
    FloatImage image;
    image.width = w;
    image.height = h;
    image.channelNames = {"P.X",        "P.Y",        "P.Z",        "N.X", "N.Y",        "N.Z",         "direct.R", "direct.G",
                          "direct.B",   "indirect.R", "indirect.G", "indirect.B", "hit", "direct.var", "indirect.var"};
    if (!variance) image.channelNames.resize(image.channelNames.size() - 2);
    image.channels = static_cast<int>(image.channelNames.size());
    for (std::size_t i = 0; i < f.hit.size(); ++i) {
      for (const auto* b : {&f.position, &f.normal, &f.direct, &f.indirect})
        for (int c = 0; c < 3; ++c) image.pixels.push_back((*b)[3 * i + c]);
      image.pixels.push_back(f.hit[i]);
      // Noise of a few percent of the radiance, so the expected test has intervals to print.
      if (!variance) continue;
      image.pixels.push_back(static_cast<float>(1e-3 * (1 + i % 7)));
      image.pixels.push_back(static_cast<float>(1e-4 * (1 + i % 5)));
    }
    ASSERT_TRUE(writeImage(frames::frameImagePath(dir, k), image));
    auto sidecar = frames::sidecarJson(k, k / 24.0, cam.frameCamera(), {});
    if (k == cutAt) sidecar["cut"] = true;
    ASSERT_TRUE(writeFileAtomic(frames::frameSidecarPath(dir, k), sidecar.dump()));
  }
}

TEST(DiscardCli, CameraCutsAreMarkedAndLeftOutOfTheMeanUnlessIncluded) {
  const auto dir = test::freshDir("discard_cuts");
  writeFrames(dir / "plain", 4, 48, 27);
  writeFrames(dir / "cut", 4, 48, 27, true, 2);  // pairs (0,1), (1,2) cut, (2,3)
  const auto plain = dynbench(fmt::format("discard {} --radiance-test expected --json {}", (dir / "plain").string(), (dir / "p.json").string()), dir);
  ASSERT_EQ(plain.status, 0) << plain.err;
  const auto cut = dynbench(fmt::format("discard {} --radiance-test expected --json {} --csv {}", (dir / "cut").string(), (dir / "c.json").string(),
                                        (dir / "c.csv").string()), dir);
  ASSERT_EQ(cut.status, 0) << cut.err;
  EXPECT_NE(cut.out.find("3 frame pairs of which 1 camera cuts are left out"), std::string::npos) << cut.out;
  EXPECT_NE(cut.err.find("1 of 3 frame pairs are camera cuts; the mean leaves them out"), std::string::npos) << cut.err;  // warnings on stderr
  const auto p = nlohmann::json::parse(test::slurp(dir / "p.json"));
  const auto c = nlohmann::json::parse(test::slurp(dir / "c.json"));
  EXPECT_EQ(c["cut_pairs"], 1);
  EXPECT_EQ(c["cuts_in_mean"], false);
  EXPECT_EQ(c["frames"][1]["cut"], true);
  EXPECT_FALSE(c["frames"][0].contains("cut"));
  // The other pairs turn 2 degrees, as every pair of the plain folder: the mean over them is the
  // plain folder's; the cut pair (a 42-degree turn) loses far more.
  EXPECT_NEAR(c["mean"]["frustum"].get<double>(), p["mean"]["frustum"].get<double>(), 1e-9);
  EXPECT_GT(c["frames"][1]["frustum"].get<double>(), 5 * p["mean"]["frustum"].get<double>());
  const auto csv = test::slurp(dir / "c.csv");
  EXPECT_NE(csv.find(",cut\n"), std::string::npos);
  const auto all = dynbench(fmt::format("discard {} --radiance-test expected --include-cuts --json {}", (dir / "cut").string(), (dir / "a.json").string()), dir);
  ASSERT_EQ(all.status, 0) << all.err;
  const auto a = nlohmann::json::parse(test::slurp(dir / "a.json"));
  EXPECT_EQ(a["cuts_in_mean"], true);
  double sum = 0;
  for (const auto& f : c["frames"]) sum += f["frustum"].get<double>();
  EXPECT_NEAR(a["mean"]["frustum"].get<double>(), sum / 3, 1e-9);
  // Only cuts: nothing to average without --include-cuts.
  writeFrames(dir / "only", 2, 16, 9, true, 1);
  const auto only = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "only").string()), dir);
  EXPECT_EQ(only.status, 5) << only.err;  // invalid data
  EXPECT_NE(only.err.find("every frame pair is a camera cut"), std::string::npos) << only.err;
}

TEST(DiscardCli, ASubPixelPanOverAFineTextureDiscardsNothingWhenRadianceIsFiltered) {
  // The issue's known answer: a static floor whose checker texture is finer than a pixel (1024
  // texels over 10 units, about 5 texels a pixel here), under a fixed directional light, seen by a
  // camera that slides 0.3 pixel a frame. Nothing changes but the sampling, so world position and
  // radiance must discard below 1 %, through the pixel filter and at the pixel centre alike: the
  // textures are filtered for each ray's cone (mip maps, ray cones), so the albedo a pixel sees is
  // the texels' average, not one texel. Before both (point-sampled textures, radiance at the
  // centre) the same pan discarded 71.8 % of the pixels' direct radiance: it looked like a change
  // of light (the report's magenta floors). Both renders converge, so noise is not taken for
  // change, at tolerance 0.125: with point-sampled textures, where each sample saw a texel of 0.1
  // or of 0.9 and a pixel's variance estimate was itself noisy, the default 0.25 counted 2 % from
  // noise alone.
  const auto dir = test::freshDir("discard_fine_texture");
  constexpr int kTexels = 1024;
  FloatImage checker{kTexels, kTexels, 3, {}, {}};
  checker.pixels.reserve(3 * kTexels * kTexels);
  for (int y = 0; y < kTexels; ++y)
    for (int x = 0; x < kTexels; ++x)
      for (int c = 0; c < 3; ++c) checker.pixels.push_back((x + y) % 2 ? 0.9f : 0.1f);
  ASSERT_TRUE(writeImage(dir / "checker.png", checker));
  test::GltfBuilder b;
  b.doc["images"] = nlohmann::json::array({{{"uri", "checker.png"}}});
  b.doc["textures"] = nlohmann::json::array({{{"source", 0}}});
  b.doc["materials"] = nlohmann::json::array(
      {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}}});
  const std::vector<float> p{-5, 0, -8, -5, 0, 2, 5, 0, 2, 5, 0, -8}, n{0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, uv{0, 0, 0, 1, 1, 1, 1, 0};
  b.doc["meshes"] = nlohmann::json::array({{{"primitives", nlohmann::json::array({{{"attributes", {{"POSITION", b.accessor(p, "VEC3")},
                                                                                                   {"NORMAL", b.accessor(n, "VEC3")},
                                                                                                   {"TEXCOORD_0", b.accessor(uv, "VEC2")}}},
                                                                                   {"indices", b.indices({0, 1, 2, 0, 2, 3})},
                                                                                   {"material", 0}}})}}});
  b.node({{"mesh", 0}});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = nlohmann::json::array({{{"type", "directional"}, {"intensity", 3.0}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.node({{"rotation", {-0.3826834, 0, 0, 0.9238795}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});  // 45 degrees down
  // 64x36, yfov 0.6: the floor 2.5 below, 30 degrees down; a pixel is about 0.04 units at the
  // image centre (distance 5), so 0.3 pixel a frame is 0.012 units a frame.
  const int camera = b.node({{"camera", b.perspectiveCamera(0.6)}, {"translation", {0, 2.5, 0}}, {"rotation", {-0.258819, 0, 0, 0.9659258}}});
  b.channel(camera, "translation", {0.0f, 3.0f / 24}, {0, 2.5f, 0, 0.036f, 2.5f, 0});
  const auto dataset = b.write(dir, "floor");
  double position[2], direct[2];
  for (int filtered = 0; filtered < 2; ++filtered) {
    const auto frames = dir / (filtered ? "filtered" : "centre");
    const auto r = dynbench(fmt::format("render {} -o {} --res 64x36 --frames 0:3 --converge --tolerance 0.125 --bounces 1 --no-environment --pixel-filter {}",
                                        dataset.string(), frames.string(), filtered ? "blackman-harris" : "centre"),
                            dir);
    ASSERT_EQ(r.status, 0) << r.err;
    // No indirect light at all (a floor alone, no environment): the indirect buffer's threshold is
    // 0, and its black pixels are unchanged after their first pairs, not undecided up to the cap.
    const auto sampling = nlohmann::json::parse(test::slurp(frames / "frame_00001.json"))["sampling"];
    EXPECT_EQ(sampling["undecided_pixels"], 0) << sampling;
    EXPECT_LT(sampling["max_pairs"].get<int>(), sampling["pair_cap"].get<int>()) << sampling;
    const auto d = dynbench(fmt::format("discard {} --json {}", frames.string(), (dir / "d.json").string()), dir);
    ASSERT_EQ(d.status, 0) << d.err;
    const auto j = nlohmann::json::parse(test::slurp(dir / "d.json"));
    position[filtered] = j["mean"]["world_position"];
    direct[filtered] = j["mean"]["direct_radiance"];
    std::printf("%s: world position %.3f %%, normal %.3f %%, direct %.3f %%\n", filtered ? "filtered" : "centre", position[filtered],
                j["mean"]["shading_normal"].get<double>(), direct[filtered]);
  }
  for (int filtered = 0; filtered < 2; ++filtered) {
    EXPECT_LT(position[filtered], 1.0);
    EXPECT_LT(direct[filtered], 1.0);
  }
  // The albedo buffer (the pixel centre's, a G-buffer's) is the texture's average: the mean of the
  // two texels' sRGB-decoded values (the PNG stores 0.1 and 0.9 as 8-bit codes 26 and 230).
  auto decode = [](double code) {
    const double c = code / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  };
  const double average = 0.5 * (decode(26) + decode(230));
  auto frames = frames::listFrames(dir / "centre");
  ASSERT_TRUE(frames && !frames->empty());
  auto frame = frames::readFrame(frames->front());
  ASSERT_TRUE(frame) << frame.error().message;
  int floor = 0, off = 0;
  for (std::size_t i = 0; i < frame->pixelCount(); ++i) {
    if (frame->hit[i] <= 0) continue;
    ++floor;
    if (std::abs(frame->albedo[3 * i] - average) > 0.02) ++off;
  }
  std::printf("albedo within 0.02 of the texels' average %.4f on %d of %d floor pixels\n", average, floor - off, floor);
  EXPECT_GT(floor, 1000);
  EXPECT_LE(off, floor / 50);
}

TEST(DiscardCli, TableJsonCsvAndMasks) {
  const auto dir = test::freshDir("discard_cli");
  writeFrames(dir / "frames", 4, 48, 27);
  const auto r = dynbench(fmt::format("discard {} --radiance-test expected --json {} --csv {} --masks {} --plots {}", (dir / "frames").string(),
                                      (dir / "d.json").string(), (dir / "d.csv").string(), (dir / "masks").string(), (dir / "plots").string()),
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("| frustum % |"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(test::slurp(dir / "d.json"));
  ASSERT_EQ(j["frames"].size(), 3u);
  // The expected test's 95 % intervals, for the mean and per frame, bracket their estimates; the
  // mean's half width is the frames' in quadrature over their count.
  EXPECT_EQ(j["thresholds"]["radiance_test"], "expected");
  double sumSq = 0;
  for (const auto& f : j["frames"]) {
    for (const char* column : {"direct_radiance", "indirect_radiance"}) {
      const auto& in = f["interval"][column];
      ASSERT_EQ(in.size(), 2u);
      EXPECT_LE(in[0].get<double>(), f[column].get<double>());
      EXPECT_GE(in[1].get<double>(), f[column].get<double>());
    }
    sumSq += std::pow(0.5 * (f["interval"]["direct_radiance"][1].get<double>() - f["interval"]["direct_radiance"][0].get<double>()), 2);
  }
  const auto& meanDirect = j["mean"]["interval"]["direct_radiance"];
  EXPECT_NEAR(0.5 * (meanDirect[1].get<double>() - meanDirect[0].get<double>()), std::sqrt(sumSq) / 3, 1e-9);
  EXPECT_GT(meanDirect[1].get<double>(), meanDirect[0].get<double>());  // these frames are noisy: a real interval
  EXPECT_NE(r.out.find(" ± "), std::string::npos) << r.out;
  // A 2-degree yaw per frame over a 50-degree-high, 48x27 image, the camera at the origin: the
  // frustum share is the pixels whose centre ray, turned by 2 degrees about +Y, lands outside the
  // span of the image's pixel centres (Eq. 3.3: NDC beyond 1 - 1/width or 1 - 1/height), worked out
  // here with plain trigonometry; by the image's left-right symmetry the direction of the turn does
  // not matter. Near the left and right edges the turn also lifts the top and bottom rows out.
  const double tanV = std::tan(radians(25.0)), tanH = tanV * 48.0 / 27.0, turn = radians(2.0);
  int outside = 0;
  for (int y = 0; y < 27; ++y)
    for (int x = 0; x < 48; ++x) {
      const double dx = ((x + 0.5) / 48 * 2 - 1) * tanH, dy = (1 - (y + 0.5) / 27 * 2) * tanV;  // view space, z = -1
      const double rx = dx * std::cos(turn) - std::sin(turn), rz = -dx * std::sin(turn) - std::cos(turn);
      const double qx = (rx / -rz / tanH + 1) / 2 * 48 - 0.5, qy = (1 - dy / -rz / tanV) / 2 * 27 - 0.5;  // pixel index coordinates
      const bool in = rz < 0 && qx >= -1e-3 && qx <= 47 + 1e-3 && qy >= -1e-3 && qy <= 26 + 1e-3;  // with discard's 1e-3 px slack
      outside += in ? 0 : 1;
    }
  const double expected = 100.0 * outside / (48 * 27);
  const double f1 = j["frames"][0]["frustum"].get<double>();
  EXPECT_GT(outside, 0);
  EXPECT_NEAR(f1, expected, 1e-9) << outside << " pixels";
  EXPECT_NEAR(j["frames"][2]["frustum"].get<double>(), expected, 1e-9);
  EXPECT_NEAR(j["mean"]["frustum"].get<double>(), expected, 1e-9);
  EXPECT_EQ(j["mean"]["world_position"].get<double>(), 0.0);
  const auto csv = test::slurp(dir / "d.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4);
  const auto png = readImageHeader(dir / "plots" / "frames_discard.png");
  ASSERT_TRUE(png) << png.error().message;
  EXPECT_EQ(png->width, 1200);
  const std::string svg = test::slurp(dir / "plots" / "frames_discard.svg");
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("shading normal"), std::string::npos);  // the legend names the features
  auto mask = readImageHeader(dir / "masks" / "discard_00003.png");
  ASSERT_TRUE(mask) << mask.error().message;
  EXPECT_EQ(mask->width, 48);
}

TEST(DiscardCli, BadFramesFoldersFailClearly) {
  const auto dir = test::freshDir("discard_bad");
  writeFrames(dir / "f", 3, 16, 9);
  fs::remove(dir / "f" / "frame_00001.json");
  auto r = dynbench(fmt::format("discard {} --radiance-test expected --json {}", (dir / "f").string(), (dir / "out.json").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("frame_00001.exr: has no frame_00001.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out.json"));

  writeFrames(dir / "g", 2, 16, 9);
  writeFrames(dir / "g2", 2, 20, 9);  // a frame of another size
  fs::copy_file(dir / "g2" / "frame_00001.exr", dir / "g" / "frame_00001.exr", fs::copy_options::overwrite_existing);
  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "g").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("frame_00001.exr: is 20x9 but its sidecar says 16x9"), std::string::npos) << r.err;

  writeFrames(dir / "h", 2, 16, 9);
  FloatImage bare{16, 9, 3, std::vector<float>(16 * 9 * 3, 0.0f), {"P.X", "P.Y", "P.Z"}};
  ASSERT_TRUE(writeImage(dir / "h" / "frame_00001.exr", bare));
  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "h").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("lacks the channel(s) N.X, N.Y, N.Z"), std::string::npos) << r.err;

  writeFrames(dir / "novar", 2, 16, 9, false);
  // Frames without variances (Cycles'): the expected test runs, says what it assumed.
  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "novar").string()), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("no direct.var / indirect.var channels"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.out.find("0.000 ± 0.000"), std::string::npos) << r.out;
  r = dynbench(fmt::format("discard {} --radiance-test expected --noise-aware", (dir / "novar").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("direct.var"), std::string::npos) << r.err;

  writeFrames(dir / "k", 2, 16, 9);
  ASSERT_TRUE(writeFileAtomic(dir / "k" / "frame_00000.json",
                              R"({"format": "dynbench-frame", "version": 1, "width": 16, "height": 9, "camera": {"view": [1, 2]}})"));
  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "k").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("frame_00000.json: /camera/view: expected an array of 16 numbers"), std::string::npos) << r.err;

  // The sidecar's format and version are checked: a file that is not a frame sidecar, and one
  // from a newer dynbench.
  ASSERT_TRUE(writeFileAtomic(dir / "k" / "frame_00000.json", R"({"width": 16, "height": 9})"));
  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "k").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("frame_00000.json: /format: expected \"dynbench-frame\""), std::string::npos) << r.err;
  ASSERT_TRUE(writeFileAtomic(dir / "k" / "frame_00000.json", R"({"format": "dynbench-frame", "version": 2, "width": 16, "height": 9})"));
  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "k").string()), dir);
  EXPECT_EQ(r.status, 6) << r.err;
  EXPECT_NE(r.err.find("frame_00000.json: /version: 2 is not a sidecar version this dynbench reads (it reads 1)"), std::string::npos)
      << r.err;

  r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "nowhere").string()), dir);
  EXPECT_EQ(r.status, 3) << r.err;
  // The default radiance test reads the frames' radiance-change pairs: frames without them are
  // refused, naming the first such frame and the options that help.
  writeFrames(dir / "nopairs", 3, 16, 9);
  r = dynbench(fmt::format("discard {}", (dir / "nopairs").string()), dir);
  EXPECT_EQ(r.status, 5) << r.err;
  EXPECT_NE(r.err.find("frame_00001.exr: no radiance-change pairs"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--radiance-test expected"), std::string::npos) << r.err;
}

// Golden output of `discard` on the analytic frames above (Table 6.7 as Markdown).
TEST(Golden, DiscardMarkdown) {
  const auto dir = test::freshDir("golden_discard");
  writeFrames(dir / "frames", 4, 48, 27);
  const auto r = dynbench(fmt::format("discard {} --radiance-test expected", (dir / "frames").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  test::expectGolden(r.out, "discard.md");
}

}  // namespace
}  // namespace dynbench::discard
