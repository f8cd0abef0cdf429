#pragma once
// A dataset's identity by content, for suite pins (/datasets/N/sha256/dataset) and render's resume
// record: the same files give the same digest wherever they are.
#include <filesystem>
#include <string>

#include "core/error.h"

namespace dynbench::scene {

// SHA-256 of sha256Listing (core/checksum.h) over the files a dataset is made of, relative to its
// folder: a .gltf and every file it names by a relative "uri" (the .bin, the textures, the
// environment map; not the README beside it); any other file (GLB, a format assimp reads) alone;
// an OBJ sequence's files (a folder or a glob, as loadScene expands it).
Expected<std::string> datasetDigest(const std::filesystem::path& dataset);

}  // namespace dynbench::scene
