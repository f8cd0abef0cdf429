#pragma once
// Scene loaders. loadScene() picks one by the path: .gltf/.glb (our glTF reader), a folder or a glob
// of .obj files (an OBJ key-frame sequence), anything else through assimp (FBX, DAE, OBJ, 3DS, ...).
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/rates.h"
#include "scene/scene.h"

namespace dynbench::scene {

struct LoadOptions {
  // Key frames per second of an OBJ sequence (one OBJ file per key frame).
  double sequenceRate = kDefaultSequenceRate;
};

Expected<Scene> loadScene(const std::filesystem::path& path, const LoadOptions& options = {});

// The individual loaders, for callers that know the format.
Expected<Scene> loadGltf(const std::filesystem::path& path);
Expected<Scene> loadWithAssimp(const std::filesystem::path& path);
Expected<Scene> loadObjSequence(const std::vector<std::filesystem::path>& frames,
                                const std::filesystem::path& displayPath, double rate);

// A glTF URI's percent-encoding (RFC 3986 %XX) undone, as the loader resolves URIs to files.
std::string percentDecodeUri(std::string_view uri);

// Expands a folder (its *.obj files) or a glob pattern into OBJ files in natural order
// (frame2 before frame10). Empty when the path names neither.
Expected<std::vector<std::filesystem::path>> expandObjSequence(const std::filesystem::path& path);

}  // namespace dynbench::scene
