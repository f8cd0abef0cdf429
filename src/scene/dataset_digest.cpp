#include "scene/dataset_digest.h"

#include <set>

#include <fmt/format.h>

#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "scene/load.h"

namespace dynbench::scene {

namespace fs = std::filesystem;

Expected<std::string> datasetDigest(const fs::path& dataset) {
  std::error_code ec;
  const std::string extension = lowercaseExtension(dataset);
  if (extension != ".gltf") {
    // One file (GLB, a file assimp reads) or an OBJ sequence: the files the loader reads.
    std::vector<std::string> files;
    fs::path root = dataset.parent_path();
    if (fs::is_regular_file(dataset, ec)) {
      files.push_back(dataset.filename().string());
    } else {
      auto frames = expandObjSequence(dataset);
      if (!frames) return std::unexpected(frames.error());
      if (frames->empty()) return fail(ErrorCode::kIo, "{}: no dataset there", dataset.string());
      root = frames->front().parent_path();
      for (const auto& f : *frames) files.push_back(fs::relative(f, root).generic_string());
    }
    return sha256Listing(root.empty() ? fs::path(".") : root, std::move(files));
  }
  auto document = readJsonFile(dataset);
  if (!document) return std::unexpected(document.error());
  std::set<std::string> files{dataset.filename().string()};
  // Every "uri" in the document: buffers, images and extensions' files alike; data: URIs are inside.
  std::vector<const nlohmann::json*> stack{&*document};
  while (!stack.empty()) {
    const nlohmann::json* node = stack.back();
    stack.pop_back();
    if (node->is_array())
      for (const auto& item : *node) stack.push_back(&item);
    if (!node->is_object()) continue;
    for (const auto& [key, value] : node->items()) {
      if (key == "uri" && value.is_string()) {
        const std::string uri = value.get<std::string>();
        if (uri.starts_with("data:") || uri.find("://") != std::string::npos) continue;
        const fs::path relative = fs::path(percentDecodeUri(uri)).lexically_normal();
        if (relative.is_absolute() || relative.string().starts_with(".."))
          return fail(ErrorCode::kInvalidData, "{}: uri '{}' leaves the dataset's folder", dataset.string(), uri);
        files.insert(relative.generic_string());
      } else {
        stack.push_back(&value);
      }
    }
  }
  const fs::path root = dataset.parent_path();
  return sha256Listing(root.empty() ? fs::path(".") : root, std::vector<std::string>(files.begin(), files.end()));
}

}  // namespace dynbench::scene
