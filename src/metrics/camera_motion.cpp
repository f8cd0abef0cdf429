#include "metrics/camera_motion.h"

#include <algorithm>
#include <cmath>
#include <charconv>

#include "metrics/properties.h"
#include "scene/queries.h"
#include "scene/pose.h"

namespace dynbench::metrics {

using namespace dynbench::scene;

Summary summarize(const std::vector<double>& values) {
  Summary s;
  if (values.empty()) return s;
  double sum = 0.0;
  for (double v : values) sum += v;
  s.mean = sum / static_cast<double>(values.size());
  double squares = 0.0;  // two passes: exact enough for 10^6 frames, unlike E[x^2] - E[x]^2
  for (double v : values) squares += (v - s.mean) * (v - s.mean);
  s.variance = squares / static_cast<double>(values.size());
  s.max = *std::max_element(values.begin(), values.end());
  return s;
}

namespace {

void setPose(CameraFrame& f, const glm::dvec3& position, const glm::dquat& rotation) {
  f.position = position;
  f.rotation = rotation;
  const EulerYawPitchRoll euler = eulerYawPitchRoll(rotation);
  f.yawDegrees = degrees(euler.yaw);
  f.pitchDegrees = degrees(euler.pitch);
  f.rollDegrees = degrees(euler.roll);
}

void setChange(const CameraFrame& prev, CameraFrame& f) {
  f.positionDelta = glm::length(f.position - prev.position);                      // Eq. (3.1)
  f.rotationDelta = degrees(geodesicAngle(prev.rotation, f.rotation));            // Eq. (2.4)
  f.yawDelta = std::abs(wrapDegrees(f.yawDegrees - prev.yawDegrees));             // Eq. (3.2)
  f.pitchDelta = std::abs(wrapDegrees(f.pitchDegrees - prev.pitchDegrees));
  f.rollDelta = std::abs(wrapDegrees(f.rollDegrees - prev.rollDegrees));
}

}  // namespace

CameraMotionSummary measurePoses(const std::vector<glm::dvec3>& positions, const std::vector<glm::dquat>& rotations) {
  std::vector<double> dPosition, dRotation, dPitch, dYaw, dRoll;
  CameraFrame prev, f;
  for (std::size_t i = 0; i < std::min(positions.size(), rotations.size()); ++i) {
    setPose(f, positions[i], rotations[i]);
    if (i > 0) {
      setChange(prev, f);
      dPosition.push_back(f.positionDelta), dRotation.push_back(f.rotationDelta);
      dPitch.push_back(f.pitchDelta), dYaw.push_back(f.yawDelta), dRoll.push_back(f.rollDelta);
    }
    prev = f;
  }
  return {summarize(dPosition), summarize(dRotation), summarize(dPitch), summarize(dYaw), summarize(dRoll)};
}

Expected<CameraMotion> measureCameraMotion(const Scene& scene, double fps, const std::optional<std::string>& cameraSelector) {
  if (!(fps > 0)) return fail(ErrorCode::kUsage, "--fps must be positive (got {})", fps);
  auto node = selectCameraNode(scene, cameraSelector);
  if (!node) return std::unexpected(node.error());
  CameraMotion motion;
  motion.fps = fps;
  if (*node < 0) return motion;
  motion.hasCamera = true;
  motion.cameraNode = *node;
  const auto& cameraNode = scene.nodes[static_cast<std::size_t>(*node)];
  motion.cameraName = !cameraNode.name.empty() ? cameraNode.name : scene.cameras[static_cast<std::size_t>(cameraNode.camera)].name;

  const auto range = scene.timeRange();
  const std::size_t count = std::max<std::size_t>(1, frameCount(scene, fps));
  const Evaluator evaluator(scene);
  motion.frames.resize(count);
  // [0]: changes that are not cuts; [1]: all changes.
  std::vector<double> dPosition[2], dRotation[2], dPitch[2], dYaw[2], dRoll[2];
  for (std::size_t i = 0; i < count; ++i) {
    CameraFrame& f = motion.frames[i];
    f.frame = i;
    f.time = range.start + static_cast<double>(i) / fps;
    const RigidPose pose = decomposeRigid(evaluator.worldMatrix(*node, f.time));
    setPose(f, pose.position, pose.rotation);
    if (i == 0) continue;
    const CameraFrame& prev = motion.frames[i - 1];
    setChange(prev, f);
    f.cut = cameraCutBetween(cameraNode, prev.time, f.time);
    motion.cuts += f.cut ? 1 : 0;
    for (int all = f.cut ? 1 : 0; all < 2; ++all) {
      dPosition[all].push_back(f.positionDelta);
      dRotation[all].push_back(f.rotationDelta);
      dYaw[all].push_back(f.yawDelta);
      dPitch[all].push_back(f.pitchDelta);
      dRoll[all].push_back(f.rollDelta);
    }
  }
  motion.position = summarize(dPosition[0]);
  motion.rotation = summarize(dRotation[0]);
  motion.pitch = summarize(dPitch[0]);
  motion.yaw = summarize(dYaw[0]);
  motion.roll = summarize(dRoll[0]);
  auto& all = motion.includingCuts;
  all.position = summarize(dPosition[1]);
  all.rotation = summarize(dRotation[1]);
  all.pitch = summarize(dPitch[1]);
  all.yaw = summarize(dYaw[1]);
  all.roll = summarize(dRoll[1]);
  return motion;
}

}  // namespace dynbench::metrics
