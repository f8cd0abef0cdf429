#pragma once
// Camera motion: the thesis's Tables 6.4-6.6 and the series behind Figures A.1 and A.2.
// Definitions, units and conventions: docs/metrics.md.
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/math.h"
#include "scene/scene.h"

namespace dynbench::metrics {

// Mean, population variance (divided by n) and maximum of a per-frame quantity; all 0 for no data.
struct Summary {
  double mean = 0.0;
  double variance = 0.0;
  double max = 0.0;
};
Summary summarize(const std::vector<double>& values);

struct CameraFrame {
  std::size_t frame = 0;
  double time = 0.0;               // seconds
  glm::dvec3 position{0.0};        // world position, scene units
  glm::dquat rotation{1, 0, 0, 0};  // world orientation
  double yawDegrees = 0.0, pitchDegrees = 0.0, rollDegrees = 0.0;  // docs/metrics.md convention
  // Change from the previous frame (0 for frame 0):
  double positionDelta = 0.0;    // Eq. (3.1), scene units per frame
  double rotationDelta = 0.0;    // Eq. (2.4) as the full rotation angle, degrees per frame
  double yawDelta = 0.0, pitchDelta = 0.0, rollDelta = 0.0;  // Eq. (3.2), |wrapped difference|, degrees
  bool cut = false;  // the camera cut (jumped) since the previous frame: scene::cameraCutBetween
};

// Tables 6.4-6.6 of a camera: summaries of its per-frame changes.
struct CameraMotionSummary {
  Summary position;  // Table 6.4, scene units per frame
  Summary rotation;  // Table 6.5, degrees per frame
  Summary pitch, yaw, roll;  // Table 6.6, degrees per frame
};

// Over the changes of frames 1..N-1 that are not cuts (a cut is a jump, not motion).
struct CameraMotion : CameraMotionSummary {
  bool hasCamera = false;
  int cameraNode = -1;
  std::string cameraName;
  double fps = 0.0;
  std::vector<CameraFrame> frames;
  std::size_t cuts = 0;  // frames 1..N-1 that are cuts
  // The same over all N-1 changes, cuts included.
  CameraMotionSummary includingCuts;
};

Expected<CameraMotion> measureCameraMotion(const scene::Scene& scene, double fps,
                                           const std::optional<std::string>& cameraSelector);
// The same tables of a sequence of camera poses one frame apart, with no cuts (a camera path
// before it is written to a dataset: the fly-through's candidates).
CameraMotionSummary measurePoses(const std::vector<glm::dvec3>& positions, const std::vector<glm::dquat>& rotations);

}  // namespace dynbench::metrics
