// The path tracer against known answers: a white furnace, a point light over a diffuse plane, the
// geometry buffers of a plane, two independent estimators of the same image, moving geometry and
// the motion vectors of a camera pan. Noise bounds come from the per-pixel variance buffers the
// renderer writes, so a test fails on a bias, not on bad luck (5 standard errors: a false alarm
// about once in 3.5 million).
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "core/image_io.h"
#include "core/math.h"
#include "gltf_builder.h"
#include "render_scenes.h"
#include "render/path_tracer.h"
#include "scene/pose.h"
#include "scene/load.h"

namespace dynbench::render {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

TEST(Render, WhiteFurnace) {
  // A white Lambertian sphere inside an environment of radiance 1: every path ends in the
  // environment after one bounce, carrying albedo 1, so every pixel's expected radiance is 1
  // and, the sphere being convex, indirect light is exactly 0.
  test::GltfBuilder b;
  const int white = addMaterial(b, glm::dvec3(1.0), 0.0, 1.0, true);
  b.node({{"mesh", addSphere(b, glm::dvec3(0.0), 1.0, white)}});
  const scene::Scene s = load(b, "furnace");
  RenderSettings settings;
  settings.samplesPerPixel = 16;
  settings.constantEnvironment = glm::dvec3(1.0);
  auto tracer = tracerFor(s, settings);
  ASSERT_TRUE(tracer);
  ASSERT_TRUE(tracer->setTime(0.0, 0.0));
  const RenderCamera cam = lookCamera({0, 0, 4}, {0, 0, -1}, 40.0, 64, 64);
  const FrameBuffers f = tracer->render(0, cam, cam);
  double sum = 0.0, variance = 0.0;
  int hits = 0, outliers = 0;
  for (std::size_t i = 0; i < 64 * 64; ++i) {
    const glm::dvec3 d = rgb(f.direct, i);
    EXPECT_EQ(rgb(f.indirect, i), glm::dvec3(0.0)) << "pixel " << i;
    // Every pixel, on the sphere, off it or on its edge, has expectation 1.
    if (std::abs(luminance(d) - 1.0) > 5.0 * std::sqrt(f.directVariance[i]) + 1e-6) ++outliers;
    if (f.hit[i] == 0.0f) continue;
    ++hits;
    sum += luminance(d);
    variance += f.directVariance[i];
  }
  ASSERT_GT(hits, 1000);
  const double mean = sum / hits, standardError = std::sqrt(variance) / hits;
  EXPECT_NEAR(mean, 1.0, 5.0 * standardError) << "standard error " << standardError;
  EXPECT_LT(standardError, 0.01);  // the bound is tight enough to mean something
  EXPECT_LE(outliers, hits / 1000 + 1);
}

struct PlaneScene {
  scene::Scene scene;
  glm::dvec3 light{0.7, 2.0, -0.4};
  double intensity = 30.0, albedo = 0.5;
};

PlaneScene pointLightOverPlane() {
  PlaneScene p;
  test::GltfBuilder b;
  const int grey = addMaterial(b, glm::dvec3(p.albedo), 0.0, 1.0, true);
  b.node({{"name", "plane"}, {"mesh", addPlane(b, 3.0, 0.0, grey)}});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", p.intensity}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular"};
  b.node({{"name", "lamp"}, {"translation", {p.light.x, p.light.y, p.light.z}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  p.scene = load(b, "point_light");
  return p;
}

// Renders the plane of pointLightOverPlane() from above (centre "filter": radiance at the pixel
// centre's hit, exact with one sample) and checks every pixel that sees it: direct radiance the
// analytic (albedo / pi) I h / d^3 times `colour` per channel, no indirect light (a plane cannot
// light itself), no variance, `spp` samples. Returns how many pixels were checked.
int checkAnalyticDirect(const PlaneScene& p, int spp, int w, int h, glm::dvec3 colour, bool learnedSelection = true) {
  RenderSettings settings;
  settings.learnedLightSelection = learnedSelection;
  settings.pixelFilter = {PixelFilterType::kCentre, 0.0};
  settings.samplesPerPixel = spp;
  settings.useEnvironment = false;
  auto tracer = tracerFor(p.scene, settings);
  EXPECT_TRUE(tracer);
  if (!tracer || !tracer->setTime(0.0, 0.0)) return 0;
  const RenderCamera cam = lookCamera({0, 4, 0}, {0, -1, 0}, 60.0, w, h);
  const FrameBuffers f = tracer->render(0, cam, cam);
  int checked = 0;
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const std::size_t i = static_cast<std::size_t>(py * w + px);
      if (f.hit[i] == 0.0f) continue;
      const Ray r = cam.ray(px + 0.5, py + 0.5);
      const glm::dvec3 x = r.origin + r.direction * (-r.origin.y / r.direction.y);
      const double d = glm::length(p.light - x);
      const double analytic = p.albedo / kPi * p.intensity * p.light.y / (d * d * d);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(f.direct[3 * i + static_cast<std::size_t>(c)], analytic * colour[c], 2e-6 * analytic) << px << "," << py << " channel " << c;
        EXPECT_NEAR(f.albedo[3 * i + static_cast<std::size_t>(c)], p.albedo * colour[c], 1e-6) << px << "," << py;
      }
      EXPECT_EQ(rgb(f.indirect, i), glm::dvec3(0.0));
      EXPECT_EQ(f.directVariance[i], 0.0f);
      EXPECT_EQ(f.spp[i], static_cast<float>(spp));
      ++checked;
    }
  return checked;
}

TEST(Render, PointLightOverDiffusePlaneGivesTheAnalyticRadianceWithoutNoise) {
  // L = (albedo / pi) I cos(theta) / d^2 = (albedo / pi) I h / d^3 at a point of the plane y = 0.
  // Punctual light is summed, not sampled, and with the centre "filter" radiance is taken at the
  // pixel centre's hit: one sample gives the exact answer, with zero variance.
  // The same with the learned light selection and with the tree's alone.
  const PlaneScene p = pointLightOverPlane();
  for (const bool learned : {true, false})
    for (const int spp : {1, 4})
      EXPECT_GT(checkAnalyticDirect(p, spp, 80, 60, glm::dvec3(1.0), learned), 3000) << spp << " spp, learned " << learned;
}

TEST(Render, VertexColoursMultiplyTheBaseColour) {
  // glTF's COLOR_0 multiplies the base colour: with (0.5, 0.25, 1) on every vertex the plane's
  // direct radiance and albedo are the analytic ones times that colour, channel by channel.
  PlaneScene p = pointLightOverPlane();
  const glm::vec4 colour(0.5f, 0.25f, 1.0f, 1.0f);
  for (auto& mesh : p.scene.meshes)
    for (auto& prim : mesh.primitives) prim.colors.assign(prim.positions.size(), colour);
  EXPECT_GT(checkAnalyticDirect(p, 1, 40, 30, glm::dvec3(colour)), 700);
}

TEST(Render, ThousandLightsOfWhichTenReachGiveTheImageOfTheTen) {
  // Ten point lights with a range over the plane, and 990 whose range ends before the plane: the
  // light tree must find the ten (and only those) and the image must be the ten's alone.
  const PlaneScene one = pointLightOverPlane();
  auto build = [&](int outOfReach) {
    test::GltfBuilder b;
    const int grey = addMaterial(b, glm::dvec3(one.albedo), 0.0, 1.0, true);
    b.node({{"name", "plane"}, {"mesh", addPlane(b, 3.0, 0.0, grey)}});
    auto& lights = b.doc["extensions"]["KHR_lights_punctual"]["lights"];
    int index = 0;
    for (int k = 0; k < 10; ++k) {
      lights.push_back({{"type", "point"}, {"intensity", one.intensity / 10}, {"range", 50.0}});
      b.node({{"translation", {-1.0 + 0.2 * k, one.light.y, 0.3 * (k % 3)}}, {"extensions", {{"KHR_lights_punctual", {{"light", index++}}}}}});
    }
    for (int k = 0; k < outOfReach; ++k) {
      lights.push_back({{"type", "point"}, {"intensity", 1000.0}, {"range", 0.5}});
      b.node({{"translation", {-2.5 + 0.005 * k, 1.0 + 0.001 * k, 0.2}}, {"extensions", {{"KHR_lights_punctual", {{"light", index++}}}}}});
    }
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular"};
    return load(b, outOfReach ? "thousand_lights" : "ten_lights");
  };
  const scene::Scene ten = build(0), thousand = build(990);
  RenderSettings settings;
  settings.samplesPerPixel = 1;
  settings.lightsPerPoint = 16;  // at least the ten: the tree then selects each with probability 1
  settings.useEnvironment = false;
  auto a = tracerFor(ten, settings), c = tracerFor(thousand, settings);
  ASSERT_TRUE(a && c);
  ASSERT_TRUE(a->setTime(0, 0));
  ASSERT_TRUE(c->setTime(0, 0));
  const RenderCamera cam = lookCamera({0, 4, 0}, {0, -1, 0}, 60.0, 40, 30);
  RenderStatistics statsTen, statsThousand;
  const FrameBuffers fa = a->render(0, cam, cam, nullptr, &statsTen), fc = c->render(0, cam, cam, nullptr, &statsThousand);
  int lit = 0;
  for (std::size_t i = 0; i < fa.hit.size(); ++i) {
    ASSERT_EQ(fa.hit[i], fc.hit[i]);
    for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(fc.direct[3 * i + ch], fa.direct[3 * i + ch], 1e-6 * fa.direct[3 * i + ch] + 1e-12);
    lit += fa.direct[3 * i] > 0;
  }
  EXPECT_GT(lit, 1000);
  EXPECT_EQ(statsThousand.punctualInFrame, 1000u);
  // The cost follows the lights in reach: exactly the ten at every shading point of the plane.
  ASSERT_GT(statsThousand.shadingPoints, 0u);
  EXPECT_EQ(statsThousand.punctualEvaluated, 10 * statsThousand.shadingPoints);
}

TEST(Render, ALightSwitchedOffByNodeVisibilityContributesNothing) {
  const PlaneScene on = pointLightOverPlane();
  test::GltfBuilder b;
  const int grey = addMaterial(b, glm::dvec3(on.albedo), 0.0, 1.0, true);
  b.node({{"name", "plane"}, {"mesh", addPlane(b, 3.0, 0.0, grey)}});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", on.intensity}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular", "KHR_node_visibility"};
  b.node({{"translation", {on.light.x, on.light.y, on.light.z}},
          {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}, {"KHR_node_visibility", {{"visible", false}}}}}});
  const scene::Scene off = load(b, "light_off");
  RenderSettings settings;
  settings.samplesPerPixel = 2;
  settings.useEnvironment = false;
  auto lit = tracerFor(on.scene, settings), dark = tracerFor(off, settings);
  ASSERT_TRUE(lit && dark);
  ASSERT_TRUE(lit->setTime(0, 0));
  ASSERT_TRUE(dark->setTime(0, 0));
  const RenderCamera cam = lookCamera({0, 4, 0}, {0, -1, 0}, 60.0, 40, 30);
  const FrameBuffers fl = lit->render(0, cam, cam), fd = dark->render(0, cam, cam);
  double litSum = 0;
  for (std::size_t i = 0; i < fd.hit.size(); ++i) {
    EXPECT_EQ(fd.direct[3 * i], 0.0f);
    EXPECT_EQ(fd.indirect[3 * i], 0.0f);
    litSum += fl.direct[3 * i];
  }
  EXPECT_GT(litSum, 0.0);  // the same light, visible, does light the plane
}

