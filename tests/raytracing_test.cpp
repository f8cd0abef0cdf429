// The Embree scene: hits equal the analytic intersection and follow the scene model's evaluated
// geometry as it moves, skins and disappears.
#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"
#include "gltf_builder.h"
#include "render/camera.h"
#include "render/raytracing_scene.h"
#include "scene/load.h"

namespace dynbench::render {
namespace {

namespace fs = std::filesystem;

// A 20 x 20 ground quad at y = 0 (normal +Y, node 0) and a unit crate triangle pair (node 1) that
// slides along +X by 1 unit per second and is scaled to 0 from t = 3.
scene::Scene groundAndCrate() {
  test::GltfBuilder b;
  const int ground = b.accessor({-10, 0, -10, -10, 0, 10, 10, 0, 10, 10, 0, -10}, "VEC3");
  const int up = b.accessor({0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, "VEC3");
  const int crate = b.accessor({-0.5f, 1, -0.5f, -0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f}, "VEC3");
  while (b.bin.size() % 4) b.bin.push_back('\0');
  const std::size_t offset = b.bin.size();
  const std::uint16_t quad[6] = {0, 1, 2, 0, 2, 3};
  b.bin.append(reinterpret_cast<const char*>(quad), sizeof quad);
  b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", sizeof quad}});
  b.doc["accessors"].push_back({{"bufferView", b.doc["bufferViews"].size() - 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}});
  const int indices = static_cast<int>(b.doc["accessors"].size()) - 1;
  nlohmann::json groundPrimitive = {{"attributes", {{"POSITION", ground}, {"NORMAL", up}}}, {"indices", indices}};
  nlohmann::json cratePrimitive = {{"attributes", {{"POSITION", crate}}}, {"indices", indices}};
  b.doc["meshes"] = nlohmann::json::array();
  b.doc["meshes"].push_back({{"primitives", nlohmann::json::array({groundPrimitive})}});
  b.doc["meshes"].push_back({{"primitives", nlohmann::json::array({cratePrimitive})}});
  b.node({{"name", "ground"}, {"mesh", 0}});
  const int node = b.node({{"name", "crate"}, {"mesh", 1}});
  b.channel(node, "translation", {0, 10}, {0, 0, 0, 10, 0, 0});
  b.channel(node, "scale", {0, 3}, {1, 1, 1, 0, 0, 0}, "STEP");
  auto scene = scene::loadScene(b.write(test::freshDir("raytracing_scene"), "scene"));
  EXPECT_TRUE(scene) << scene.error().message;
  return std::move(*scene);
}

TEST(RayTracing, GroundHitsEqualTheAnalyticIntersection) {
  const scene::Scene s = groundAndCrate();
  auto rt = RayTracingScene::create(s);
  ASSERT_TRUE(rt) << rt.error().message;
  ASSERT_TRUE((*rt)->update(0.0));
  EXPECT_EQ((*rt)->stats().staticTriangles, 2u);
  EXPECT_EQ((*rt)->stats().dynamicTriangles, 2u);
  // Camera at (0, 5, 8) pitched down 30 degrees.
  glm::dmat4 world = glm::mat4_cast(quatFromYawPitchRoll(0.0, radians(-30.0), 0.0));
  world[3] = glm::dvec4(0, 5, 8, 1);
  scene::Camera lens;
  lens.yfov = radians(50.0);
  lens.znear = 0.1;
  const RenderCamera cam(world, lens, 64, 48);
  int groundHits = 0, crateHits = 0;
  for (int py = 0; py < 48; py += 3)
    for (int px = 0; px < 64; px += 3) {
      const Ray ray = cam.ray(px + 0.5, py + 0.5);
      const SurfaceHit hit = (*rt)->intersect(ray);
      if (ray.direction.y >= 0) {
        EXPECT_FALSE(hit.hit);
        continue;
      }
      // The crate's top (y = 1, |x|, |z| <= 0.5) is in front of the ground where the ray crosses it.
      const double tTop = (1.0 - ray.origin.y) / ray.direction.y;
      const glm::dvec3 top = ray.origin + tTop * ray.direction;
      const double edge = std::max(std::abs(top.x), std::abs(top.z));
      if (std::abs(edge - 0.5) < 1e-3) continue;  // grazing the crate's edge: either answer is right
      if (edge < 0.5) {
        ASSERT_TRUE(hit.hit) << px << "," << py;
        ++crateHits;
        EXPECT_EQ(hit.node, 1) << px << "," << py;
        EXPECT_LT(glm::length(hit.position - top), 1e-4 * std::max(1.0, tTop)) << px << "," << py;
        continue;
      }
      const double t = -ray.origin.y / ray.direction.y;  // the plane y = 0
      const glm::dvec3 expected = ray.origin + t * ray.direction;
      if (std::abs(expected.x) > 9.9 || std::abs(expected.z) > 9.9) continue;  // near the quad's edge
      ASSERT_TRUE(hit.hit) << px << "," << py;
      ++groundHits;
      EXPECT_EQ(hit.node, 0);
      EXPECT_LT(glm::length(hit.position - expected), 1e-4 * std::max(1.0, t)) << px << "," << py;
      EXPECT_NEAR(hit.distance, t, 1e-4 * t);
      EXPECT_NEAR(hit.shadingNormal.y, 1.0, 1e-9);
      EXPECT_NEAR(std::abs(hit.geometricNormal.y), 1.0, 1e-9);
    }
  EXPECT_GT(groundHits, 100);
  EXPECT_GT(crateHits, 0);  // every sampled ray was classified and checked above; the crate was among them
  EXPECT_TRUE((*rt)->occluded({0, 5, 0}, {0, -1, 0}, 10.0));
  EXPECT_FALSE((*rt)->occluded({0, 5, 0}, {0, 1, 0}, 10.0));
  EXPECT_FALSE((*rt)->occluded({0, 5, 0}, {0, -1, 0}, 2.0));  // stops short of the crate top (y = 1)
}

TEST(RayTracing, DynamicGeometryFollowsTheAnimationAndDisappears) {
  const scene::Scene s = groundAndCrate();
  auto rt = RayTracingScene::create(s);
  ASSERT_TRUE(rt);
  const Ray down{{2.2, 5, 0}, {0, -1, 0}};
  ASSERT_TRUE((*rt)->update(0.0));
  EXPECT_EQ((*rt)->intersect(down).node, 0);  // the crate (|x| <= 0.5) is not under x = 2.2 yet
  ASSERT_TRUE((*rt)->update(2.0));  // the crate has slid to x = 2
  SurfaceHit hit = (*rt)->intersect(down);
  EXPECT_EQ(hit.node, 1);
  EXPECT_NEAR(hit.position.y, 1.0, 1e-6);
  EXPECT_NEAR(hit.position.x, 2.2, 1e-6);
  ASSERT_TRUE((*rt)->update(3.0));  // scaled to zero: gone
  hit = (*rt)->intersect({{3.0, 5, 0}, {0, -1, 0}});
  EXPECT_EQ(hit.node, 0);
  EXPECT_EQ((*rt)->stats().dynamicTriangles, 0u);
}

TEST(RayTracing, SkinnedHitsLandOnTheEvaluatedSkin) {
  auto s = scene::loadScene(fs::path(DYNBENCH_TESTDATA_DIR) / "SimpleSkin/SimpleSkin.gltf");
  ASSERT_TRUE(s) << s.error().message;
  auto rt = RayTracingScene::create(*s);
  ASSERT_TRUE(rt);
  const scene::Evaluator e(*s);
  for (double t : {0.0, 2.0, 4.5}) {
    ASSERT_TRUE((*rt)->update(t));
    const auto world = e.worldPositions(0, 0, t);
    const auto& indices = s->meshes[0].primitives[0].indices;
    for (std::size_t tri = 0; tri < indices.size() / 3; ++tri) {
      // Aim at the triangle's centroid from in front (+Z): the hit is that point of the skin.
      const glm::dvec3 centroid = (world[indices[3 * tri]] + world[indices[3 * tri + 1]] + world[indices[3 * tri + 2]]) / 3.0;
      const SurfaceHit hit = (*rt)->intersect({centroid + glm::dvec3(0, 0, 5), {0, 0, -1}});
      ASSERT_TRUE(hit.hit) << t << " " << tri;
      EXPECT_LT(glm::length(hit.position - centroid), 1e-5) << t << " " << tri;
    }
  }
}

}  // namespace
}  // namespace dynbench::render
