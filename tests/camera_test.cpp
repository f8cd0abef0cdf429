// The camera tools (src/camera): merge-camera replaces a dataset's camera with a recorded run.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "camera/merge_camera.h"
#include "camera/slowed.h"
#include "capture_fixture.h"
#include "core/files.h"
#include "gltf_builder.h"
#include "run_cli.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace dynbench::camera {
namespace {

namespace fs = std::filesystem;
using namespace dynbench::test;

TEST(MergeCamera, CsvPoseLogReplacesTheCameraKeepingRoll) {
  const Converted c = convertFixture("merge_csv");
  const fs::path csv = c.dataset.parent_path() / "headset.csv";
  {
    std::ofstream out(csv);
    out << "time,x,y,z,qx,qy,qz,qw\n";
    for (int k = 0; k < 20; ++k) {
      const glm::dquat q = quatFromYawPitchRoll(radians(5.0 * k), radians(-2.0 * k), radians(10.0 * k));
      out << fmt::format("{},{},{},{},{},{},{},{}\n", 100.0 + 0.05 * k, k, 2, 0, q.x, q.y, q.z, q.w);
    }
  }
  MergeCameraOptions options;
  options.dataset = c.dataset;
  options.run = csv;
  options.output = c.dataset.parent_path() / "vr.gltf";
  options.offsetSeconds = 0.02;
  auto report = mergeCamera(options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->keys, 20u);
  EXPECT_NEAR(report->startTime, 0.02, 1e-6);
  int status = -1;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_EQ(status, 0) << validation;
  auto merged = scene::loadScene(options.output);
  ASSERT_TRUE(merged) << merged.error().message;
  const scene::Evaluator e(*merged);
  const int camera = nodeNamed(*merged, "camera_1");
  for (int k = 0; k < 20; ++k) {
    const double t = static_cast<float>(0.02 + 0.05 * k);
    const RigidPose pose = decomposeRigid(e.worldMatrix(camera, t));
    expectClose(pose.position, {k, 2, 0}, fmt::format("key {}", k));
    const auto euler = eulerYawPitchRoll(pose.rotation);
    EXPECT_NEAR(wrapDegrees(degrees(euler.yaw) - 5.0 * k), 0.0, 1e-3) << k;
    EXPECT_NEAR(wrapDegrees(degrees(euler.pitch) + 2.0 * k), 0.0, 1e-3) << k;
    EXPECT_NEAR(wrapDegrees(degrees(euler.roll) - 10.0 * k), 0.0, 1e-3) << k;  // roll is kept (190 reads as -170)
  }
  // Everything else is untouched: the crate still disappears in frames 4-6.
  EXPECT_FALSE(e.visible(nodeNamed(*merged, "model_3_mapmodel/crate:1"), static_cast<float>(5 / 60.0)));
  // The captured camera's cut (frame 7) belonged to the motion the run replaced: it is gone.
  EXPECT_TRUE(merged->nodes[static_cast<std::size_t>(camera)].cuts.empty());
  // The input dataset still has its own camera.
  auto original = scene::loadScene(c.dataset);
  ASSERT_TRUE(original);
  const scene::Evaluator o(*original);
  expectClose(decomposeRigid(o.worldMatrix(camera, static_cast<float>(3 / 60.0))).position, {0, 1.7f, 3}, "original camera");
}

// The run's poses are world poses: under a parent that moves and turns, merge-camera keys the
// camera's local channels so that its world pose is the run's at every key.
TEST(MergeCamera, CameraUnderAMovingParentGetsTheRunsWorldPoses) {
  const fs::path dir = freshDir("merge_parent");
  test::GltfBuilder b;
  const int rig = b.node({{"name", "rig"}});
  b.channel(rig, "translation", {0, 2}, {0, 0, 0, 10, 1, -4});
  std::vector<float> turn = test::yawQuat(0), end = test::yawQuat(90);
  turn.insert(turn.end(), end.begin(), end.end());
  b.channel(rig, "rotation", {0, 2}, turn);
  const int camera = b.node({{"name", "eye"}, {"camera", b.perspectiveCamera()}, {"translation", {0, 1.5, 0}}});
  b.doc["scenes"][0]["nodes"] = nlohmann::json::array({rig});  // the camera is the rig's child, not a root
  b.doc["nodes"][static_cast<std::size_t>(rig)]["children"] = {camera};
  const fs::path dataset = b.write(dir, "rigged");
  const fs::path csv = dir / "run.csv";
  {
    std::ofstream out(csv);
    out << "time,x,y,z,qx,qy,qz,qw\n";
    for (int k = 0; k < 20; ++k) {
      const glm::dquat q = quatFromYawPitchRoll(radians(3.0 * k), radians(1.0 * k), 0.0);
      out << fmt::format("{},{},{},{},{},{},{},{}\n", 0.1 * k, k, 2, -k, q.x, q.y, q.z, q.w);
    }
  }
  MergeCameraOptions options;
  options.dataset = dataset;
  options.run = csv;
  options.output = dir / "merged.gltf";
  auto report = mergeCamera(options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->cameraNode, camera);
  auto merged = scene::loadScene(options.output);
  ASSERT_TRUE(merged) << merged.error().message;
  const scene::Evaluator e(*merged);
  for (int k = 0; k < 20; ++k) {
    const double t = static_cast<float>(0.1 * k);
    const RigidPose pose = decomposeRigid(e.worldMatrix(camera, t));
    expectClose(pose.position, {k, 2, -k}, fmt::format("key {}", k));
    const auto euler = eulerYawPitchRoll(pose.rotation);
    EXPECT_NEAR(wrapDegrees(degrees(euler.yaw) - 3.0 * k), 0.0, 1e-3) << k;
    EXPECT_NEAR(wrapDegrees(degrees(euler.pitch) - 1.0 * k), 0.0, 1e-3) << k;
  }
  // The rig itself still moves as before.
  expectClose(glm::dvec3(e.worldMatrix(rig, 1.0)[3]), {5, 0.5, -2}, "rig at 1 s");
}

// A dataset whose file name convert had to percent-encode (a space) merges, and the merged
// dataset's own .bin is referenced by an encoded URI that the validator and the loader accept.
TEST(MergeCamera, DatasetNamesWithSpaces) {
  convert::ConvertOptions convertOptions;
  convertOptions.output = freshDir("merge_space_out") / "my dataset.gltf";
  const Converted c = convertFixture("merge_space", convertOptions);
  const fs::path csv = c.dataset.parent_path() / "run.csv";
  std::ofstream(csv) << "0,0,1,2,0,0,0,1\n1,1,1,2,0,0,0,1\n";
  MergeCameraOptions options;
  options.dataset = c.dataset;
  options.run = csv;
  options.output = c.dataset.parent_path() / "my dataset vr.gltf";
  auto report = mergeCamera(options);
  ASSERT_TRUE(report) << report.error().message;
  const auto doc = nlohmann::json::parse(test::slurp(options.output));
  EXPECT_EQ(doc["buffers"][0]["uri"], "my%20dataset%20vr.bin");
  EXPECT_TRUE(fs::exists(c.dataset.parent_path() / "my dataset vr.bin"));
  int status = -1;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_EQ(status, 0) << validation;
  auto merged = scene::loadScene(options.output);
  ASSERT_TRUE(merged) << merged.error().message;
}

TEST(MergeCamera, CameraOnlyCaptureRun) {
  const Converted c = convertFixture("merge_capture");
  const fs::path runDir = freshDir("merge_capture_run");
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open(runDir.c_str(), "headset", &s), DBC_OK);
  const uint64_t id = dbc_new_id(s);
  for (int f = 0; f < 5; ++f) {
    ASSERT_EQ(dbc_frame_begin(s, static_cast<uint64_t>(f), 5.0 + f / 30.0), DBC_OK);
    const float p[] = {1, 1, static_cast<float>(-f)};
    ASSERT_EQ(dbc_camera(s, id, p, 0, 0, 15.0f * f), DBC_OK);
    ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  }
  ASSERT_EQ(dbc_close(s), DBC_OK);
  MergeCameraOptions options;
  options.dataset = c.dataset;
  options.run = runDir;
  options.output = c.dataset.parent_path() / "run2.gltf";
  auto report = mergeCamera(options);
  ASSERT_TRUE(report) << report.error().message;
  auto merged = scene::loadScene(options.output);
  ASSERT_TRUE(merged);
  const scene::Evaluator e(*merged);
  const RigidPose pose = decomposeRigid(e.worldMatrix(nodeNamed(*merged, "camera_1"), static_cast<float>(4 / 30.0)));
  expectClose(pose.position, {1, 1, -4}, "camera at run frame 4");
  EXPECT_NEAR(degrees(eulerYawPitchRoll(pose.rotation).roll), 60.0, 1e-3);
}

