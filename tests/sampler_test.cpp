// glTF 2.0 Appendix C interpolation, checked against values worked out by hand.
#include <cmath>

#include <gtest/gtest.h>

#include "core/math.h"
#include "gltf_builder.h"
#include "scene/pose.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

Sampler scalarSampler(Interpolation interpolation, std::vector<float> times, std::vector<float> values) {
  return Sampler{interpolation, std::move(times), std::move(values), 1};
}

double at(const Sampler& s, double t) {
  double v = 0;
  sampleValues(s, t, std::span<double>(&v, 1));
  return v;
}

TEST(Sampler, StepHoldsTheEarlierKey) {
  const auto s = scalarSampler(Interpolation::kStep, {0, 1, 2}, {1, 2, 3});
  EXPECT_EQ(at(s, -1.0), 1.0);  // before the first key: clamp
  EXPECT_EQ(at(s, 0.5), 1.0);
  EXPECT_EQ(at(s, 1.0), 2.0);   // exactly on a key: that key
  EXPECT_EQ(at(s, 1.999), 2.0);
  EXPECT_EQ(at(s, 7.0), 3.0);   // after the last key: clamp
}

TEST(Sampler, LinearInterpolatesComponentwise) {
  const auto s = scalarSampler(Interpolation::kLinear, {0, 1, 3}, {1, 2, 6});
  EXPECT_DOUBLE_EQ(at(s, 0.25), 1.25);
  EXPECT_DOUBLE_EQ(at(s, 2.0), 4.0);  // halfway through [1, 3]: (2 + 6) / 2
  EXPECT_DOUBLE_EQ(at(s, 3.0), 6.0);
}

TEST(Sampler, CubicSplineHermite) {
  // Keys t=0 (v=0, out-tangent b=1) and t=2 (in-tangent a=0, v=1). Stored as [a0 v0 b0 a1 v1 b1].
  // At s=0.5, td=2: p = td*(s^3-2s^2+s)*b0 + (-2s^3+3s^2)*v1 = 2*0.125 + 0.5 = 0.75.
  const auto s = scalarSampler(Interpolation::kCubicSpline, {0, 2}, {9, 0, 1, 0, 1, 9});
  EXPECT_NEAR(at(s, 1.0), 0.75, 1e-12);
  EXPECT_NEAR(at(s, 0.0), 0.0, 1e-12);
  EXPECT_NEAR(at(s, 2.0), 1.0, 1e-12);
  // s=0.25: td*(1/64 - 2/16 + 1/4)*1 + (-2/64 + 3/16)*1 = 2*0.140625 + 0.15625 = 0.4375
  EXPECT_NEAR(at(s, 0.5), 0.4375, 1e-12);
}

TEST(Sampler, LinearRotationIsSlerpOnTheShortestArc) {
  const auto q90 = test::yawQuat(90.0);
  Sampler s{Interpolation::kLinear, {0, 1}, {0, 0, 0, 1, q90[0], q90[1], q90[2], q90[3]}, 4};
  EXPECT_NEAR(degrees(geodesicAngle(glm::dquat(1, 0, 0, 0), sampleRotation(s, 0.5))), 45.0, 1e-5);
  // The same end rotation stored as -q: still 45 degrees halfway, not 135.
  Sampler flipped{Interpolation::kLinear, {0, 1}, {0, 0, 0, 1, -q90[0], -q90[1], -q90[2], -q90[3]}, 4};
  const glm::dquat half = sampleRotation(flipped, 0.5);
  EXPECT_NEAR(degrees(geodesicAngle(glm::dquat(1, 0, 0, 0), half)), 45.0, 1e-5);
  EXPECT_NEAR(degrees(eulerYawPitchRoll(half).yaw), 45.0, 1e-5);
}

TEST(Sampler, CubicSplineRotationIsNormalised) {
  const auto q90 = test::yawQuat(90.0);
  std::vector<float> v = {0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0,  // key 0: a, v, b
                          0, 0, 0, 0, q90[0], q90[1], q90[2], q90[3], 0, 0, 0, 0};
  Sampler s{Interpolation::kCubicSpline, {0, 1}, v, 4};
  const glm::dquat q = sampleRotation(s, 0.5);
  EXPECT_NEAR(glm::length(q), 1.0, 1e-12);
  // With zero tangents the components blend as 0.5/0.5, which is the 45-degree rotation.
  EXPECT_NEAR(degrees(eulerYawPitchRoll(q).yaw), 45.0, 1e-5);
}

