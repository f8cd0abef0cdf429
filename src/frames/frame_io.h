#pragma once
// Reading and writing frames folders to the contract (docs/feature-buffers.md): the EXR image with
// the named channels and, written after it, the camera sidecar frame_NNNNN.json. A frame is
// complete exactly when its sidecar exists and records the settings that made it.
#include <filesystem>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/image_io.h"
#include "frames/feature_frame.h"

namespace dynbench::frames {

// The sidecar's format name and the version this build writes and reads.
inline constexpr const char* kSidecarFormat = "dynbench-frame";
inline constexpr int kSidecarVersion = 1;

// A matrix as 16 numbers, column-major (glTF's order).
nlohmann::json matrixJson(const glm::dmat4& m);

// The sidecar: format and version, frame, time, resolution, camera, conventions, and `render`,
// the engine and settings that made the frame (compared when resuming).
nlohmann::json sidecarJson(long frame, double time, const FrameCamera& camera, const nlohmann::json& render);
nlohmann::json samplingJson(const SamplingSummary& sampling);

struct Sidecar {
  long frame = 0;
  double time = 0.0;
  FrameCamera camera;
  nlohmann::json render;  // null when absent (another renderer's frames)
  std::optional<SamplingSummary> sampling;
  bool cut = false;  // /cut: the camera jumped since the previous frame
};
// Reads and checks a sidecar: /format must be "dynbench-frame" and /version one this build reads;
// errors name the file and the JSON pointer.
Expected<Sidecar> readSidecar(const std::filesystem::path& path);

struct FrameEntry {
  long frame = 0;
  std::filesystem::path image, sidecar;
};
// The frame a file frame_NNNNN.exr or frame_NNNNN.json names, with both its files' paths (which
// need not exist); errors name a file that is not a frame's.
Expected<FrameEntry> frameEntry(const std::filesystem::path& file);
// The frames of a folder in frame order; every frame_NNNNN.exr must have its frame_NNNNN.json and
// the other way round. An empty list is not an error here (callers say how many they need).
Expected<std::vector<FrameEntry>> listFrames(const std::filesystem::path& dir);

struct ReadOptions {
  bool requireVariance = false;  // fail when direct.var / indirect.var are absent
};
// Reads one frame: every channel of the contract the image has (optional buffers stay empty
// when absent), the camera from the sidecar. Errors name the file and what is missing.
Expected<FeatureFrame> readFrame(const FrameEntry& entry, const ReadOptions& options = {});

struct WriteOptions {
  // Every channel as 32-bit float, whatever the contract's storage says (render --float32).
  bool float32 = false;
};
// The frame's EXR image as writeFrame writes it: every non-empty buffer in contract order, each
// channel's format as its BufferSpec's Storage gives it for these values, ZIP compression.
// Errors name a missing required buffer or a buffer of the wrong size.
Expected<FloatImage> frameImage(const FeatureFrame& frame, const WriteOptions& options = {});
// Writes frame_NNNNN.exr (every non-empty buffer, contract order, each stored as its BufferSpec
// says, ZIP-compressed) and then its sidecar, each through a temporary name, so an interrupted
// write never leaves a frame that looks complete.
Expected<void> writeFrame(const std::filesystem::path& dir, const FeatureFrame& frame, const nlohmann::json& render,
                          const WriteOptions& options = {});

// True when frame `frame` of `dir` exists and its sidecar records exactly `render`.
bool frameComplete(const std::filesystem::path& dir, long frame, const nlohmann::json& render);

}  // namespace dynbench::frames