TEST(MergeCamera, BadRunsAndPaths) {
  const Converted c = convertFixture("merge_bad");
  const fs::path csv = c.dataset.parent_path() / "bad.csv";
  std::ofstream(csv) << "0,0,0,0,0,0,0,1\n0.1,1,2,3,0,0,0,1\n0.2,1,two,3,0,0,0,1\n";
  MergeCameraOptions options;
  options.dataset = c.dataset;
  options.run = csv;
  options.output = c.dataset.parent_path() / "never.gltf";
  auto r = mergeCamera(options);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("bad.csv:3:"), std::string::npos) << r.error().message;
  EXPECT_FALSE(fs::exists(options.output));
  std::ofstream(csv, std::ios::trunc) << "0,0,0,0,0,0,0,1\n0,1,2,3,0,0,0,1\n";
  r = mergeCamera(options);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("bad.csv:2:"), std::string::npos) << r.error().message;
  std::ofstream(csv, std::ios::trunc) << "0,0,0,0,0,0,0,1\n";
  options.output = freshDir("merge_elsewhere") / "x.gltf";
  r = mergeCamera(options);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kUsage);
  options.output = c.dataset.parent_path() / "y.gltf";
  options.camera = "nobody";
  r = mergeCamera(options);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("nobody"), std::string::npos);
}

