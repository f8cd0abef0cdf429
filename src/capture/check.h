#pragma once
// `dynbench capture-check`: validates a whole capture and summarises it.
#include <cstdint>
#include <filesystem>

#include <nlohmann/json.hpp>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "capture/reader.h"
#include "core/error.h"

namespace dynbench::capture {

struct CaptureSummary {
  CaptureSettings settings;
  bool closed = false;               // the session wrote its closing record
  std::size_t frames = 0;            // complete frames
  std::uint64_t firstFrame = 0, lastFrame = 0;
  double startTime = 0, endTime = 0;  // seconds
  // Distinct capturables by kind.
  std::size_t capturables = 0, cameras = 0, staticModels = 0, rigidModels = 0, skinnedModels = 0;
  std::size_t vertexAnimatedModels = 0;  // capturables with key-frame (`v`) records
  std::size_t staticLights = 0, dynamicLights = 0;
  std::map<std::string, std::size_t> lightsByModelType;
  // Model files.
  std::size_t models = 0, skinnedModelFiles = 0, meshes = 0, vertices = 0, triangles = 0, joints = 0;
  std::size_t vertexAnimatedModelFiles = 0, keyFrames = 0;  // files with `K` records; their key frames, summed
  std::size_t cameraRecords = 0, modelRecords = 0, jointRecords = 0, vertexFrameRecords = 0, lightRecords = 0;
  std::map<std::string, std::size_t> cutsByReason;  // `c` records (camera cuts) by reason
  std::vector<std::string> warnings;
};

// Reads every frame; `onFrame(frames done, capture bytes read)` reports progress.
Expected<CaptureSummary> checkCapture(const std::filesystem::path& directory,
                                      const std::function<void(std::size_t)>& onFrame = {});

std::string summaryText(const std::filesystem::path& directory, const CaptureSummary& summary);
nlohmann::json summaryJson(const std::filesystem::path& directory, const CaptureSummary& summary);

}  // namespace dynbench::capture