// PathTracer::lightReach (fidelity's pixels without direct light, without sampling) against the
// geometry of a shadow: a 1 x 1 plate at y = 1 over the floor y = 0, lit from y = 2. The segment
// from a floor point (a, 0, b) to a light point (q, 2, r) crosses y = 1 at ((a + q) / 2, (b + r) / 2),
// so a point light over the centre shadows |a|, |b| < 1 exactly, and a 0.2 x 0.2 emissive square
// there hides all of itself from |a|, |b| < 0.9 (umbra) and none of itself beyond 1.1. The camera
// above sees the floor beyond 2/3 (the plate hides the rest).
TEST(Render, LightReachIsTheShadowsGeometry) {
  enum class Light { kPoint, kEmissiveSquare, kEnvironment, kNone };
  for (const Light light : {Light::kPoint, Light::kEmissiveSquare, Light::kEnvironment, Light::kNone}) {
    SCOPED_TRACE(static_cast<int>(light));
    test::GltfBuilder b;
    const int grey = addMaterial(b, glm::dvec3(0.5), 0.0, 1.0, true);
    b.node({{"mesh", addPlane(b, 3.0, 0.0, grey)}});
    b.node({{"mesh", addPlane(b, 0.5, 1.0, grey)}});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular"};
    if (light == Light::kPoint) {
      b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 10.0}}});
      b.node({{"translation", {0, 2, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    }
    if (light == Light::kEmissiveSquare) b.node({{"mesh", addPlane(b, 0.1, 2.0, addMaterial(b, glm::dvec3(0.0), 0.0, 1.0, true, glm::dvec3(1.0)))}});
    const scene::Scene s = load(b, "light_reach");
    RenderSettings settings;
    settings.samplesPerPixel = 1;
    settings.useEnvironment = light == Light::kEnvironment;
    if (light == Light::kEnvironment) settings.constantEnvironment = glm::dvec3(1.0);
    auto tracer = tracerFor(s, settings);
    ASSERT_TRUE(tracer);
    ASSERT_TRUE(tracer->setTime(0.0, 0.0));
    const RenderCamera cam = lookCamera({0, 4, 0}, {0, -1, 0}, 90.0, 101, 101);
    const FrameBuffers f = tracer->render(0, cam, cam);  // the pixel centres' hits, to judge by
    const std::vector<std::uint8_t> reach = tracer->lightReach(cam);
    ASSERT_EQ(reach.size(), f.hit.size());
    int shadowed = 0, lit = 0;
    for (std::size_t i = 0; i < reach.size(); ++i) {
      if (f.hit[i] == 0.0f) {
        EXPECT_EQ(reach[i], 0) << "pixel " << i << " sees nothing";
        continue;
      }
      const glm::dvec3 x = rgb(f.position, i);
      const double edge = std::max(std::abs(x.x), std::abs(x.z));
      bool expected = light != Light::kNone;  // the plate and the square, seen from above, and open floor
      if (light == Light::kPoint && x.y < 0.5) {
        if (std::abs(edge - 1.0) < 0.02) continue;  // the shadow's edge, within float precision
        expected = edge > 1.0;
      }
      if (light == Light::kEmissiveSquare && x.y < 0.5) {
        if (edge > 0.85 && edge < 1.15) continue;  // the penumbra: four points of the square judge it
        expected = edge >= 1.15;
      }
      EXPECT_EQ(reach[i], expected ? 1 : 0) << "pixel " << i << " at " << x.x << ", " << x.y << ", " << x.z;
      (reach[i] ? lit : shadowed) += 1;
    }
    if (light == Light::kPoint || light == Light::kEmissiveSquare) EXPECT_GT(shadowed, 100);  // the test has a shadow to judge
    EXPECT_EQ(lit > 0, light != Light::kNone);
  }
}

// A closed room (inward-facing walls, floor and ceiling of half size `half`, centred on the origin).
void addRoom(test::GltfBuilder& b, double half, int material) {
  const auto h = static_cast<float>(half);
  auto quad = [&](std::vector<float> corners, glm::vec3 n) {
    b.node({{"mesh", addMesh(b, corners, {0, 1, 2, 0, 2, 3}, material, {n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z})}});
  };
  quad({-h, -h, -h, h, -h, -h, h, -h, h, -h, -h, h}, {0, 1, 0});    // floor
  quad({-h, h, -h, -h, h, h, h, h, h, h, h, -h}, {0, -1, 0});       // ceiling
  quad({-h, -h, -h, -h, -h, h, -h, h, h, -h, h, -h}, {1, 0, 0});    // x = -h
  quad({h, -h, -h, h, h, -h, h, h, h, h, -h, h}, {-1, 0, 0});       // x = +h
  quad({-h, -h, -h, -h, h, -h, h, h, -h, h, -h, -h}, {0, 0, 1});    // z = -h
  quad({-h, -h, h, h, -h, h, h, h, h, -h, h, h}, {0, 0, -1});       // z = +h
}

TEST(Render, ARoomLitByAHundredPointLightsRendersAsEvaluatingEveryLight) {
  // 100 point lights of varied intensity and colour, half of them with a range, in a closed room
  // with a sphere on its floor: the light tree alone (4 lights per shading point, nothing learned,
  // never every light in reach) and the default selection (every light in reach where at most 16
  // reach, the lights learned to arrive summed at the first vertex and one other sampled) must
  // render, within their noise, the image of evaluating every light at every point (lightsPerPoint
  // 0, without the tree; exact for direct light), direct and indirect; the tree must evaluate far
  // fewer lights to do it.
  test::GltfBuilder b;
  const int wall = addMaterial(b, {0.7, 0.6, 0.5}, 0.0, 0.7, false);
  addRoom(b, 5.0, wall);
  b.node({{"mesh", addSphere(b, {0.5, -3.5, 0.5}, 1.5, wall, 12, 24)}});
  auto& lights = b.doc["extensions"]["KHR_lights_punctual"]["lights"];
  for (int k = 0; k < 100; ++k) {
    json light = {{"type", "point"}, {"intensity", 2.0 + 3.0 * (k % 7)}, {"color", {0.5 + 0.5 * (k % 2), 1.0, 0.4 + 0.2 * (k % 4)}}};
    if (k % 2) light["range"] = 2.0 + 0.05 * k;
    lights.push_back(light);
    const double a = 2.4 * k, r = 1.0 + 3.5 * ((k * 37) % 100) / 100.0;
    b.node({{"translation", {r * std::cos(a), -4.5 + 0.09 * k, r * std::sin(a)}}, {"extensions", {{"KHR_lights_punctual", {{"light", k}}}}}});
  }
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  const scene::Scene s = load(b, "hundred_lights");
  const RenderCamera cam = lookCamera({0, 3.5, 4.5}, {0, -0.6, -1}, 80.0, 48, 32);
  RenderSettings tree, learned, every;
  tree.samplesPerPixel = learned.samplesPerPixel = every.samplesPerPixel = 64;
  tree.bounces = learned.bounces = every.bounces = 1;
  tree.useEnvironment = learned.useEnvironment = every.useEnvironment = false;
  tree.lightsPerPoint = 4;
  tree.learnedLightSelection = false;
  tree.everyLightUpTo = 0;
  every.lightsPerPoint = 0;
  every.seed = 2;
  learned.seed = 3;
  ASSERT_TRUE(learned.learnedLightSelection && learned.everyLightUpTo == kEveryLightUpTo && learned.lightsPerPoint == 4) << "the defaults";
  // At the pixel centres, so that evaluating every light is exact (no pixel filter's noise).
  tree.pixelFilter = learned.pixelFilter = every.pixelFilter = {PixelFilterType::kCentre, 0.0};
  auto tt = tracerFor(s, tree), tl = tracerFor(s, learned), te = tracerFor(s, every);
  ASSERT_TRUE(tt && tl && te);
  ASSERT_TRUE(tt->setTime(0, 0));
  ASSERT_TRUE(tl->setTime(0, 0));
  ASSERT_TRUE(te->setTime(0, 0));
  RenderStatistics st, sl, se;
  const FrameBuffers ft = tt->render(0, cam, cam, nullptr, &st), fl = tl->render(0, cam, cam, nullptr, &sl),
                     fe = te->render(0, cam, cam, nullptr, &se);
  for (const auto& [name, frame] : {std::pair<const char*, const FrameBuffers*>{"tree", &ft}, {"learned", &fl}})
    for (const bool direct : {true, false}) {
      const auto& bt = direct ? frame->direct : frame->indirect;
      const auto& be = direct ? fe.direct : fe.indirect;
      const auto& vt = direct ? frame->directVariance : frame->indirectVariance;
      const auto& ve = direct ? fe.directVariance : fe.indirectVariance;
      double worst = 0, sumT = 0, sumE = 0;
      for (int by = 0; by < 32; by += 8)
        for (int bx = 0; bx < 48; bx += 8) {
          double a = 0, c = 0, var = 0;
          for (int y = by; y < by + 8; ++y)
            for (int x = bx; x < bx + 8; ++x) {
              const std::size_t i = static_cast<std::size_t>(y * 48 + x);
              a += luminance(rgb(bt, i));
              c += luminance(rgb(be, i));
              var += vt[i] + ve[i];
            }
          ASSERT_GT(c, 0.0) << "every block of the room is lit";
          const double z = std::abs(a - c) / std::sqrt(var);
          worst = std::max(worst, z);
          EXPECT_LT(z, 5.0) << name << (direct ? " direct" : " indirect") << " block " << bx << "," << by << ": " << a / 64 << " vs " << c / 64;
          sumT += a;
          sumE += c;
        }
      std::printf("%s %s: worst block z = %.2f, mean %s / every = %.4f\n", name, direct ? "direct" : "indirect", worst, name, sumT / sumE);
    }
  // Every light is evaluated exactly without the tree: its direct light has no noise at all.
  for (std::size_t i = 0; i < fe.directVariance.size(); ++i) {
    const double l = luminance(rgb(fe.direct, i));
    EXPECT_LE(fe.directVariance[i], 1e-12 * l * l + 1e-30) << "pixel " << i;  // rounding of the sums alone
  }
  ASSERT_GT(st.shadingPoints, 0u);
  EXPECT_LE(st.punctualEvaluated, 4 * st.shadingPoints);
  EXPECT_GT(static_cast<double>(se.punctualEvaluated) / static_cast<double>(se.shadingPoints), 30.0);
  double directTree = 0, directLearned = 0;
  for (std::size_t i = 0; i < ft.directVariance.size(); ++i) directTree += ft.directVariance[i], directLearned += fl.directVariance[i];
  std::printf("lights a point: tree %.1f, learned %.1f, every %.1f; direct variance learned / tree %.3f\n",
              static_cast<double>(st.punctualEvaluated) / static_cast<double>(st.shadingPoints),
              static_cast<double>(sl.punctualEvaluated) / static_cast<double>(sl.shadingPoints),
              static_cast<double>(se.punctualEvaluated) / static_cast<double>(se.shadingPoints), directLearned / directTree);
  EXPECT_LT(directLearned, 0.5 * directTree) << "the learned selection sums the lights it saw arrive";
}

TEST(Render, SpotLightConeAndRangeWindow) {
  // A spot light straight above the plane: full intensity inside the inner cone, nothing outside
  // the outer cone; and a point light's range window switches light off beyond `range`.
  test::GltfBuilder b;
  const int grey = addMaterial(b, glm::dvec3(1.0), 0.0, 1.0, true);
  b.node({{"mesh", addPlane(b, 10.0, 0.0, grey)}});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] =
      json::array({{{"type", "spot"}, {"intensity", 10.0}, {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.4}}}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_specular"};
  // Rotated so local -Z points down (-Y): 90 degrees about +X.
  const double c = std::cos(kPi / 4), sn = std::sin(kPi / 4);
  b.node({{"translation", {0, 2, 0}}, {"rotation", {-sn, 0, 0, c}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const scene::Scene s = load(b, "spot");
  RenderSettings settings;
  settings.samplesPerPixel = 1;
  settings.useEnvironment = false;
  auto tracer = tracerFor(s, settings);
  ASSERT_TRUE(tracer);
  ASSERT_TRUE(tracer->setTime(0.0, 0.0));
  const RenderCamera cam = lookCamera({0, 6, 0}, {0, -1, 0}, 90.0, 101, 101);
  const FrameBuffers f = tracer->render(0, cam, cam);
  for (std::size_t i = 0; i < f.hit.size(); ++i) {
    const glm::dvec3 x(f.position[3 * i], 0.0, f.position[3 * i + 2]);
    const double angle = std::atan2(glm::length(glm::dvec2(x.x, x.z)), 2.0);
    // One sample per pixel at a random point: only judge pixels well inside or outside the cones.
    if (angle > 0.45) EXPECT_EQ(f.direct[3 * i], 0.0f) << "outside the outer cone";
    if (angle < 0.15) {
      const double d2 = 4.0 + glm::dot(x, x);
      EXPECT_NEAR(f.direct[3 * i], 1.0 / kPi * 10.0 * 2.0 / std::pow(d2, 1.5), 0.03) << "inside the inner cone";
    }
  }
}

TEST(Render, GeometryBuffersOfAPlaneEqualTheAnalyticIntersection) {
  const PlaneScene p = pointLightOverPlane();
  RenderSettings settings;
  settings.samplesPerPixel = 1;
  auto tracer = tracerFor(p.scene, settings);
  ASSERT_TRUE(tracer);
  ASSERT_TRUE(tracer->setTime(0.0, 0.0));
  const int w = 64, h = 48;
  // Looking down at 35 degrees from (0, 2, 5): the far rows see past the plane's edge.
  const RenderCamera cam = lookCamera({0, 2, 5}, {0, -std::tan(radians(35.0)), -1}, 50.0, w, h);
  const FrameBuffers f = tracer->render(0, cam, cam);
  int hits = 0, misses = 0;
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const std::size_t i = static_cast<std::size_t>(py * w + px);
      const Ray r = cam.ray(px + 0.5, py + 0.5);
      const double t = -r.origin.y / r.direction.y;
      const glm::dvec3 x = r.origin + t * r.direction;
      const bool onPlane = t > 0 && std::abs(x.x) < 3 && std::abs(x.z) < 3;
      if (std::abs(std::abs(x.x) - 3) < 0.05 || std::abs(std::abs(x.z) - 3) < 0.05) continue;  // the edge itself
      if (!onPlane) {
        ++misses;
        EXPECT_EQ(f.hit[i], 0.0f);
        EXPECT_EQ(rgb(f.position, i), glm::dvec3(0.0));
        EXPECT_EQ(f.id[i], -1.0f);
        continue;
      }
      ++hits;
      ASSERT_EQ(f.hit[i], 1.0f) << px << "," << py;
      EXPECT_LT(glm::length(rgb(f.position, i) - x), 1e-4 * (1 + glm::length(x)));
      EXPECT_LT(glm::length(rgb(f.normal, i) - glm::dvec3(0, 1, 0)), 1e-6);
      EXPECT_NEAR(f.depth[i], glm::dot(x - cam.position(), -glm::dvec3(cam.world()[2])), 1e-4);
      EXPECT_EQ(f.id[i], 0.0f);  // node 0
      // Albedo averages the jittered samples: the plane's albedo where the whole pixel is on it.
      auto inside = [&](double qx, double qy) {
        const Ray q = cam.ray(qx, qy);
        const glm::dvec3 y = q.origin + q.direction * (-q.origin.y / q.direction.y);
        return q.direction.y < 0 && std::abs(y.x) < 3 && std::abs(y.z) < 3;
      };
      if (inside(px, py) && inside(px + 1, py) && inside(px, py + 1) && inside(px + 1, py + 1))
        EXPECT_NEAR(f.albedo[3 * i], p.albedo, 1e-6);
      // Nothing moved; Embree's single-precision barycentrics put the hit ~1e-7 relative off the
      // exact ray point, a few 1e-5 pixels at the far rows.
      EXPECT_NEAR(f.motion[2 * i], 0.0f, 1e-4);
      EXPECT_NEAR(f.motion[2 * i + 1], 0.0f, 1e-4);
    }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(misses, 100);
}

// Light sampling + MIS (direct + indirect) against BSDF sampling alone (the whole image as one
// "full" render): two independent estimators of the same radiance, compared per 8 x 8 block.
TEST(Render, DirectPlusIndirectEqualsAnIndependentFullRender) {
  test::GltfBuilder b;
  const int floorMaterial = addMaterial(b, {0.8, 0.7, 0.6}, 0.0, 1.0, false);
  const int metal = addMaterial(b, {0.9, 0.6, 0.3}, 1.0, 0.35, false);
  const int lamp = addMaterial(b, glm::dvec3(0.0), 0.0, 1.0, true, {4.0, 3.5, 3.0});
  b.node({{"mesh", addPlane(b, 4.0, 0.0, floorMaterial)}});
  b.node({{"mesh", addSphere(b, {0.3, 0.8, 0.0}, 0.8, metal, 16, 32)}});
  // An emissive quad facing down at y = 2.5.
  b.node({{"mesh", addMesh(b, {-0.8f, 2.5f, -0.8f, 0.8f, 2.5f, -0.8f, 0.8f, 2.5f, 0.8f, -0.8f, 2.5f, 0.8f}, {0, 1, 2, 0, 2, 3}, lamp)}});
  b.doc["extensionsUsed"] = {"KHR_materials_specular"};
  const scene::Scene s = load(b, "mis");
  const RenderCamera cam = lookCamera({0, 2.2, 5}, {0, -0.35, -1}, 50.0, 48, 32);
  RenderSettings settings;
  settings.bounces = 3;
  settings.constantEnvironment = glm::dvec3(0.3, 0.35, 0.5);
  settings.samplesPerPixel = 64;
  auto mis = tracerFor(s, settings);
  settings.nextEventEstimation = false;
  settings.seed = 2;
  auto bsdfOnly = tracerFor(s, settings);
  ASSERT_TRUE(mis && bsdfOnly);
  ASSERT_TRUE(mis->setTime(0, 0));
  ASSERT_TRUE(bsdfOnly->setTime(0, 0));
  const FrameBuffers a = mis->render(0, cam, cam), c = bsdfOnly->render(0, cam, cam);
  int blocks = 0;
  double worst = 0.0;
  for (int by = 0; by < 32; by += 8)
    for (int bx = 0; bx < 48; bx += 8) {
      double sumA = 0, sumC = 0, varA = 0, varC = 0;
      for (int y = by; y < by + 8; ++y)
        for (int x = bx; x < bx + 8; ++x) {
          const std::size_t i = static_cast<std::size_t>(y * 48 + x);
          sumA += luminance(rgb(a.direct, i) + rgb(a.indirect, i));
          sumC += luminance(rgb(c.direct, i) + rgb(c.indirect, i));
          // Variance of a sum of two estimates: at most (sqrt(v1) + sqrt(v2))^2.
          varA += std::pow(std::sqrt(a.directVariance[i]) + std::sqrt(a.indirectVariance[i]), 2);
          varC += std::pow(std::sqrt(c.directVariance[i]) + std::sqrt(c.indirectVariance[i]), 2);
        }
      // Blocks that see only the environment have no noise at all: then the sums must agree.
      const double z = varA + varC > 0 ? std::abs(sumA - sumC) / std::sqrt(varA + varC) : std::abs(sumA - sumC) * 1e6;
      worst = std::max(worst, z);
      EXPECT_LT(z, 5.0) << "block " << bx << "," << by << ": " << sumA / 64 << " vs " << sumC / 64;
      ++blocks;
    }
  EXPECT_EQ(blocks, 24);
  // Light sampling must actually help: it is much less noisy on the lamp-lit floor.
  double noiseA = 0, noiseC = 0;
  for (std::size_t i = 0; i < a.directVariance.size(); ++i) {
    noiseA += a.directVariance[i];
    noiseC += c.directVariance[i];
  }
  EXPECT_LT(noiseA, noiseC);
  std::printf("worst block z = %.2f; direct variance MIS / BSDF-only = %.3f\n", worst, noiseA / noiseC);
}

TEST(Render, SameSeedSameImageWhateverTheThreads) {
  const PlaneScene p = pointLightOverPlane();
  RenderSettings settings;
  settings.samplesPerPixel = 4;
  settings.constantEnvironment = glm::dvec3(0.5);
  const RenderCamera cam = lookCamera({0, 2, 5}, {0, -0.5, -1}, 50.0, 40, 30);
  auto render = [&](std::uint64_t seed, int threads) {
    settings.seed = seed;
    auto t = tracerFor(p.scene, settings);
    if (!t) {  // a lambda cannot ASSERT: fail the test and compare nothing
      ADD_FAILURE() << "no tracer for seed " << seed;
      return std::vector<float>{};
    }
    EXPECT_TRUE(t->setTime(0, 0));
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    const FrameBuffers f = t->render(3, cam, cam);
    std::vector<float> all;  // every buffer of the contract, one after another
    for (const auto& spec : frames::contractBuffers()) all.insert(all.end(), (f.*spec.member).begin(), (f.*spec.member).end());
    return all;
  };
  const auto one = render(7, 1), two = render(7, 2), other = render(8, 2);
  EXPECT_EQ(one, two);
  EXPECT_NE(one, other);
}

// Every machine traces with the same kernels (core/simd.h): the default device is Embree's AVX2
// one, so a render is the same as one run with max_isa=avx2 forced, as an AVX2-only machine runs.
// Before the cap, an AVX-512 machine's default was its AVX-512 kernels, which round hit distances
// differently: the figure printed says on how many values they still differ here.
TEST(Render, TheSameImageOnEveryMachineWithAvx2) {
  test::GltfBuilder b;
  const int wall = addMaterial(b, {0.7, 0.6, 0.5}, 0.0, 0.7, false);
  addRoom(b, 5.0, wall);
  b.node({{"mesh", addSphere(b, {0.5, -3.5, 0.5}, 1.5, wall, 24, 48)}});
  b.node({{"mesh", addSphere(b, {-2.0, -4.0, -1.0}, 1.0, wall, 16, 32)}});
  auto& lights = b.doc["extensions"]["KHR_lights_punctual"]["lights"];
  lights.push_back({{"type", "point"}, {"intensity", 40.0}, {"color", {1.0, 0.9, 0.8}}});
  b.node({{"translation", {1.0, 2.0, 1.0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  const scene::Scene s = load(b, "avx2_room");
  const RenderCamera cam = lookCamera({0, 3.5, 4.5}, {0, -0.6, -1}, 80.0, 64, 48);
  RenderSettings settings;
  settings.samplesPerPixel = 4;
  auto render = [&](const char* embreeConfig) {
    if (embreeConfig) ::setenv("DYNBENCH_EMBREE_CONFIG", embreeConfig, 1);
    auto t = tracerFor(s, settings);
    ::unsetenv("DYNBENCH_EMBREE_CONFIG");
    if (!t) {
      ADD_FAILURE() << "no tracer for " << (embreeConfig ? embreeConfig : "the default device");
      return std::vector<float>{};
    }
    EXPECT_TRUE(t->setTime(0, 0));
    const FrameBuffers f = t->render(0, cam, cam);
    std::vector<float> all;
    for (const auto& spec : frames::contractBuffers()) all.insert(all.end(), (f.*spec.member).begin(), (f.*spec.member).end());
    return all;
  };
  const auto byDefault = render(nullptr), avx2 = render("max_isa=avx2"), widest = render("max_isa=avx512");
  ASSERT_FALSE(byDefault.empty());
  EXPECT_EQ(byDefault, avx2) << "the default device is not the AVX2 one every machine runs";
  std::size_t differing = 0;
  for (std::size_t i = 0; i < std::min(avx2.size(), widest.size()); ++i) differing += avx2[i] != widest[i];
  std::printf("values differing with the machine's widest Embree kernels: %zu of %zu\n", differing, avx2.size());
}

TEST(Render, PathsTracedInBatchesComputeExactlyWhatOnePathAtATimeDoes) {
  // The batched tracer prefetches, draws the light sample's random numbers early and streams
  // rays to Embree; none of that may change a bit. A scene that exercises every such step:
  // textures (base colour, metallic-roughness, an alpha mask), an image environment with a sun,
  // an emissive quad, a point light, metal and glossy surfaces, and converging pixels.
  const fs::path dir = test::freshDir("batches");
  FloatImage checker{16, 16, 4, std::vector<float>(16 * 16 * 4), {}};
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 4; ++c)
        checker.pixels[static_cast<std::size_t>((y * 16 + x) * 4 + c)] =
            c == 3 ? ((x / 2 + y) % 5 ? 1.0f : 0.0f) : static_cast<float>(((x / 4 + y / 4) % 2 ? 200 : 40 + 60 * c)) / 255.0f;
  ASSERT_TRUE(writeImage(dir / "checker.png", checker));
  FloatImage sky{32, 16, 3, std::vector<float>(32 * 16 * 3, 0.3f), {}};
  for (int c = 0; c < 3; ++c) sky.pixels[static_cast<std::size_t>((4 * 32 + 9) * 3 + c)] = 400.0f;
  ASSERT_TRUE(writeImage(dir / "sky.hdr", sky));

  test::GltfBuilder b;
  b.doc["images"] = json::array({{{"uri", "checker.png"}}});
  b.doc["textures"] = json::array({{{"source", 0}}});
  b.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 0}}}}},
                                {"alphaMode", "MASK"}});
  const int textured = static_cast<int>(b.doc["materials"].size()) - 1;
  const int metal = addMaterial(b, glm::dvec3(0.9, 0.7, 0.4), 1.0, 0.3, false);
  const int glossy = addMaterial(b, glm::dvec3(0.2, 0.4, 0.8), 0.0, 0.2, false);
  const int lamp = addMaterial(b, glm::dvec3(0.0), 0.0, 1.0, true, glm::dvec3(8.0, 6.0, 4.0));
  const int floor = addMesh(b, {-4, 0, -4, -4, 0, 4, 4, 0, 4, 4, 0, -4}, {0, 1, 2, 0, 2, 3}, textured, {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0});
  b.doc["meshes"][floor]["primitives"][0]["attributes"]["TEXCOORD_0"] = b.accessor(std::vector<float>{0, 0, 0, 3, 3, 3, 3, 0}, "VEC2");
  b.node({{"mesh", floor}});
  b.node({{"mesh", addMesh(b, {-4, -1, -4, 4, -1, -4, 4, -1, 4, -4, -1, 4}, {0, 1, 2, 0, 2, 3}, glossy)}});
  b.node({{"mesh", addSphere(b, glm::dvec3(-0.8, 0.7, 0.0), 0.7, metal)}});
  b.node({{"mesh", addSphere(b, glm::dvec3(0.9, 0.5, 0.5), 0.5, glossy)}});
  b.node({{"mesh", addMesh(b, {-1, 2.5, -2, 1, 2.5, -2, 1, 3.5, -2}, {0, 1, 2}, lamp)}});
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 20.0}}});
  b.node({{"translation", {1.5, 2.0, 1.5}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["extensions"]["DYNBENCH_environment"] = {{"uri", "sky.hdr"}};
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "DYNBENCH_environment"};
  auto loaded = scene::loadScene(b.write(dir, "batches"));
  ASSERT_TRUE(loaded) << loaded.error().message;
  const RenderCamera cam = lookCamera({0, 2.5, 5}, {0, -0.5, -1}, 50.0, 24, 16);

  auto render = [&](int batch, bool converge, FrameBuffers* frame = nullptr) {
    RenderSettings settings;
    // 37 samples: batches of 32, 64 or 100 paths span two or three pixels, starting and ending
    // inside them; in converging rounds, several pixels' next samples share batches.
    settings.samplesPerPixel = 37;
    settings.bounces = 5;
    settings.pathBatch = batch;
    settings.converge = converge;
    settings.maxSamplesPerPixel = 300;
    auto t = tracerFor(*loaded, settings);
    if (!t) {  // a lambda cannot ASSERT: fail the test and compare nothing
      ADD_FAILURE() << "no tracer for batch " << batch;
      return std::make_pair(std::vector<float>{}, std::uint64_t{0});
    }
    EXPECT_TRUE(t->setTime(0, 0));
    RenderStatistics statistics;
    const FrameBuffers f = t->render(2, cam, cam, nullptr, &statistics);
    if (frame) *frame = f;
    std::vector<float> all;  // every buffer of the contract, one after another
    for (const auto& spec : frames::contractBuffers()) all.insert(all.end(), (f.*spec.member).begin(), (f.*spec.member).end());
    return std::make_pair(all, statistics.rays);
  };
  for (const bool converge : {false, true}) {
    FrameBuffers frame;
    const auto one = render(1, converge, &frame);
    for (const int batch : {5, 32, 64, 100}) {
      const auto batched = render(batch, converge);
      EXPECT_EQ(batched.first, one.first) << "batch " << batch << (converge ? ", converging" : "");
      EXPECT_EQ(batched.second, one.second) << "rays traced, batch " << batch;
    }
    // Not a comparison of black images: direct and indirect light arrive, some pixels converged
    // early and others took more samples.
    double direct = 0, indirect = 0;
    for (std::size_t i = 0; i < frame.pixelCount(); ++i) {
      direct += luminance(rgb(frame.direct, i));
      indirect += luminance(rgb(frame.indirect, i));
    }
    EXPECT_GT(direct, 0.1 * static_cast<double>(frame.pixelCount()));
    EXPECT_GT(indirect, 0.01 * static_cast<double>(frame.pixelCount()));
    if (converge) EXPECT_LT(*std::min_element(frame.spp.begin(), frame.spp.end()), *std::max_element(frame.spp.begin(), frame.spp.end()));
  }
  RenderSettings bad;
  bad.pathBatch = 0;
  std::vector<std::string> warnings;
  EXPECT_FALSE(PathTracer::create(*loaded, bad, warnings));
}

// Distance from a point to a triangle (Ericson, Real-Time Collision Detection §5.1.5).
double pointTriangleDistance(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  const double denom = 1.0 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

TEST(Render, PositionBufferFollowsTheSkinnedMesh) {
  auto s = scene::loadScene(fs::path(DYNBENCH_TESTDATA_DIR) / "SimpleSkin" / "SimpleSkin.gltf");
  ASSERT_TRUE(s) << s.error().message;
  RenderSettings settings;
  settings.samplesPerPixel = 1;
  settings.useEnvironment = false;
  auto tracer = tracerFor(*s, settings);
  ASSERT_TRUE(tracer);
  const scene::Evaluator evaluator(*s);
  const RenderCamera cam = lookCamera({0.5, 1.0, 4.0}, {0, 0, -1}, 45.0, 48, 64);
  for (double t : {0.0, 1.5, 3.5}) {
    ASSERT_TRUE(tracer->setTime(t, t - 1.0 / 24));
    const FrameBuffers f = tracer->render(0, cam, cam);
    std::vector<glm::dvec3> world;
    const int meshNode = 0;
    world = evaluator.worldPositions(meshNode, 0, t);
    const auto& indices = s->meshes[0].primitives[0].indices;
    int hits = 0;
    for (std::size_t i = 0; i < f.hit.size(); ++i) {
      if (f.hit[i] == 0.0f) continue;
      ++hits;
      double best = 1e30;
      for (std::size_t k = 0; k < indices.size(); k += 3)
        best = std::min(best, pointTriangleDistance(rgb(f.position, i), world[indices[k]], world[indices[k + 1]], world[indices[k + 2]]));
      EXPECT_LT(best, 1e-5) << "t = " << t;
    }
    EXPECT_GT(hits, 50) << "t = " << t;
  }
}

TEST(Render, MotionOfACameraPanIsExact) {
  // A pure yaw by angle a: a pixel centre's direction (x, y, -1) in camera space (x, y at the
  // image plane z = -1) is, in the previous camera (turned by -a about +Y relative to this one),
  // (x cos a - sin a, y, -x sin a - cos a)... written out below with the pinhole model.
  const PlaneScene p = pointLightOverPlane();
  RenderSettings settings;
  settings.samplesPerPixel = 1;
  settings.useEnvironment = false;
  auto tracer = tracerFor(p.scene, settings);
  ASSERT_TRUE(tracer);
  ASSERT_TRUE(tracer->setTime(0, 0));
  const int w = 64, h = 36;
  const double yfov = radians(50.0), a = radians(4.0), tanHalf = std::tan(yfov / 2), aspect = double(w) / h;
  const glm::dvec3 eye(0, 2, 1);
  auto camera = [&](double yaw) {
    glm::dmat4 world = glm::mat4_cast(quatFromYawPitchRoll(yaw, radians(-40.0), 0.0));
    world[3] = glm::dvec4(eye, 1);
    scene::Camera lens;
    lens.yfov = yfov;
    lens.znear = 0.01;
    return RenderCamera(world, lens, w, h);
  };
  const RenderCamera now = camera(0.0), before = camera(a);
  const FrameBuffers f = tracer->render(0, now, before);
  int checked = 0;
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const std::size_t i = static_cast<std::size_t>(py * w + px);
      if (f.hit[i] == 0.0f) continue;
      // The world direction of this pixel, rotated into the previous camera's frame: the previous
      // camera's basis is this one's turned by +a about world +Y.
      const glm::dvec3 local((2 * (px + 0.5) / w - 1) * tanHalf * aspect, (1 - 2 * (py + 0.5) / h) * tanHalf, -1);
      const glm::dmat3 r = glm::dmat3(now.world());
      const glm::dvec3 d = r * local;
      const glm::dvec3 dPrev(d.x * std::cos(a) - d.z * std::sin(a), d.y, d.x * std::sin(a) + d.z * std::cos(a));  // R_y(-a) d
      const glm::dvec3 q = glm::transpose(r) * dPrev;  // in the previous camera's own axes
      const double xPrev = (q.x / -q.z / (tanHalf * aspect) + 1) * w / 2, yPrev = (1 - q.y / -q.z / tanHalf) * h / 2;
      EXPECT_NEAR(f.motion[2 * i], xPrev - (px + 0.5), 2e-3) << px << "," << py;
      EXPECT_NEAR(f.motion[2 * i + 1], yPrev - (py + 0.5), 2e-3) << px << "," << py;
      ++checked;
    }
  EXPECT_GT(checked, 500);
}

TEST(Render, MotionOfATranslatingObject) {
  // A quad at height 1 sliding +X at 1.2 units/s under a camera looking straight down from y = 5:
  // at depth 4 a pixel spans 2 * 4 * tan(yfov/2) / h units, so the motion is -1.2/24 of that, in x.
  test::GltfBuilder b;
  const int grey = addMaterial(b, glm::dvec3(0.5), 0.0, 1.0, true);
  const int quad = b.node({{"mesh", addPlane(b, 0.5, 1.0, grey)}});
  b.channel(quad, "translation", {0, 10}, {0, 0, 0, 12, 0, 0});
  const scene::Scene s = load(b, "slide");
  RenderSettings settings;
  settings.samplesPerPixel = 1;
  settings.useEnvironment = false;
  auto tracer = tracerFor(s, settings);
  ASSERT_TRUE(tracer);
  const int w = 64, h = 64;
  const RenderCamera cam = lookCamera({0, 5, 0}, {0, -1, 0}, 40.0, w, h);
  ASSERT_TRUE(tracer->setTime(1.0, 1.0 - 1.0 / 24));
  const FrameBuffers f = tracer->render(24, cam, cam);
  const double unitsPerPixel = 2.0 * 4.0 * std::tan(radians(20.0)) / h;
  int checked = 0;
  for (std::size_t i = 0; i < f.hit.size(); ++i) {
    if (f.hit[i] == 0.0f) continue;
    // The camera's +X is world +X when looking down with up = -Z: moving +X moves right.
    EXPECT_NEAR(f.motion[2 * i], -(1.2 / 24) / unitsPerPixel, 1e-3);
    EXPECT_NEAR(f.motion[2 * i + 1], 0.0, 1e-3);
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

}  // namespace
}  // namespace dynbench::render
