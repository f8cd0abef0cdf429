#pragma once
// Reading a frames folder written to the feature-buffer contract (docs/feature-buffers.md): the
// EXR channels discard needs and each frame's camera from its JSON sidecar. Any renderer that
// writes the contract can be read, dynbench's own or not.
#include <filesystem>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"

namespace dynbench::discard {

struct FrameCamera {
  glm::dmat4 view{1.0}, projection{1.0};
  int width = 0, height = 0;
};

// One frame's buffers, row 0 at the top, channels interleaved.
struct FeatureFrame {
  long frame = 0;
  double time = 0.0;
  FrameCamera camera;
  int width = 0, height = 0;
  std::vector<float> position, normal, direct, indirect;  // 3 per pixel
  std::vector<float> hit;                                 // 1 per pixel
  std::vector<float> directVariance, indirectVariance;    // 1 per pixel; empty when absent
  bool hasVariance() const { return !directVariance.empty() && !indirectVariance.empty(); }
};

struct FrameEntry {
  long frame = 0;
  std::filesystem::path image, sidecar;
};

// The frames of a folder in frame order: every frame_NNNNN.exr must have its frame_NNNNN.json.
Expected<std::vector<FrameEntry>> listFrames(const std::filesystem::path& dir);

// Reads one frame; errors name the file and what is missing (channel, JSON pointer, size).
Expected<FeatureFrame> readFeatureFrame(const FrameEntry& entry, bool needVariance);

}  // namespace dynbench::discard
