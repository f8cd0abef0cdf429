// Radiance change by correlated re-shading (PathTracer::renderChanges, frames/radiance_change.h,
// discard's pairs test) against known answers: a frame paired with itself and a static diffuse
// scene under a moving camera change exactly nothing; glossy materials under a moving camera
// change almost nothing, alike for two seeds; one of two coincident lights switched off changes
// exactly the pixels whose light was above the threshold, direct from the frame itself, indirect
// as a brute-force render says; a moving occluder changes the bands its shadow leaves and enters,
// and a few pairs land inside the interval of many.
#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"
#include "discard/discard.h"
#include "frames/radiance_change.h"
#include "render_scenes.h"

namespace dynbench::render {
namespace {

using nlohmann::json;
using frames::ChangeDecision;
using frames::ChangeEstimate;
using frames::decideChange;

TEST(RadianceChange, TheDecisionRuleAtKnownEstimates) {
  const double tau = 1.0;
  EXPECT_EQ(decideChange({2.0, 0.3, 5.0, 8}, tau), ChangeDecision::kChanged);     // 1 > 3 x 0.3
  EXPECT_EQ(decideChange({-2.0, 0.3, 5.0, 8}, tau), ChangeDecision::kChanged);    // either sign
  EXPECT_EQ(decideChange({1.5, 0.3, 5.0, 8}, tau), ChangeDecision::kUndecided);   // 0.5 < 0.9
  EXPECT_EQ(decideChange({0.05, 0.3, 5.0, 8}, tau), ChangeDecision::kUnchanged);  // 0.05 + 0.9 < 1
  EXPECT_EQ(decideChange({0.2, 0.3, 5.0, 8}, tau), ChangeDecision::kUndecided);   // 0.2 + 0.9 > 1
  // All pairs exactly 0: unchanged only once the rule of three's 3 gathered / n is below tau.
  EXPECT_EQ(decideChange({0.0, 0.0, 2.0, 4}, tau), ChangeDecision::kUndecided);   // 1.5
  EXPECT_EQ(decideChange({0.0, 0.0, 2.0, 8}, tau), ChangeDecision::kUnchanged);   // 0.75
  EXPECT_EQ(decideChange({0.0, 0.0, 0.0, 4}, tau), ChangeDecision::kUnchanged);   // nothing a path gathered could differ
  // A buffer black over the whole frame has tau 0: a black pixel (no light gathered, every D 0)
  // is unchanged at once, a pixel whose paths gathered light is not (it could have changed by any
  // amount), and any change at all is one.
  EXPECT_EQ(decideChange({0.0, 0.0, 0.0, 4}, 0.0), ChangeDecision::kUnchanged);
  EXPECT_EQ(decideChange({0.0, 0.0, 1e-9, 4096}, 0.0), ChangeDecision::kUndecided);
  EXPECT_EQ(decideChange({1e-6, 0.0, 1e-6, 4}, 0.0), ChangeDecision::kChanged);
  EXPECT_EQ(decideChange({0.0, 0.0, 0.0, 1}, 0.0), ChangeDecision::kUndecided);  // one pair is still too few
  // Every pair the same non-zero change: exact.
  EXPECT_EQ(decideChange({1.2, 0.0, 3.0, 4}, tau), ChangeDecision::kChanged);
  EXPECT_EQ(decideChange({5.0, 0.0, 5.0, 1}, tau), ChangeDecision::kUndecided);  // one pair has no spread to judge by
  EXPECT_EQ(frames::changeLooks(4), 1);
  EXPECT_EQ(frames::changeLooks(8), 2);
  EXPECT_EQ(frames::changeLooks(256), 7);
  EXPECT_EQ(frames::changeLooks(300), 8);
}

// A glossy or diffuse ball on a diffuse floor with a back wall, lit by a point light (optionally a
// second one at the same place, hidden from frame `hideFrom` on) and a constant environment; the
// ball slides along x by `ballSpeed` units a second.
struct Room {
  scene::Scene scene;
  glm::dvec3 light{0.5, 2.5, 0.5};
  glm::dvec3 ball{0.0, 0.5, 0.0};
  double ballRadius = 0.5, ballSpeed = 0.0;
};

Room room(const std::string& name, bool glossy, double ballSpeed, bool secondLight = false, double hideFrom = 1.0, double ballStart = 0.0,
          int unchangedLights = 0) {
  Room r;
  r.ballSpeed = ballSpeed;
  r.ball.x = ballStart;
  test::GltfBuilder b;
  const int floor = addMaterial(b, glm::dvec3(0.6), 0.0, 1.0, true);
  const int ballMaterial = glossy ? addMaterial(b, glm::dvec3(0.8, 0.3, 0.2), 0.0, 0.5, false) : addMaterial(b, glm::dvec3(0.8, 0.3, 0.2), 0.0, 1.0, true);
  b.node({{"name", "floor"}, {"mesh", addPlane(b, 4.0, 0.0, floor)}});
  b.node({{"name", "wall"}, {"mesh", addMesh(b, {-4, 0, -2, 4, 0, -2, 4, 3, -2, -4, 3, -2}, {0, 1, 2, 0, 2, 3}, floor)}});
  const int ball = b.node({{"name", "ball"}, {"mesh", addSphere(b, glm::dvec3(0.0), r.ballRadius, ballMaterial, 16, 32)},
                           {"translation", {r.ball.x, r.ball.y, r.ball.z}}});
  if (ballSpeed != 0)
    b.channel(ball, "translation", {0.0f, 4.0f},
              {static_cast<float>(r.ball.x), static_cast<float>(r.ball.y), static_cast<float>(r.ball.z),
               static_cast<float>(r.ball.x + 4 * ballSpeed), static_cast<float>(r.ball.y), static_cast<float>(r.ball.z)});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 20.0}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular", "KHR_node_visibility", "KHR_animation_pointer"};
  b.node({{"name", "lamp"}, {"translation", {r.light.x, r.light.y, r.light.z}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  if (secondLight) {
    const int lamp = b.node({{"name", "lamp2"},
                             {"translation", {r.light.x, r.light.y, r.light.z}},
                             {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}, {"KHR_node_visibility", {{"visible", true}}}}}});
    // Visible until hideFrom, then hidden: STEP keys as KHR_animation_pointer defines them.
    const int times = b.accessor({0.0f, static_cast<float>(hideFrom)}, "SCALAR");
    while (b.bin.size() % 4) b.bin.push_back('\0');
    const std::size_t offset = b.bin.size();
    b.bin += std::string("\x01\x00", 2);
    b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", 2}});
    b.doc["accessors"].push_back({{"bufferView", b.doc["bufferViews"].size() - 1}, {"componentType", 5121}, {"count", 2}, {"type", "SCALAR"}});
    b.doc["animations"][0]["samplers"].push_back({{"input", times}, {"output", b.doc["accessors"].size() - 1}, {"interpolation", "STEP"}});
    b.doc["animations"][0]["channels"].push_back(
        {{"sampler", b.doc["animations"][0]["samplers"].size() - 1},
         {"target", {{"path", "pointer"},
                     {"extensions", {{"KHR_animation_pointer", {{"pointer", fmt::format("/nodes/{}/extensions/KHR_node_visibility/visible", lamp)}}}}}}}});
  }
  // Dim point lights without a range on a grid under the ceiling, the same in every frame.
  if (unchangedLights > 0) {
    b.doc["extensions"]["KHR_lights_punctual"]["lights"].push_back({{"type", "point"}, {"intensity", 1.0}});
    const int side = static_cast<int>(std::ceil(std::sqrt(unchangedLights)));
    for (int i = 0; i < unchangedLights; ++i) {
      const double x = -3.0 + 6.0 * (i % side + 0.5) / side, z = -1.8 + 4.0 * (i / side + 0.5) / side;
      b.node({{"name", fmt::format("dim{}", i)}, {"translation", {x, 2.9, z}}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
    }
  }
  r.scene = load(b, name);
  return r;
}

struct Pair {
  FrameBuffers previous, current;  // current carries the pairs
};

// Frames t - dt and t, the second with its radiance-change pairs against the first.
Pair renderPair(const scene::Scene& s, RenderSettings settings, double t, double dt, const RenderCamera& before, const RenderCamera& now) {
  settings.pairs = true;
  auto tracer = tracerFor(s, settings);
  EXPECT_TRUE(tracer);
  Pair p;
  if (!tracer) return p;
  EXPECT_TRUE(tracer->setTime(t - dt, t - 2 * dt));
  p.previous = tracer->render(0, before, before);
  EXPECT_TRUE(tracer->setTime(t, t - dt));
  p.current = tracer->render(1, now, before);
  tracer->renderChanges(1, now, before, p.current);
  for (FrameBuffers* f : {&p.previous, &p.current}) {
    f->camera = (f == &p.previous ? before : now).frameCamera();
    f->frame = f == &p.previous ? 0 : 1;
    f->time = f == &p.previous ? t - dt : t;
  }
  return p;
}

discard::FramePercentages discardPair(const Pair& p) {
  discard::Thresholds t;  // the defaults: the pairs test
  return discard::discardFrame(p.current, p.previous, discard::absoluteThresholds(t, p.current, 0.0)).percentages;
}

RenderSettings smallSettings(std::uint64_t seed) {
  RenderSettings s;
  s.width = 48;
  s.height = 36;
  s.samplesPerPixel = 64;  // the image's luminance floors the unseen-change bound: a fair estimate
  s.seed = seed;
  s.maxPairs = 1024;
  s.constantEnvironment = glm::dvec3(0.3);
  return s;
}

void expectNoChangeAtAll(const Pair& p) {
  ASSERT_TRUE(p.current.hasChanges());
  std::size_t pixelsWithPairs = 0;
  for (std::size_t i = 0; i < p.current.pixelCount(); ++i) {
    for (const auto* change : {&p.current.directChange, &p.current.indirectChange}) {
      ASSERT_EQ((*change)[3 * i], 0.0f) << "pixel " << i;
      ASSERT_EQ((*change)[3 * i + 1], 0.0f) << "pixel " << i;
    }
    pixelsWithPairs += p.current.changePairs[i] >= frames::kFirstPairs ? 1 : 0;
  }
  EXPECT_EQ(pixelsWithPairs, p.current.pixelCount());
  const auto d = discardPair(p);
  EXPECT_EQ(d.direct, 0.0);
  EXPECT_EQ(d.indirect, 0.0);
  ASSERT_TRUE(d.directInterval && d.indirectInterval);
  // Every D is 0, so the column is 0; the interval's top is the share of pixels so bright that the
  // rule of three still allows an unseen change at the pair cap (a few, far below the dagger's 0.5 %).
  EXPECT_EQ(d.directInterval->low, 0.0);
  EXPECT_EQ(d.indirectInterval->low, 0.0);
  EXPECT_EQ(d.directInterval->high, d.directNoisy);
  EXPECT_EQ(d.indirectInterval->high, d.indirectNoisy);
  EXPECT_LT(d.directNoisy, 0.1);
  EXPECT_LT(d.indirectNoisy, 0.1);
}

TEST(RadianceChange, AFramePairedWithItselfChangesExactlyNothing) {
  // Frame t - 1's scene and camera set to t's (dt = 0): both halves compute the same numbers, and
  // the glossy ball, the environment and the light's tree change nothing of that.
  const Room r = room("self_pair", true, 0.5);
  const RenderCamera cam = lookCamera({0.3, 1.6, 3.5}, {-0.1, -0.35, -1}, 50.0, 48, 36);
  for (const std::uint64_t seed : {1u, 7u}) expectNoChangeAtAll(renderPair(r.scene, smallSettings(seed), 1.0, 0.0, cam, cam));
}

TEST(RadianceChange, AStaticDiffuseSceneUnderAMovingCameraChangesExactlyNothing) {
  // Lambertian surfaces reflect alike towards either camera, so re-shading the same points from
  // the moved camera with the same random numbers gives the same paths.
  const Room r = room("moving_camera_diffuse", false, 0.0);
  const RenderCamera before = lookCamera({0.3, 1.6, 3.5}, {-0.1, -0.35, -1}, 50.0, 48, 36);
  const RenderCamera now = lookCamera({0.45, 1.65, 3.4}, {-0.16, -0.33, -1}, 50.0, 48, 36);
  expectNoChangeAtAll(renderPair(r.scene, smallSettings(3), 1.0, 1.0 / 24, before, now));
}

TEST(RadianceChange, AStaticGlossySceneUnderAMovingCameraChangesAlmostNothingAlikeForTwoSeeds) {
  // The ball's highlight moves with the view, a real but small change; the rest is exactly 0.
  const Room r = room("moving_camera_glossy", true, 0.0);
  const RenderCamera before = lookCamera({0.3, 1.6, 3.5}, {-0.1, -0.35, -1}, 50.0, 48, 36);
  const RenderCamera now = lookCamera({0.45, 1.65, 3.4}, {-0.16, -0.33, -1}, 50.0, 48, 36);
  std::vector<discard::FramePercentages> seeds;
  for (const std::uint64_t seed : {1u, 2u}) seeds.push_back(discardPair(renderPair(r.scene, smallSettings(seed), 1.0, 1.0 / 24, before, now)));
  for (const auto& d : seeds) {
    EXPECT_LE(d.direct, 0.5);
    EXPECT_LE(d.indirect, 0.5);
    ASSERT_TRUE(d.directInterval && d.indirectInterval);
  }
  for (const auto& [a, b] : {std::pair{seeds[0], seeds[1]}, {seeds[1], seeds[0]}}) {
    EXPECT_GE(a.direct, b.directInterval->low - 1e-9);
    EXPECT_LE(a.direct, b.directInterval->high + 1e-9);
    EXPECT_GE(a.indirect, b.indirectInterval->low - 1e-9);
    EXPECT_LE(a.indirect, b.indirectInterval->high + 1e-9);
  }
}

TEST(RadianceChange, OneOfTwoCoincidentLightsSwitchedOffChangesExactlyThePixelsItLitAboveTheThreshold) {
  // Two point lights at one place, the second hidden from t = 1 s on; no environment. Every path
  // gathers the lights' sum (the tree sums as many lights as reach a point), so frame t - 1's halves
  // have exactly twice frame t's light: D = -Y_t, with no noise in direct light at the pixel centre.
  const double fps = 24.0, t = 1.0 + 0.5 / fps;  // the first frame with the second light off
  const Room r = room("light_off", false, 0.0, true, 1.0);
  const RenderCamera cam = lookCamera({0.3, 1.6, 3.5}, {-0.1, -0.35, -1}, 50.0, 48, 36);
  RenderSettings settings = smallSettings(5);
  settings.constantEnvironment.reset();
  settings.useEnvironment = false;
  settings.pixelFilter = {PixelFilterType::kCentre, 0.0};
  const Pair p = renderPair(r.scene, settings, t, 1.0 / fps, cam, cam);
  ASSERT_TRUE(p.current.hasChanges());
  const discard::Thresholds absolute = discard::absoluteThresholds(discard::Thresholds{}, p.current, 0.0);
  constexpr double kGrey = 1.7320508075688772;
  // Direct: the share of surface pixels whose frame-t direct luminance (= |D|) exceeds tau / sqrt(3).
  std::size_t expected = 0;
  for (std::size_t i = 0; i < p.current.pixelCount(); ++i) {
    if (p.current.hit[i] <= 0) continue;
    const double y = luminance(rgb(p.current.direct, i));
    EXPECT_NEAR(p.current.directChange[3 * i], -y, 1e-5 * std::max(1.0, y)) << "pixel " << i;
    EXPECT_EQ(p.current.directChange[3 * i + 1], 0.0f) << "pixel " << i;
    if (kGrey * y > absolute.direct) ++expected;
  }
  const auto d = discardPair(p);
  EXPECT_NEAR(d.direct, 100.0 * static_cast<double>(expected) / static_cast<double>(p.current.pixelCount()), 1e-9);
  EXPECT_GT(expected, p.current.pixelCount() / 4);  // the test means something
  // Indirect: brute force, two independent converged renders of the two frames compared pixel by
  // pixel at their own noise (the expected test's answer), agrees within its noise.
  RenderSettings brute = settings;
  brute.samplesPerPixel = 2048;
  brute.pairs = false;
  auto tracer = tracerFor(r.scene, brute);
  ASSERT_TRUE(tracer);
  ASSERT_TRUE(tracer->setTime(t - 1.0 / fps, t - 2.0 / fps));
  FrameBuffers before = tracer->render(10, cam, cam);
  ASSERT_TRUE(tracer->setTime(t, t - 1.0 / fps));
  FrameBuffers now = tracer->render(11, cam, cam);
  before.camera = now.camera = cam.frameCamera();
  discard::Thresholds expectedTest;
  expectedTest.radianceTest = discard::Thresholds::RadianceTest::kExpected;
  const auto bruteForce = discard::discardFrame(now, before, discard::absoluteThresholds(expectedTest, now, 0.0)).percentages;
  EXPECT_GT(d.indirect, 20.0);
  EXPECT_NEAR(d.indirect, bruteForce.indirect, 2.0) << "brute force " << bruteForce.indirect << " interval ["
                                                     << bruteForce.indirectInterval->low << ", " << bruteForce.indirectInterval->high << "]";
}

TEST(RadianceChange, ManyUnchangedLightsCancelInThePairsAsIfEveryLightWereEvaluated) {
  // 48 unchanged lights without a range, more than the 32 a pair's half evaluates at its first
  // vertex (and the 4 at the next), and the second lamp switched off. The unchanged lights are
  // chosen from one tree with the same number in both halves (PairLights), so on every path their
  // light cancels and D is the lamp's light alone, as with every light evaluated (lightsPerPoint
  // 0): at the pixel centre the same direct D for every pair, and the same indirect D pair by pair
  // (4 pairs a pixel, both ways). Each frame's own tree would choose differently in the two halves.
  const double fps = 24.0, t = 1.0 + 0.5 / fps;
  const Room r = room("many_lights", false, 0.0, true, 1.0, 0.0, 48);
  const RenderCamera cam = lookCamera({0.3, 1.6, 3.5}, {-0.1, -0.35, -1}, 50.0, 48, 36);
  RenderSettings settings = smallSettings(5);
  settings.constantEnvironment.reset();
  settings.useEnvironment = false;
  settings.pixelFilter = {PixelFilterType::kCentre, 0.0};
  settings.bounces = 1;
  settings.maxPairs = frames::kFirstPairs;
  const Pair chosen = renderPair(r.scene, settings, t, 1.0 / fps, cam, cam);
  settings.lightsPerPoint = 0;
  const Pair every = renderPair(r.scene, settings, t, 1.0 / fps, cam, cam);
  ASSERT_TRUE(chosen.current.hasChanges() && every.current.hasChanges());
  std::size_t lit = 0;
  for (std::size_t i = 0; i < chosen.current.pixelCount(); ++i) {
    if (chosen.current.hit[i] <= 0) continue;
    const double exact = every.current.directChange[3 * i], y = luminance(rgb(every.current.direct, i));
    EXPECT_NEAR(chosen.current.directChange[3 * i], exact, 1e-5 * std::max(1.0, y)) << "pixel " << i;
    EXPECT_LE(chosen.current.directChange[3 * i + 1], 1e-5 * std::max(1.0, y)) << "pixel " << i;
    const double yIndirect = luminance(rgb(every.current.indirect, i));
    EXPECT_NEAR(chosen.current.indirectChange[3 * i], every.current.indirectChange[3 * i], 1e-5 * std::max(1.0, yIndirect)) << "pixel " << i;
    EXPECT_EQ(chosen.current.changePairs[i], every.current.changePairs[i]) << "pixel " << i;
    if (exact < -1e-3 * y) ++lit;  // the lamp lit it: its light is a share of the pixel's, not rounding
  }
  EXPECT_GT(lit, chosen.current.pixelCount() / 4);  // the test means something
  // ... and the lamp's indirect light changed too, by more than rounding.
  double indirectChange = 0.0;
  for (std::size_t i = 0; i < every.current.pixelCount(); ++i) indirectChange += std::abs(every.current.indirectChange[3 * i]);
  EXPECT_GT(indirectChange, 1e-2 * static_cast<double>(every.current.pixelCount()) * frames::meanLuminance(every.current.indirect));
}

// Whether the segment from floor point p to the light passes through the ball at centre c.
bool shadowed(const glm::dvec3& p, const glm::dvec3& light, const glm::dvec3& c, double radius) {
  const glm::dvec3 d = light - p;
  const double t = std::clamp(glm::dot(c - p, d) / glm::dot(d, d), 0.0, 1.0);
  return glm::length(p + t * d - c) < radius;
}

TEST(RadianceChange, AMovingOccluderChangesTheBandsItsShadowLeavesAndEnters) {
  // The ball slides 12 units a second (1/2 unit, four to five pixels, a frame at 24 fps) under the
  // light: on the floor, direct light changes where the shadow arrives (leading band) and where it
  // leaves (trailing).
  const double fps = 24.0, t = 1.0;
  const Room r = room("moving_occluder", false, 12.0, false, 1.0, -10.5);
  const RenderCamera cam = lookCamera({0.0, 4.0, 2.5}, {0.0, -1.0, -0.55}, 55.0, 48, 36);
  RenderSettings settings = smallSettings(9);
  settings.maxPairs = 1024;
  const Pair many = renderPair(r.scene, settings, t, 1.0 / fps, cam, cam);
  settings.maxPairs = 16;
  const Pair few = renderPair(r.scene, settings, t, 1.0 / fps, cam, cam);
  const auto dMany = discardPair(many), dFew = discardPair(few);
  // The coarse run's interval covers the fine run's answer.
  ASSERT_TRUE(dFew.directInterval && dFew.indirectInterval);
  EXPECT_GE(dMany.direct, dFew.directInterval->low - 1e-9);
  EXPECT_LE(dMany.direct, dFew.directInterval->high + 1e-9);
  EXPECT_GE(dMany.indirect, dFew.indirectInterval->low - 1e-9);
  EXPECT_LE(dMany.indirect, dFew.indirectInterval->high + 1e-9);
  EXPECT_GT(dMany.direct, 1.0);  // the shadow's bands are there
  // The mask against the analytic shadows: floor pixels whose point is shadowed in exactly one of
  // the two frames are the bands; floor pixels away from both shadows' edges must agree.
  const discard::DiscardResult result = discard::discardFrame(many.current, many.previous,
                                                              discard::absoluteThresholds(discard::Thresholds{}, many.current, 0.0));
  const glm::dvec3 ballNow = r.ball + glm::dvec3(r.ballSpeed * t, 0, 0), ballBefore = r.ball + glm::dvec3(r.ballSpeed * (t - 1.0 / fps), 0, 0);
  int band = 0, bandMarked = 0, calm = 0, calmMarked = 0;
  for (std::size_t i = 0; i < many.current.pixelCount(); ++i) {
    if (many.current.hit[i] <= 0 || many.current.id[i] != 0.0f) continue;  // floor pixels only (node 0)
    const glm::dvec3 p = rgb(many.current.position, i);
    // Well inside a band or well outside both shadows: the pixel's footprint (~0.1 unit) not near an edge.
    auto sureShadow = [&](const glm::dvec3& c, bool inside) {
      return shadowed(p, r.light, c, r.ballRadius * (inside ? 0.85 : 1.15)) == inside;
    };
    const bool marked = (result.mask[i] & discard::kDirect) != 0;
    if ((sureShadow(ballNow, true) && sureShadow(ballBefore, false)) || (sureShadow(ballNow, false) && sureShadow(ballBefore, true))) {
      ++band;
      bandMarked += marked;
    } else if (sureShadow(ballNow, false) && sureShadow(ballBefore, false) && glm::length(p - ballNow) > 2.0 && glm::length(p - ballBefore) > 2.0) {
      // (Near the ball its occlusion of the sky, also direct light, moves with it: left out.)
      ++calm;
      calmMarked += marked;
    }
  }
  EXPECT_GE(band, 10);
  EXPECT_EQ(bandMarked, band);
  EXPECT_GT(calm, 300);
  EXPECT_EQ(calmMarked, 0);
}

}  // namespace
}  // namespace dynbench::render
