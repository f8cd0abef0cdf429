#pragma once
// Image files through OpenImageIO (Debian libopenimageio-dev). This is the only place that talks
// to OpenImageIO; its errors come back as Error.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench {

struct FloatImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  // row-major, top row first, channels interleaved
  std::vector<std::string> channelNames;  // empty: the format's defaults (R, G, B, A)
};

// Writes to a temporary name and renames, as every output. The format follows the extension
// (.hdr, .exr, .png, ...).
Expected<void> writeImage(const std::filesystem::path& path, const FloatImage& image);
Expected<FloatImage> readImage(const std::filesystem::path& path);
// Width, height and channels from the header only.
Expected<FloatImage> readImageHeader(const std::filesystem::path& path);

}  // namespace dynbench
