// Tables 6.4-6.6 on analytic scenes written by the test, where the answer is known by hand.
#include <cmath>

#include <gtest/gtest.h>

#include "gltf_builder.h"
#include "metrics/camera_motion.h"
#include "scene/queries.h"
#include "scene/load.h"

namespace dynbench::metrics {
namespace {

using test::GltfBuilder;

CameraMotion measure(GltfBuilder& b, const std::string& name, double fps = 24.0) {
  const auto dir = test::freshDir(name);
  auto scene = scene::loadScene(b.write(dir, name));
  EXPECT_TRUE(scene) << scene.error().message;
  auto motion = measureCameraMotion(*scene, fps, std::nullopt);
  EXPECT_TRUE(motion) << motion.error().message;
  return *motion;
}

TEST(CameraMotion, StaticCameraGivesZeros) {
  GltfBuilder b;
  const int cam = b.perspectiveCamera();
  const int n = b.node({{"name", "cam"}, {"camera", cam}, {"translation", {1, 2, 3}}});
  b.channel(n, "translation", {0, 1, 2}, {1, 2, 3, 1, 2, 3, 1, 2, 3});
  const auto m = measure(b, "static");
  ASSERT_TRUE(m.hasCamera);
  EXPECT_EQ(m.frames.size(), 49u);  // 2 s at 24 fps, both ends included
  for (const Summary* s : {&m.position, &m.rotation, &m.pitch, &m.yaw, &m.roll}) {
    EXPECT_EQ(s->mean, 0.0);
    EXPECT_EQ(s->variance, 0.0);
    EXPECT_EQ(s->max, 0.0);
  }
}

TEST(CameraMotion, ConstantSpeedGivesKnownDistancePerFrame) {
  // 48 units along a diagonal in 2 s sampled at 24 fps: exactly 1 unit per frame.
  GltfBuilder b;
  const int n = b.node({{"name", "cam"}, {"camera", b.perspectiveCamera()}});
  const float d = static_cast<float>(48.0 / std::sqrt(2.0));
  b.channel(n, "translation", {0, 2}, {0, 0, 0, d, 0, -d});
  const auto m = measure(b, "speed");
  EXPECT_NEAR(m.position.mean, 1.0, 1e-5);
  EXPECT_NEAR(m.position.variance, 0.0, 1e-9);
  EXPECT_NEAR(m.position.max, 1.0, 1e-5);
  EXPECT_NEAR(m.rotation.max, 0.0, 1e-9);
}

TEST(CameraMotion, CutFramesAreLeftOutOfTheSummariesAndCounted) {
  // 1 unit per frame along -Z at 24 fps for 2 s, except that the camera jumps 100 units along +X
  // between the keys at 24/24 and 25/24 s, a cut its extras record. Without the cut: every change
  // is 1. With it: 47 changes of 1 and one of sqrt(100^2 + 1).
  GltfBuilder b;
  const int n = b.node({{"name", "cam"},
                        {"camera", b.perspectiveCamera()},
                        {"extras", {{"dynbench_camera_cuts", {{{"from", 24 / 24.0f}, {"time", 25 / 24.0f}, {"reason", "respawn"}}}}}}});
  std::vector<float> times, values;
  for (int k = 0; k <= 48; ++k) {
    times.push_back(static_cast<float>(k / 24.0));
    for (float v : {k >= 25 ? 100.0f : 0.0f, 0.0f, -static_cast<float>(k)}) values.push_back(v);
  }
  b.channel(n, "translation", times, values);
  const auto m = measure(b, "cuts");
  EXPECT_EQ(m.cuts, 1u);
  ASSERT_EQ(m.frames.size(), 49u);
  for (const auto& f : m.frames) EXPECT_EQ(f.cut, f.frame == 25) << f.frame;
  EXPECT_NEAR(m.position.mean, 1.0, 1e-4);
  EXPECT_NEAR(m.position.max, 1.0, 1e-4);
  EXPECT_NEAR(m.position.variance, 0.0, 1e-6);
  const double jump = std::sqrt(100.0 * 100.0 + 1.0);
  EXPECT_NEAR(m.includingCuts.position.max, jump, 1e-3);
  EXPECT_NEAR(m.includingCuts.position.mean, (47.0 + jump) / 48.0, 1e-4);
  // At 12 fps the jump lies inside the pair (22/24, 26/24]: frame 13 is the cut.
  const auto half = measure(b, "cuts12", 12.0);
  EXPECT_EQ(half.cuts, 1u);
  for (const auto& f : half.frames) EXPECT_EQ(f.cut, f.frame == 13) << f.frame;
  EXPECT_NEAR(half.position.max, 2.0, 1e-4);
}

TEST(CameraMotion, ConstantYawGivesThatYawAndZeroVariance) {
  // Yaw 7.5 degrees per frame for 48 frames: 360 degrees, crossing the +-180 seam; one key per frame.
  GltfBuilder b;
  const int n = b.node({{"name", "cam"}, {"camera", b.perspectiveCamera()}});
  std::vector<float> times, values;
  for (int k = 0; k <= 48; ++k) {
    times.push_back(static_cast<float>(k / 24.0));
    for (float v : test::yawQuat(7.5 * k)) values.push_back(v);
  }
  b.channel(n, "rotation", times, values);
  const auto m = measure(b, "yaw");
  ASSERT_EQ(m.frames.size(), 49u);
  EXPECT_NEAR(m.yaw.mean, 7.5, 1e-4);
  EXPECT_NEAR(m.yaw.variance, 0.0, 1e-7);
  EXPECT_NEAR(m.yaw.max, 7.5, 1e-4);
  EXPECT_NEAR(m.pitch.mean, 0.0, 1e-6);
  EXPECT_NEAR(m.roll.mean, 0.0, 1e-6);
  EXPECT_NEAR(m.rotation.mean, 7.5, 1e-4);  // a pure yaw: geodesic angle = yaw angle
  EXPECT_NEAR(m.rotation.variance, 0.0, 1e-7);
  EXPECT_NEAR(m.position.max, 0.0, 1e-12);
}

TEST(CameraMotion, PitchAndRollAreSeparated) {
  // Frame 0: identity; frame 1: pitch 10; frame 2: pitch 10 and roll 20 (both via the convention).
  GltfBuilder b;
  const int n = b.node({{"name", "cam"}, {"camera", b.perspectiveCamera()}});
  std::vector<float> values;
  for (auto [pitch, roll] : {std::pair{0.0, 0.0}, std::pair{10.0, 0.0}, std::pair{10.0, 20.0}}) {
    const glm::dquat q = quatFromYawPitchRoll(0.0, radians(pitch), radians(roll));
    values.insert(values.end(), {static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z), static_cast<float>(q.w)});
  }
  b.channel(n, "rotation", {0.0f, 1.0f / 24, 2.0f / 24}, values, "STEP");
  const auto m = measure(b, "pitchroll");
  ASSERT_EQ(m.frames.size(), 3u);
  EXPECT_NEAR(m.frames[1].pitchDelta, 10.0, 1e-4);
  EXPECT_NEAR(m.frames[1].rollDelta, 0.0, 1e-4);
  EXPECT_NEAR(m.frames[2].pitchDelta, 0.0, 1e-4);
  EXPECT_NEAR(m.frames[2].rollDelta, 20.0, 1e-4);
  EXPECT_NEAR(m.pitch.mean, 5.0, 1e-4);
  EXPECT_NEAR(m.pitch.variance, 25.0, 1e-3);  // values {10, 0}: mean 5, population variance 25
  EXPECT_NEAR(m.frames[2].rotationDelta, 20.0, 1e-4);  // roll about the view axis only
}

TEST(CameraMotion, QuaternionSignFlipBetweenKeysGivesZero) {
  // STEP keys alternate q and -q (the same 30-degree yaw): the camera never turns.
  GltfBuilder b;
  const int n = b.node({{"name", "cam"}, {"camera", b.perspectiveCamera()}});
  const auto q = test::yawQuat(30.0);
  std::vector<float> times, values;
  for (int k = 0; k < 10; ++k) {
    times.push_back(static_cast<float>(k / 24.0));
    const float sign = k % 2 ? -1.0f : 1.0f;
    for (float v : q) values.push_back(sign * v);
  }
  b.channel(n, "rotation", times, values, "STEP");
  const auto m = measure(b, "signflip");
  EXPECT_NEAR(m.rotation.max, 0.0, 1e-6);
  EXPECT_NEAR(m.yaw.max, 0.0, 1e-6);
  EXPECT_NEAR(m.pitch.max, 0.0, 1e-6);
  EXPECT_NEAR(m.roll.max, 0.0, 1e-6);
}

TEST(CameraMotion, CameraUnderAnAnimatedParentUsesWorldPose) {
  GltfBuilder b;
  const int rig = b.node({{"name", "rig"}, {"children", {1}}});
  b.doc["nodes"].push_back({{"name", "cam"}, {"camera", b.perspectiveCamera()}, {"translation", {0, 0, 5}}});
  // The rig turns 90 degrees about +Y in 1 s: the camera at radius 5 moves on a circle.
  b.channel(rig, "rotation", {0, 1}, {0, 0, 0, 1, test::yawQuat(90)[0], test::yawQuat(90)[1], test::yawQuat(90)[2], test::yawQuat(90)[3]});
  const auto m = measure(b, "rig");
  ASSERT_EQ(m.frames.size(), 25u);
  EXPECT_NEAR(m.yaw.mean, 90.0 / 24, 1e-4);
  // chord of a 3.75-degree arc of radius 5
  EXPECT_NEAR(m.position.mean, 2 * 5 * std::sin(radians(90.0 / 24 / 2)), 1e-5);
  EXPECT_NEAR(m.frames.back().position.x, 5.0, 1e-5);
}

TEST(CameraMotion, CameraSelection) {
  GltfBuilder b;
  b.doc["cameras"] = {{{"type", "perspective"}, {"name", "overview"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}},
                      {{"type", "perspective"}, {"name", "player"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}}};
  b.node({{"name", "still"}, {"camera", 0}});
  const int moving = b.node({{"name", "eye"}, {"camera", 1}});
  b.channel(moving, "translation", {0, 1}, {0, 0, 0, 24, 0, 0});
  const auto dir = test::freshDir("select");
  auto scene = scene::loadScene(b.write(dir, "select"));
  ASSERT_TRUE(scene);
  EXPECT_EQ(*scene::selectCameraNode(*scene, std::nullopt), moving);  // the first *animated* camera
  EXPECT_EQ(*scene::selectCameraNode(*scene, std::string("0")), 0);
  EXPECT_EQ(*scene::selectCameraNode(*scene, std::string("overview")), 0);
  EXPECT_EQ(*scene::selectCameraNode(*scene, std::string("eye")), moving);
  auto missing = scene::selectCameraNode(*scene, std::string("nope"));
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("overview"), std::string::npos);  // lists what exists
  auto m = measureCameraMotion(*scene, 24.0, std::string("still"));
  ASSERT_TRUE(m);
  EXPECT_EQ(m->position.max, 0.0);
  m = measureCameraMotion(*scene, 24.0, std::nullopt);
  EXPECT_NEAR(m->position.mean, 1.0, 1e-5);
}

TEST(Summary, MeanPopulationVarianceMax) {
  const Summary s = summarize({1, 2, 3, 4});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.variance, 1.25);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  const Summary empty = summarize({});
  EXPECT_EQ(empty.mean, 0.0);
}

}  // namespace
}  // namespace dynbench::metrics
