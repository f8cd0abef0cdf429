#pragma once
// A synthetic capture written through the SDK's C API, shared by the capture and convert tests:
// a two-joint skinned "arm" walking along +X, a spinning rigid "crate" absent in frames 4-6, a
// static map model, a static lamp, a "flash" light in frames 2-3 (orange, half as bright in frame 3),
// and a camera yawing 3 degrees and moving 1 unit a frame, with a cut ("respawn") at frame 7;
// frames 100..109 at 60 fps.
#include <cstdint>
#include <filesystem>
#include <string>

#include "convert/convert.h"
#include "core/math.h"
#include "scene/scene.h"
#include "dynbench/capture.h"

namespace dynbench::test {

dbc_dual_quat toC(const DualQuaternion& q);
dbc_dual_quat rigid(double yawDegrees, glm::dvec3 t);

struct Ids {
  uint64_t camera, arm, crate, tree, lamp, flash;
};

void recordModels(dbc_session* s);
Ids recordFrames(dbc_session* s, int frames = 10);
// A fresh folder with the whole capture, closed.
std::filesystem::path writeCapture(const std::string& name);

// The arm's mesh and joint poses as recorded, for tests that recompute skinning by hand.
extern const float kArmPositions[12];
extern const uint16_t kArmJoints[16];
extern const float kArmWeights[16];
dbc_dual_quat armJointPose(int frame, int joint);
dbc_dual_quat armModelPose(int frame);
dbc_dual_quat crateModelPose(int frame);


// A 1x1 PNG (written by hand: IHDR, one zlib-compressed scanline, IEND).
inline constexpr unsigned char kPng[] = {137, 80, 78, 71, 13, 10, 26, 10, 0, 0, 0, 13, 73, 72, 68, 82, 0, 0, 0, 1, 0, 0, 0, 1, 8, 2, 0, 0, 0,
                              144, 119, 83, 222, 0, 0, 0, 12, 73, 68, 65, 84, 120, 156, 99, 248, 223, 192, 0, 0, 4, 1, 1, 128,
                              197, 42, 24, 93, 0, 0, 0, 0, 73, 69, 78, 68, 174, 66, 96, 130};

// The capture above converted (with two 1x1 PNG textures under its data root), for the convert
// and camera tests.
struct Converted {
  std::filesystem::path capture, dataset;
  convert::ConvertReport report;
};
Converted convertFixture(const std::string& name, convert::ConvertOptions options = {});
// The index of the node named `name` (a test failure and -1 when none is).
int nodeNamed(const scene::Scene& s, const std::string& name);
// |a - b| <= 1e-5 relative (absolute below 1).
void expectClose(const glm::dvec3& a, const glm::dvec3& b, const std::string& what);

}  // namespace dynbench::test
