// The learned light selection (render/light_visibility.h) against what it promises: the lights
// seen arriving are summed, a light behind a closed wall falls to the defensive share among the
// others, the estimate is the sum over every light (unbiased, also where the pilot was wrong), the
// image is the one of evaluating every light, with less noise than the tree's own selection, and
// the same bytes at one and two threads and on every run.
#include <array>
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

// `extra`: more lights (position, range) after those.
WallScene wallScene(int front, int behind, const std::string& name, const std::vector<std::pair<glm::dvec3, double>>& extra = {}) {
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
  for (std::size_t e = 0; e < extra.size(); ++e) {
    const auto& [at, range] = extra[e];
    lights.push_back({{"type", "point"}, {"intensity", 5.0}, {"range", range}});
    b.node({{"translation", {at.x, at.y, at.z}}, {"extensions", {{"KHR_lights_punctual", {{"light", front + behind + static_cast<int>(e)}}}}}});
    w.lights.push_back(at);
  }
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular"};
  w.scene = load(b, name);
  return w;
}

// Three lights and what the cell of a point on the front floor learns of each, from pilot points
// of the front floor away from the wall (x < -2): light A in front is seen (its shadow rays
// arrived), so its leaf's factor is 0 and it is summed; light B behind the wall reached those
// points unoccluded by range and orientation but never arrived, so it keeps the defensive share s;
// light D in front near the wall, whose short range reaches no pilot point, is unknown and keeps
// 1. At a point near the wall that D does light (the pilot was wrong about it there), the
// estimate must still be the sum over every light: over a fine grid of u (the selection is a
// deterministic function of u), the mean of sum f(l) / p(l) over the selected lights equals the
// sum of f(l) over all lights, f the light's unshadowed irradiance times its true visibility.
TEST(LightVisibility, SeenLightsAreSummedAndTheOthersSampledWithoutBias) {
  WallScene w = wallScene(1, 1, "visibility_three_lights", {{{-0.7, 1.5, 0.2}, 1.6}});
  auto rt = RayTracingScene::create(w.scene);
  ASSERT_TRUE(rt) << rt.error().message;
  ASSERT_TRUE((*rt)->update(0.0));
  LightSet lights;
  ASSERT_TRUE(lights.build(w.scene, **rt, nullptr, 5.0, [](int, int, unsigned, glm::dvec2) { return glm::dvec3(0.0); }));
  ASSERT_EQ(lights.punctualCount(), 3u);  // A, B, D in the builder's order
  std::vector<LightVisibility::Point> points;
  for (double x = -4.5; x < -2.0; x += 0.25)
    for (double z = -4.5; z < 4.6; z += 0.25) points.push_back({{x, 0.0, z}, {0, 1, 0}});
  auto visible = [&](const glm::dvec3& at, const glm::dvec3& normal, const LightSample& sample) {
    return !(*rt)->occluded(at + 1e-4 * normal, sample.direction, sample.distance * (1 - 1e-4));
  };
  LightVisibility visibility;
  visibility.learn(lights, points, 0.5, [&](const LightVisibility::Point& p, const LightSample& sample) { return visible(p.position, p.normal, sample); });
  const glm::dvec3 p(-1.0, 0.0, 0.2), n(0, 1, 0);
  const LightVisibility::Cell cell = visibility.cell(p, n);
  ASSERT_NE(cell.factors, nullptr) << "a coarser cell holds pilot points";
  // The tree's light of each punctual light, and its leaf.
  const LightTree& tree = lights.punctualTree();
  std::array<std::uint32_t, 3> leaf{};
  for (std::uint32_t node = 0; node < tree.nodeCount(); ++node)
    if (tree.nodes()[node].count == 1) leaf[lights.treeLight(tree.nodes()[node].first)] = node;
  std::array<std::uint32_t, 3> treeIndex{};
  for (std::uint32_t k = 0; k < 3; ++k) treeIndex[lights.treeLight(k)] = k;
  EXPECT_EQ(cell.factors[leaf[0]], 0.0f) << "A is seen: summed, never sampled";
  EXPECT_EQ(cell.factors[leaf[1]], static_cast<float>(LightVisibility::kDefensiveShare)) << "B is occluded";
  EXPECT_EQ(cell.factors[leaf[2]], 1.0f) << "D is unknown";
  ASSERT_EQ(cell.seen.size(), 1u);
  EXPECT_EQ(cell.seen[0], treeIndex[0]);
  EXPECT_EQ(cell.typicalReaching, 2u) << "A and B reach the pilot points";

  // f(l) for each light at p: what the integrator adds for it with probability 1.
  std::array<double, 3> f{};
  double exact = 0;
  LightSample sample;
  for (std::size_t l = 0; l < 3; ++l) {
    if (lights.samplePunctual(l, p, sample) && visible(p, n, sample)) f[l] = luminance(sample.radiance) * std::max(0.0, glm::dot(n, sample.direction));
    exact += f[l];
  }
  ASSERT_GT(f[0], 0.0);
  EXPECT_EQ(f[1], 0.0) << "B is behind the wall";
  ASSERT_GT(f[2], 0.0) << "D lights the point";
  const int grid = 1 << 16;
  double mean = 0;
  std::array<int, 3> picked{};
  std::vector<LightTree::Selected> selected;
  for (int k = 0; k < grid; ++k) {
    lights.selectPunctual(p, n, (k + 0.5) / grid, kUnseenLightsPerPoint, selected, {.factors = cell.factors}, cell.seen);
    double estimate = 0;
    for (const auto& s : selected) {
      ++picked[s.light];
      if (s.light == 0) EXPECT_EQ(s.probability, 1.0);
      estimate += f[s.light] / s.probability;
    }
    mean += estimate / grid;
  }
  EXPECT_EQ(picked[0], grid) << "A at every u";
  EXPECT_EQ(picked[1] + picked[2], grid) << "one of the others at every u";
  EXPECT_GT(picked[2], picked[1]) << "the unknown light before the occluded one";
  EXPECT_GT(picked[1], 0) << "the occluded light keeps its defensive share";
  EXPECT_NEAR(mean, exact, 1e-3 * exact) << "unbiased";
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
