#include "capture_fixture.h"

#include <fstream>

#include <gtest/gtest.h>

#include "gltf_builder.h"

namespace dynbench::test {

const float kArmPositions[12] = {0, 0, 0, 1, 0, 0, 1, 2, 0, 0, 2, 0};
const uint16_t kArmJoints[16] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0};
const float kArmWeights[16] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0.25f, 0.75f, 0, 0};

dbc_dual_quat toC(const DualQuaternion& q) {
  return {static_cast<float>(q.real.x), static_cast<float>(q.real.y), static_cast<float>(q.real.z), static_cast<float>(q.real.w),
          static_cast<float>(q.dual.x), static_cast<float>(q.dual.y), static_cast<float>(q.dual.z), static_cast<float>(q.dual.w)};
}

dbc_dual_quat rigid(double yawDegrees, glm::dvec3 t) {
  return toC(dualQuaternionFromRigid(glm::angleAxis(radians(yawDegrees), glm::dvec3(0, 1, 0)), t));
}

// Model space: the shoulder stays at the origin; the elbow (bind position y = 1) bends about Y by
// 10 degrees a frame.
dbc_dual_quat armJointPose(int frame, int joint) { return joint == 0 ? rigid(0, {0, 0, 0}) : rigid(10.0 * frame, {0, 1, 0}); }
dbc_dual_quat armModelPose(int frame) { return rigid(90, {0.1 * frame, 0, 0}); }
dbc_dual_quat crateModelPose(int frame) { return rigid(20.0 * frame, {2, 0, 0}); }

#define DBC_OK_OR_FAIL(call) ASSERT_EQ((call), DBC_OK) << dbc_last_error()

