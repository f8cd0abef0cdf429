#pragma once
// A synthetic capture written through the SDK's C API, shared by the capture and convert tests:
// a two-joint skinned "arm" walking along +X, a spinning rigid "crate" absent in frames 4-6, a
// static map model, a static lamp, a "flash" light in frames 2-3 (orange, half as bright in frame 3),
// and a camera yawing 3 degrees and moving 1 unit a frame, with a cut ("respawn") at frame 7;
// frames 100..109 at 60 fps.
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/math.h"
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

}  // namespace dynbench::test
