#pragma once
// Dataset properties: the thesis's Tables 6.1-6.3. Counting rules are in docs/metrics.md.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace dynbench::metrics {

struct DatasetProperties {
  // Table 6.1
  std::string fileFormat;
  std::uint64_t totalBytes = 0;   // the file and every file it references, bytes
  std::size_t fileCount = 0;      // how many files that is
  std::uint64_t faces = 0;        // triangles of every mesh instance in the displayed scene
  std::uint64_t uniqueFaces = 0;  // triangles of each mesh counted once
  bool animatedCamera = false;    // some camera node is dynamic
  bool morphTargets = false;      // some mesh has morph targets
  // Table 6.2
  std::size_t materialCount = 0;
  std::size_t textureCount = 0;       // distinct images
  std::uint64_t textureBytes = 0;     // their encoded size (files on disk or embedded bytes)
  std::string materialWorkflow;       // the workflow of most materials; "-" without materials
  std::map<std::string, std::size_t> workflowCounts;
  // Table 6.3
  std::size_t animationFrames = 0;  // frames at the sampling rate over the animation's time range
  double fps = 0.0;                 // that sampling rate, frames per second
  double startTime = 0.0, endTime = 0.0;  // seconds
  std::size_t staticObjects = 0;        // mesh instances, not skinned, not dynamic
  std::size_t dynamicRigidObjects = 0;  // mesh instances, not skinned, dynamic
  std::size_t armatures = 0;            // distinct skins used by mesh instances
  std::size_t staticPointLights = 0;
  std::size_t dynamicPointLights = 0;
  // Further counts, for --json
  std::size_t nodes = 0, meshes = 0, skins = 0, joints = 0, cameras = 0, animations = 0, channels = 0;
  std::size_t morphAnimatedObjects = 0;  // mesh instances with a weights channel
  std::size_t spotLights = 0, directionalLights = 0;  // static + dynamic
  std::size_t lights = 0;
  std::vector<std::string> warnings;
};

DatasetProperties measureProperties(const scene::Scene& scene, double fps);

}  // namespace dynbench::metrics