// The same three interpolations read back from a glTF file (checks the CUBICSPLINE a/v/b layout).
TEST(Sampler, ThroughTheGltfReader) {
  const auto dir = test::freshDir("sampler_file");
  test::GltfBuilder b;
  const int step = b.node({{"name", "step"}});
  const int linear = b.node({{"name", "linear"}});
  const int cubic = b.node({{"name", "cubic"}});
  b.channel(step, "translation", {0, 1, 2}, {1, 0, 0, 2, 0, 0, 3, 0, 0}, "STEP");
  b.channel(linear, "translation", {0, 1, 3}, {1, 0, 0, 2, 0, 0, 6, 0, 0}, "LINEAR");
  b.channel(cubic, "translation", {0, 2}, {9, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 9, 0, 0}, "CUBICSPLINE");
  auto scene = loadScene(b.write(dir, "samplers"));
  ASSERT_TRUE(scene) << scene.error().message;
  const Evaluator e(*scene);
  EXPECT_EQ(e.worldMatrix(step, 1.5)[3].x, 2.0);
  EXPECT_DOUBLE_EQ(e.worldMatrix(linear, 2.0)[3].x, 4.0);
  EXPECT_NEAR(e.worldMatrix(cubic, 1.0)[3].x, 0.75, 1e-7);
}

TEST(Evaluator, ChildFollowsAnimatedParentAndScaleZeroHides) {
  const auto dir = test::freshDir("hierarchy");
  test::GltfBuilder b;
  const int parent = b.node({{"name", "parent"}, {"children", {1}}});
  b.doc["nodes"].push_back({{"name", "child"}, {"translation", {0, 1, 0}}});
  b.channel(parent, "translation", {0, 1}, {0, 0, 0, 10, 0, 0});
  b.channel(parent, "scale", {0, 1, 2}, {1, 1, 1, 1, 1, 1, 0, 0, 0}, "STEP");
  auto scene = loadScene(b.write(dir, "hierarchy"));
  ASSERT_TRUE(scene) << scene.error().message;
  const Evaluator e(*scene);
  const glm::dvec4 p = e.worldMatrix(1, 0.5)[3];
  EXPECT_DOUBLE_EQ(p.x, 5.0);
  EXPECT_DOUBLE_EQ(p.y, 1.0);
  EXPECT_TRUE(e.visible(1, 1.5));
  EXPECT_FALSE(e.visible(1, 2.0));  // parent scaled to zero at t=2
  ScenePose pose;
  e.evaluate(2.0, pose);
  EXPECT_FALSE(pose.visible[1]);
  e.evaluate(0.5, pose);
  EXPECT_TRUE(pose.visible[1]);
  EXPECT_DOUBLE_EQ(pose.world[1][3].x, 5.0);
}

