#include "scene/load.h"

#include "core/files.h"

namespace dynbench::scene {

Expected<Scene> loadScene(const std::filesystem::path& path, const LoadOptions& options) {
  auto sequence = expandObjSequence(path);
  if (!sequence) return std::unexpected(sequence.error());
  if (!sequence->empty()) return loadObjSequence(*sequence, path, options.sequenceRate);

  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return fail(ErrorCode::kIo, "{}: no such file or folder", path.string());
  const std::string ext = lowercaseExtension(path);
  if (ext == ".gltf" || ext == ".glb") return loadGltf(path);
  return loadWithAssimp(path);
}

}  // namespace dynbench::scene
