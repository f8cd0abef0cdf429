// The learned light selection (render/light_visibility.h) against what it promises: a light behind
// a closed wall falls to the defensive share of its importance once learned, the image is the one
// of evaluating every light (unbiased), with less noise than the tree's own selection, and the
// same bytes at one and two threads and on every run.
#include <atomic>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/math.h"
#include "frames/feature_frame.h"
#include "render/light_visibility.h"
#include "render/lights.h"
#include "render/raytracing_scene.h"
#include "render_scenes.h"

namespace dynbench::render {
namespace {

using nlohmann::json;

// A floor y = 0 (half size 5) split by a closed wall x = 0 (height 4, across the floor): `front`
// lights over x < 0, `behind` over x > 0, all at height 1.5 with a range that reaches the whole
// floor. The camera looks down on the front half, where the lights behind give no direct light.
struct WallScene {
  scene::Scene scene;
  std::vector<glm::dvec3> lights;  // positions, front ones first
};

WallScene wallScene(int front, int behind, const std::string& name) {
  WallScene w;
  test::GltfBuilder b;
  const int grey = addMaterial(b, glm::dvec3(0.6), 0.0, 1.0, true);
  b.node({{"mesh", addPlane(b, 5.0, 0.0, grey)}});
  // the wall, two triangles facing -x and two facing +x
  b.node({{"mesh", addMesh(b, {0, 0, -5, 0, 4, -5, 0, 4, 5, 0, 0, 5}, {0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2}, grey)}});
  auto& lights = b.doc["extensions"]["KHR_lights_punctual"]["lights"];
  for (int k = 0; k < front + behind; ++k) {
    const bool isFront = k < front;
    const int i = isFront ? k : k - front;
    const glm::dvec3 at(isFront ? -1.0 - 3.0 * ((i * 7) % 10) / 10.0 : 1.0 + 3.0 * ((i * 3) % 10) / 10.0, 1.5, -4.0 + 8.0 * ((i * 37) % 100) / 100.0);
    lights.push_back({{"type", "point"}, {"intensity", 3.0 + (k % 4)}, {"range", 30.0}});
    b.node({{"translation", {at.x, at.y, at.z}}, {"extensions", {{"KHR_lights_punctual", {{"light", k}}}}}});
    w.lights.push_back(at);
  }
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular"};
  w.scene = load(b, name);
  return w;
}

// A leaf's importance as the tree computes it (LightTree::importance of a one-light node).
double leafImportance(const glm::dvec3& light, double power, double range, const glm::dvec3& p, const glm::dvec3& n) {
  LightTree::Node node;
  node.lower = node.upper = light;
  node.power = power;
  node.range = range;
  node.count = 1;
  return LightTree::importance(node, p, n);
}

// Two lights, one in front of the wall, one behind it: learned from points of the front floor, the
// one behind keeps exactly the defensive share of its importance there, the one in front all of
// it, so that with one light a point the probability of picking the one behind is
// s i_B / (i_A + s i_B) (it was i_B / (i_A + i_B) by the tree alone), measured over a fine grid of u.
TEST(LightVisibility, ALightBehindAClosedWallFallsToTheDefensiveShare) {
  const WallScene w = wallScene(1, 1, "visibility_two_lights");
  auto rt = RayTracingScene::create(w.scene);
  ASSERT_TRUE(rt) << rt.error().message;
  ASSERT_TRUE((*rt)->update(0.0));
  LightSet lights;
  ASSERT_TRUE(lights.build(w.scene, **rt, nullptr, 5.0, [](int, int, unsigned, glm::dvec2) { return glm::dvec3(0.0); }));
  ASSERT_EQ(lights.punctualCount(), 2u);
  std::vector<LightVisibility::Point> points;
  for (double x = -4.5; x < -0.4; x += 0.25)
    for (double z = -4.5; z < 4.6; z += 0.25) points.push_back({{x, 0.0, z}, {0, 1, 0}});
  LightVisibility visibility;
  std::atomic<int> traced = 0;  // learn() calls back from TBB's threads
  visibility.learn(lights, points, 0.5, [&](const LightVisibility::Point& p, const LightSample& s) {
    ++traced;
    return !(*rt)->occluded(p.position + 1e-4 * p.normal, s.direction, s.distance * (1 - 1e-4));
  });
  EXPECT_EQ(traced.load(), 2 * static_cast<int>(points.size())) << "every point sees both lights in reach";
  EXPECT_GT(visibility.cellCount(), 50u);
  const glm::dvec3 p(-2.0, 0.0, 0.5), n(0, 1, 0);
  const float* factors = visibility.factors(p, n);
  ASSERT_NE(factors, nullptr);
  EXPECT_EQ(visibility.factors({-2.0, 0.0, 0.5}, {0, -1, 0}), nullptr) << "the other side of the floor learned nothing";
  EXPECT_EQ(visibility.factors({2.0, 0.0, 0.5}, n), nullptr) << "nor the floor behind the wall";
  // light 0 in front, light 1 behind (the builder's order); power = luminance of intensity (white)
  const double iA = leafImportance(w.lights[0], 3.0, 30.0, p, n), iB = leafImportance(w.lights[1], 4.0, 30.0, p, n);
  const double s = LightVisibility::kDefensiveShare;
  for (const bool learned : {false, true}) {
    const int grid = 1 << 16;
    int behind = 0;
    std::vector<LightTree::Selected> selected;
    double reported = 0;
    for (int k = 0; k < grid; ++k) {
      lights.selectPunctual(p, n, (k + 0.5) / grid, 1, selected, learned ? factors : nullptr);
      ASSERT_EQ(selected.size(), 1u);
      if (selected[0].light == 1) {
        ++behind;
        reported = selected[0].probability;
      }
    }
    const double expected = learned ? s * iB / (iA + s * iB) : iB / (iA + iB);
    EXPECT_NEAR(static_cast<double>(behind) / grid, expected, 2.0 / grid) << "learned " << learned;
    EXPECT_NEAR(reported, expected, 1e-6 * expected) << "learned " << learned;  // the factors are floats
  }
}

// Twelve lights in front of the wall and twelve behind it, one light a shading point: the learned
// selection renders what evaluating every light renders (blocks of 8 x 8 pixels within 5 standard
// errors, direct and indirect), with less direct noise than the tree alone, and mostly picks lights
// in front where the tree alone spends about half its picks behind the wall.
TEST(LightVisibility, LearnedSelectionRendersAsEveryLightWithLessNoise) {
  const WallScene w = wallScene(12, 12, "visibility_wall");
  const RenderCamera cam = lookCamera({-2.5, 5.0, 0.0}, {0, -1, 0}, 50.0, 48, 48);  // the front floor alone
  auto render = [&](bool learned, int lightsPerPoint, std::uint64_t seed) {
    RenderSettings settings;
    settings.samplesPerPixel = 32;
    settings.bounces = 1;
    settings.useEnvironment = false;
    settings.lightsPerPoint = lightsPerPoint;
    settings.learnedLightSelection = learned;
    settings.seed = seed;
    settings.pixelFilter = {PixelFilterType::kCentre, 0.0};
    auto t = tracerFor(w.scene, settings);
    EXPECT_TRUE(t && t->setTime(0, 0));
    return t ? t->render(0, cam, cam) : FrameBuffers{};
  };
  const FrameBuffers learned = render(true, 1, 1), tree = render(false, 1, 1), every = render(false, 0, 2);
  ASSERT_EQ(learned.hit.size(), every.hit.size());
  for (const bool direct : {true, false}) {
    const auto& bl = direct ? learned.direct : learned.indirect;
    const auto& be = direct ? every.direct : every.indirect;
    const auto& vl = direct ? learned.directVariance : learned.indirectVariance;
    const auto& ve = direct ? every.directVariance : every.indirectVariance;
    double worst = 0;
    for (int by = 0; by < 48; by += 8)
      for (int bx = 0; bx < 48; bx += 8) {
        double a = 0, c = 0, var = 0;
        for (int y = by; y < by + 8; ++y)
          for (int x = bx; x < bx + 8; ++x) {
            const auto i = static_cast<std::size_t>(y * 48 + x);
            a += luminance(rgb(bl, i));
            c += luminance(rgb(be, i));
            var += vl[i] + ve[i];
          }
        ASSERT_GT(c, 0.0);
        const double z = std::abs(a - c) / std::sqrt(var);
        worst = std::max(worst, z);
        EXPECT_LT(z, 5.0) << (direct ? "direct" : "indirect") << " block " << bx << "," << by;
      }
    std::printf("%s: worst block z = %.2f\n", direct ? "direct" : "indirect", worst);
  }
  double noiseLearned = 0, noiseTree = 0;
  for (std::size_t i = 0; i < learned.directVariance.size(); ++i) {
    noiseLearned += learned.directVariance[i];
    noiseTree += tree.directVariance[i];
  }
  std::printf("direct variance learned / tree = %.3f\n", noiseLearned / noiseTree);
  EXPECT_LT(noiseLearned, 0.6 * noiseTree);
}

// The pilot and the learning in a fixed order: the same bytes at one and two threads, and on a
// second run.
TEST(LightVisibility, TheSameBytesWhateverTheThreads) {
  const WallScene w = wallScene(12, 12, "visibility_threads");
  const RenderCamera cam = lookCamera({-2.5, 6.0, 0.0}, {0, -1, 0}, 70.0, 40, 30);
  auto render = [&](int threads) {
    RenderSettings settings;
    settings.samplesPerPixel = 4;
    settings.lightsPerPoint = 2;
    settings.useEnvironment = false;
    auto t = tracerFor(w.scene, settings);
    if (!t) {
      ADD_FAILURE() << "no tracer";
      return std::vector<float>{};
    }
    EXPECT_TRUE(t->setTime(0, 0));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    const FrameBuffers f = t->render(5, cam, cam);
    std::vector<float> all;
    for (const auto& spec : frames::contractBuffers()) all.insert(all.end(), (f.*spec.member).begin(), (f.*spec.member).end());
    return all;
  };
  const auto one = render(1), two = render(2), again = render(2);
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(one, two);
  EXPECT_EQ(two, again);
}

}  // namespace
}  // namespace dynbench::render