TEST(Evaluator, LightAndCameraWorldPoses) {
  // A rig turning 90 degrees about +Y over 1 s carries a light 2 units in front of it (-Z) and a
  // camera looking forward; at t = 1 the light sits at (-2, 0, 0) and the camera looks down -X.
  const auto dir = test::freshDir("light_pose");
  test::GltfBuilder b;
  b.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "spot"}}}}}}};
  const int rig = b.node({{"name", "rig"}, {"children", {1, 2}}});
  b.doc["nodes"].push_back({{"name", "light"}, {"translation", {0, 0, -2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["nodes"].push_back({{"name", "eye"}, {"camera", b.perspectiveCamera()}});
  const auto q = test::yawQuat(90);
  b.channel(rig, "rotation", {0, 1}, {0, 0, 0, 1, q[0], q[1], q[2], q[3]});
  auto scene = loadScene(b.write(dir, "light_pose"));
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->nodes[1].light, 0);
  EXPECT_EQ(scene->lights[0].type, Light::Type::kSpot);
  const Evaluator e(*scene);
  const glm::dvec3 light(e.worldMatrix(1, 1.0)[3]);
  EXPECT_NEAR(light.x, -2.0, 1e-6);
  EXPECT_NEAR(light.z, 0.0, 1e-6);
  const glm::dvec3 lightAtHalf(e.worldMatrix(1, 0.5)[3]);
  EXPECT_NEAR(glm::length(lightAtHalf), 2.0, 1e-6);  // on the circle, halfway: 45 degrees
  EXPECT_NEAR(lightAtHalf.x, -std::sqrt(2.0), 1e-5);
  const glm::dvec3 view = glm::dmat3(e.worldMatrix(2, 1.0)) * glm::dvec3(0, 0, -1);
  EXPECT_NEAR(view.x, -1.0, 1e-6);
}

TEST(Evaluator, SimpleSkinVerticesFollowTheirJoints) {
  // SimpleSkin: vertices 0-1 (y = 0) are bound to joint node 1 only; joint node 2 sits at y = 1
  // and rotates about Z. A vertex weighted fully to joint 2 turns with it about (0, 1, 0).
  auto scene = loadScene(std::filesystem::path(DYNBENCH_TESTDATA_DIR) / "SimpleSkin/SimpleSkin.gltf");
  ASSERT_TRUE(scene) << scene.error().message;
  const Evaluator e(*scene);
  const auto& prim = scene->meshes[0].primitives[0];
  for (double t : {0.0, 1.5, 3.0}) {
    const auto world = e.worldPositions(0, 0, t);
    const glm::dmat4 joint2 = e.worldMatrix(2, t) * scene->skins[0].inverseBindMatrices[1];
    for (std::size_t v = 0; v < world.size(); ++v) {
      // Independent expectation: blend the two joint matrices by the vertex weights.
      const glm::dmat4 joint1 = e.worldMatrix(1, t) * scene->skins[0].inverseBindMatrices[0];
      const glm::dvec4 p(glm::dvec3(prim.positions[v]), 1.0);
      const glm::dvec3 expected =
          glm::dvec3(static_cast<double>(prim.weights[v][0]) * ((prim.joints[v][0] == 0 ? joint1 : joint2) * p) +
                     static_cast<double>(prim.weights[v][1]) * ((prim.joints[v][1] == 0 ? joint1 : joint2) * p));
      EXPECT_NEAR(glm::length(world[v] - expected), 0.0, 1e-6) << v;
    }
    // The bottom vertices (fully on the unmoving root joint) never move.
    EXPECT_NEAR(glm::length(world[0] - glm::dvec3(prim.positions[0])), 0.0, 1e-6);
  }
  // At t = 0 the joint is unrotated: vertex 9 (top right) is at its bind position.
  const auto rest = e.worldPositions(0, 0, 0.0);
  EXPECT_NEAR(glm::length(rest[9] - glm::dvec3(prim.positions[9])), 0.0, 1e-6);
}

TEST(Evaluator, NodeVisibilityExtensionAndAnimationPointer) {
  const auto dir = test::freshDir("visibility");
  test::GltfBuilder b;
  const int parent = b.node({{"name", "parent"},
                             {"children", {1}},
                             {"extensions", {{"KHR_node_visibility", {{"visible", true}}}}}});
  b.doc["nodes"].push_back({{"name", "child"}});
  b.doc["extensionsUsed"] = {"KHR_node_visibility", "KHR_animation_pointer"};
  // Visibility keys as KHR_animation_pointer defines them: STEP, unsigned byte booleans.
  const int times = b.accessor({0, 1, 2}, "SCALAR");
  while (b.bin.size() % 4) b.bin.push_back('\0');
  const std::size_t offset = b.bin.size();
  b.bin += std::string("\x01\x00\x01", 3);
  b.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", 3}});
  b.doc["accessors"].push_back({{"bufferView", b.doc["bufferViews"].size() - 1}, {"componentType", 5121}, {"count", 3}, {"type", "SCALAR"}});
  b.doc["animations"] = {{{"samplers", {{{"input", times}, {"output", b.doc["accessors"].size() - 1}, {"interpolation", "STEP"}}}},
                          {"channels", {{{"sampler", 0},
                                         {"target", {{"path", "pointer"},
                                                     {"extensions", {{"KHR_animation_pointer",
                                                                      {{"pointer", "/nodes/0/extensions/KHR_node_visibility/visible"}}}}}}}}}}}};
  auto scene = loadScene(b.write(dir, "visibility"));
  ASSERT_TRUE(scene) << scene.error().message;
  const Evaluator e(*scene);
  EXPECT_TRUE(e.visible(1, 0.5));
  EXPECT_FALSE(e.visible(1, 1.5));  // the parent is switched off, so the child is hidden too
  EXPECT_TRUE(e.visible(1, 2.5));
}

}  // namespace
}  // namespace dynbench::scene