void recordModels(dbc_session* s) {
  const float normals[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
  const uint32_t quad[] = {0, 1, 2, 0, 2, 3};
  DBC_OK_OR_FAIL(dbc_model_begin(s, "chars/arm"));
  dbc_mesh arm{0, "skin", "chars/arm.png", "chars/arm_mask.png", 4, kArmPositions, normals, uvs, kArmJoints, kArmWeights, 2, quad};
  DBC_OK_OR_FAIL(dbc_model_mesh(s, &arm));
  DBC_OK_OR_FAIL(dbc_model_joint(s, 0, "shoulder", -1, rigid(0, {0, 0, 0}), rigid(0, {0, 0, 0})));
  DBC_OK_OR_FAIL(dbc_model_joint(s, 1, "elbow", 0, rigid(0, {0, 1, 0}), rigid(0, {0, -1, 0})));
  DBC_OK_OR_FAIL(dbc_model_end(s));
  const uint32_t tri[] = {0, 1, 2};
  DBC_OK_OR_FAIL(dbc_model_begin(s, "mapmodel/crate:1"));  // a ':' in a path must survive
  dbc_mesh crate{0, nullptr, "crate.jpg", nullptr, 3, kArmPositions, nullptr, nullptr, nullptr, nullptr, 1, tri};
  DBC_OK_OR_FAIL(dbc_model_mesh(s, &crate));
  DBC_OK_OR_FAIL(dbc_model_end(s));
}

Ids recordFrames(dbc_session* s, int frames) {
  Ids ids{dbc_new_id(s), dbc_new_id(s), dbc_new_id(s), dbc_new_id(s), dbc_new_id(s), dbc_new_id(s)};
  for (int f = 0; f < frames; ++f) {
    EXPECT_EQ(dbc_frame_begin(s, static_cast<uint64_t>(100 + f), f / 60.0), DBC_OK) << dbc_last_error();
    const float eye[] = {0, 1.7f, static_cast<float>(f)};
    EXPECT_EQ(dbc_camera(s, ids.camera, eye, -5.0f, 3.0f * f, 0.0f), DBC_OK);
    if (f == 7) EXPECT_EQ(dbc_camera_cut(s, ids.camera, "respawn"), DBC_OK) << dbc_last_error();
    EXPECT_EQ(dbc_static_model(s, ids.tree, "mapmodel/crate:1", rigid(0, {5, 0, 5})), DBC_OK);
    EXPECT_EQ(dbc_model(s, ids.arm, "chars/arm", armModelPose(f)), DBC_OK);
    const dbc_dual_quat pose[] = {armJointPose(f, 0), armJointPose(f, 1)};
    EXPECT_EQ(dbc_joints(s, ids.arm, "chars/arm", 2, pose), DBC_OK) << dbc_last_error();
    if (f < 4 || f > 6) EXPECT_EQ(dbc_model(s, ids.crate, "mapmodel/crate:1", crateModelPose(f)), DBC_OK);
    const float lampAt[] = {0, 5, 0}, white[] = {1, 1, 1}, orange[] = {1, 0.5f, 0};
    EXPECT_EQ(dbc_light(s, ids.lamp, lampAt, white, 40.0f, DBC_FALLOFF_LINEAR, DBC_LIGHT_POINT, 0, nullptr), DBC_OK);
    if (f == 2 || f == 3) {
      const float at[] = {0.5f, 1.5f, static_cast<float>(f)};
      const float fading[] = {orange[0] / 2, orange[1] / 2, orange[2] / 2};  // the flash fades to half in frame 3
      EXPECT_EQ(dbc_light(s, ids.flash, at, f == 2 ? orange : fading, 0.0f, DBC_FALLOFF_QUADRATIC, DBC_LIGHT_POINT, 1, "flash"), DBC_OK);
    }
    EXPECT_EQ(dbc_frame_end(s), DBC_OK) << dbc_last_error();
  }
  return ids;
}

std::filesystem::path writeCapture(const std::string& name) {
  const auto dir = freshDir(name);
  dbc_session* s = nullptr;
  EXPECT_EQ(dbc_open(dir.c_str(), "dynbench tests", &s), DBC_OK) << dbc_last_error();
  const float offset[] = {1, 2, 3};
  EXPECT_EQ(dbc_set_map(s, "testmap", offset), DBC_OK);
  EXPECT_EQ(dbc_set_data_root(s, "/data/game"), DBC_OK);
  EXPECT_EQ(dbc_set_camera_settings(s, 16.0f / 9, 75.0f, 0.1f, 500.0f), DBC_OK);
  recordModels(s);
  recordFrames(s);
  EXPECT_EQ(dbc_close(s), DBC_OK) << dbc_last_error();
  return dir;
}



Converted convertFixture(const std::string& name, convert::ConvertOptions options) {
  Converted c;
  c.capture = writeCapture(name + "_capture");
  const std::filesystem::path dataRoot = freshDir(name + "_data");
  std::filesystem::create_directories(dataRoot / "chars");
  for (const char* texture : {"chars/arm.png", "chars/arm_mask.png"})
    std::ofstream(dataRoot / texture, std::ios::binary).write(reinterpret_cast<const char*>(kPng), sizeof kPng);
  options.capture = c.capture;
  options.dataRoot = dataRoot;
  if (options.output.empty()) options.output = freshDir(name + "_out") / (options.glb ? "dataset.glb" : "dataset.gltf");
  c.dataset = options.output;
  auto report = convert::convertCapture(options);
  EXPECT_TRUE(report) << report.error().message;
  if (report) c.report = *report;
  return c;
}

int nodeNamed(const scene::Scene& s, const std::string& name) {
  for (std::size_t i = 0; i < s.nodes.size(); ++i)
    if (s.nodes[i].name == name) return static_cast<int>(i);
  ADD_FAILURE() << "no node named " << name;
  return -1;
}

// |a - b| <= 1e-5 relative (absolute below 1).
void expectClose(const glm::dvec3& a, const glm::dvec3& b, const std::string& what) {
  EXPECT_LE(glm::length(a - b), 1e-5 * std::max(1.0, glm::length(b))) << what << ": (" << a.x << ", " << a.y << ", " << a.z
                                                                        << ") vs (" << b.x << ", " << b.y << ", " << b.z << ")";
}

}  // namespace dynbench::test
