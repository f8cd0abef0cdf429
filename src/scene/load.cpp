#include "scene/load.h"

#include <algorithm>

namespace dynbench::scene {

Expected<Scene> loadScene(const std::filesystem::path& path, const LoadOptions& options) {
  auto sequence = expandObjSequence(path);
  if (!sequence) return std::unexpected(sequence.error());
  if (!sequence->empty()) return loadObjSequence(*sequence, path, options.sequenceRate);

  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return fail(ErrorCode::kIo, "{}: no such file or folder", path.string());
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
  return loadWithAssimp(path);
}

}  // namespace dynbench::scene