// The third camera policy (issue 48): the bot's positions and cuts, its heading averaged over a
// window. A heading turning at a constant rate (the fixture's 3 degrees a frame) is left as it is.
TEST(SlowedTurns, PositionsAndCutsAreTheBotsAndAConstantTurnIsKept) {
  const Converted c = convertFixture("slowed_constant");
  SlowedTurnsOptions options;
  options.window = 0.1;  // 6 frames at 60 fps
  const fs::path out = c.dataset.parent_path() / "slowed.gltf";
  auto report = makeSlowedTurnsDataset(c.dataset, out, c.dataset.parent_path() / "slowed.csv", options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->stretches, 2u);  // the cut at frame 7 splits it
  int status = -1;
  const std::string validation = test::validateGltf(out, status);
  EXPECT_EQ(status, 0) << validation;
  auto original = scene::loadScene(c.dataset);
  auto slowed = scene::loadScene(out);
  ASSERT_TRUE(original && slowed);
  const int camera = nodeNamed(*original, "camera_1");
  const auto& cuts = slowed->nodes[static_cast<std::size_t>(camera)].cuts;
  ASSERT_EQ(cuts.size(), original->nodes[static_cast<std::size_t>(camera)].cuts.size());
  ASSERT_EQ(cuts.size(), 1u);
  EXPECT_NEAR(cuts[0].time, original->nodes[static_cast<std::size_t>(camera)].cuts[0].time, 1e-6);
  const scene::Evaluator a(*original), b(*slowed);
  for (int frame = 0; frame < 10; ++frame) {
    const double t = static_cast<float>(frame / 60.0);
    const RigidPose was = decomposeRigid(a.worldMatrix(camera, t)), is = decomposeRigid(b.worldMatrix(camera, t));
    expectClose(is.position, was.position, fmt::format("frame {}", frame));
    EXPECT_NEAR(wrapDegrees(degrees(eulerYawPitchRoll(is.rotation).yaw - eulerYawPitchRoll(was.rotation).yaw)), 0.0, 1e-3) << frame;
  }
}

// A heading that zig-zags +-10 degrees every key (+10 at even keys): the window's mean. At key 4
// the window of 0.1 s (keys 1-7) holds four -10 and three +10: -10/7 degrees; at key 5 (keys 2-8)
// four +10 and three -10: +10/7.
TEST(SlowedTurns, AZigZagIsAveragedOverTheWindow) {
  const Converted c = convertFixture("slowed_zigzag");
  const fs::path csv = c.dataset.parent_path() / "zigzag.csv";
  {
    std::ofstream run(csv);
    run << "time,x,y,z,qx,qy,qz,qw\n";
    for (int k = 0; k < 10; ++k) {
      const glm::dquat q = quatFromYawPitchRoll(radians(k % 2 ? -10.0 : 10.0), 0.0, 0.0);
      run << fmt::format("{},{},{},{},{},{},{},{}\n", k / 60.0, k, 2, 0, q.x, q.y, q.z, q.w);
    }
  }
  MergeCameraOptions merge;
  merge.dataset = c.dataset, merge.run = csv, merge.output = c.dataset.parent_path() / "zigzag.gltf";
  ASSERT_TRUE(mergeCamera(merge));
  SlowedTurnsOptions options;
  options.window = 0.1;
  const fs::path out = c.dataset.parent_path() / "slowed.gltf";
  ASSERT_TRUE(makeSlowedTurnsDataset(merge.output, out, c.dataset.parent_path() / "slowed.csv", options));
  auto slowed = scene::loadScene(out);
  ASSERT_TRUE(slowed);
  const int camera = nodeNamed(*slowed, "camera_1");
  const scene::Evaluator e(*slowed);
  auto yawAt = [&](int key) { return degrees(eulerYawPitchRoll(decomposeRigid(e.worldMatrix(camera, static_cast<float>(key / 60.0))).rotation).yaw); };
  EXPECT_NEAR(yawAt(4), -10.0 / 7.0, 1e-3);
  EXPECT_NEAR(yawAt(5), 10.0 / 7.0, 1e-3);
  EXPECT_NEAR(yawAt(0), 10.0, 1e-3);  // a stretch keeps its ends
  // Bad options: an error, nothing written.
  options.window = -1;
  const auto bad = makeSlowedTurnsDataset(merge.output, c.dataset.parent_path() / "bad.gltf", c.dataset.parent_path() / "bad.csv", options);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kUsage);
  EXPECT_FALSE(fs::exists(c.dataset.parent_path() / "bad.gltf"));
}

}  // namespace
}  // namespace dynbench::camera
