#pragma once
// `dynbench convert`: a capture directory (docs/capture-format.md) to a glTF 2.0 dataset laid out
// as thesis §5.1 (docs/dataset.md). Two streaming passes over Capture.txt: the first finds every
// capturable's life span and visibility changes, the second writes key frames straight to their
// place in the binary buffer. Memory grows with the number of capturables, not with the frames
// (plus 4 bytes of time per frame).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "convert/light_rules.h"
#include "convert/sky.h"
#include "core/error.h"

namespace dynbench::convert {

enum class VisibilityMode { kNode, kScale, kBoth };

struct ConvertOptions {
  std::filesystem::path capture;
  std::filesystem::path output;  // DATASET.gltf (or .glb with `glb`)
  bool glb = false;
  VisibilityMode visibility = VisibilityMode::kBoth;
  LightRules lightRules = defaultLightRules();
  std::optional<std::filesystem::path> dataRoot;  // overrides the capture's `d` record
  // Environment lighting: the user's equirectangular .hdr/.exr, or else the generated sky.
  std::optional<std::filesystem::path> environment;
  SkyParameters sky;
  // The generated sky's sun from the capture's map lighting (`L`: its direction, or no sun disc
  // when the map has none); false when the user chose the sun (--sun-elevation, --sun-azimuth).
  bool sunFromCapture = true;
  // Progress: pass (1 or 2), frames done in it, frames in all (0 in pass 1: not known yet).
  std::function<void(int, std::size_t, std::size_t)> onProgress;
};

struct ConvertReport {
  std::size_t frames = 0;
  std::size_t capturables = 0;
  std::size_t nodes = 0, meshes = 0, materials = 0, textures = 0, skins = 0, lights = 0, channels = 0;
  std::size_t cameraCuts = 0;  // cuts carried into the camera node's extras
  std::size_t morphTargets = 0;  // of vertex-animated models' meshes (one per key frame)
  std::uint64_t binBytes = 0;
  std::vector<std::filesystem::path> written;  // the dataset's files
  std::vector<std::string> warnings;
};

Expected<ConvertReport> convertCapture(const ConvertOptions& options);

}  // namespace dynbench::convert
