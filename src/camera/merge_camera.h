#pragma once
// `dynbench merge-camera` (thesis §5.5, the VR workflow): replace a dataset's camera animation
// with another camera run, keeping everything else byte for byte.
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/error.h"
#include "metrics/camera_motion.h"
#include "scene/scene.h"

namespace dynbench::camera {

struct CameraPoseKey {
  double time = 0.0;  // seconds
  glm::dvec3 position{0.0};
  glm::dquat rotation{1, 0, 0, 0};  // world orientation; roll included
};

// A camera run: a capture directory (its first camera capturable's `t` records), or a CSV pose log
// with lines `time,x,y,z,qx,qy,qz,qw` (a header line is allowed) such as a head-mounted display
// records. Errors name file:line.
Expected<std::vector<CameraPoseKey>> readCameraRun(const std::filesystem::path& run);
// How strictly a CSV pose log is read: merge-camera normalises any quaternion of non-zero length;
// a head trace (camera/vr_head.h) refuses one whose length is off 1 by more than unitTolerance.
struct PoseCsvRules {
  double unitTolerance = std::numeric_limits<double>::infinity();
  std::size_t minimumPoses = 1;
};
Expected<std::vector<CameraPoseKey>> readPoseCsv(const std::filesystem::path& csv, const PoseCsvRules& rules = {});
// Writes a CSV pose log readCameraRun reads (header line, one key a line, shortest round-trip
// decimals), from a temporary file.
Expected<void> writeCameraRunCsv(const std::filesystem::path& csv, const std::vector<CameraPoseKey>& keys);

// A dataset whose first animated camera a camera tool reworks: the scene, that camera's node and
// the animation's time range. An error names the dataset and says what the tool wanted to do
// (`purpose`, e.g. "fly along") when it has no camera or no animation.
struct AnimatedCamera {
  scene::Scene scene;
  int node = -1;
  scene::Scene::TimeRange range;
  double duration() const { return range.end - range.start; }
};
Expected<AnimatedCamera> loadAnimatedCamera(const std::filesystem::path& dataset, const std::string& purpose);

struct MergeCameraOptions {
  std::filesystem::path dataset;  // .gltf with its .bin (as `convert` writes)
  std::filesystem::path run;
  std::filesystem::path output;   // .gltf, in the dataset's folder (textures stay reachable)
  std::optional<std::string> camera;  // camera node: index or name (default: the first animated camera)
  double offsetSeconds = 0.0;     // added after aligning the run's first key to the dataset's start
  // Keep the dataset camera's cuts (extras.dynbench_camera_cuts): for a run whose keys jump where
  // the old camera's did (the bot's positions with another rotation). Otherwise they go with it.
  bool keepCuts = false;
};

struct MergeCameraReport {
  int cameraNode = -1;
  std::size_t keys = 0;
  double startTime = 0.0, endTime = 0.0;  // of the new camera keys, dataset time
};

Expected<MergeCameraReport> mergeCamera(const MergeCameraOptions& options);

// A pose log the camera tools wrote (`csv`) merged into a copy of `dataset` (`output`, keepCuts as
// merge-camera's), then the new dataset's camera measured as `stats` measures it at `fps`: how the
// fly-through and the VR camera make their datasets.
Expected<metrics::CameraMotion> mergeAndMeasure(const std::filesystem::path& dataset, const std::filesystem::path& csv,
                                                const std::filesystem::path& output, double fps);

}  // namespace dynbench::camera
