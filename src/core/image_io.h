#pragma once
// Image files through OpenImageIO (Debian libopenimageio-dev). This is the only place that talks
// to OpenImageIO; its errors come back as Error.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench {

// How a channel is stored in the file (OpenEXR's pixel types); pixels are floats in memory either way.
enum class SampleFormat : char { kFloat32 = 'f', kFloat16 = 'h' };

struct FloatImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  // row-major, top row first, channels interleaved
  std::vector<std::string> channelNames;  // empty: the format's defaults (R, G, B, A)
  // Per channel, for EXR files: 32- or 16-bit float on disk. Empty: 32-bit float. Read back as the
  // file stores them (kFloat16 for half channels, kFloat32 for any other type). PNG and JPEG are 8-bit
  // whatever this says.
  std::vector<SampleFormat> formats;
  // EXR compression ("zip", "piz", "zips", "none", ...); empty: OpenImageIO's default (zip).
  std::string compression;
};

// Writes to a temporary name and renames, as every output. The format follows the extension
// (.hdr, .exr, .png, ...).
Expected<void> writeImage(const std::filesystem::path& path, const FloatImage& image);
Expected<FloatImage> readImage(const std::filesystem::path& path);
// Width, height and channels from the header only.
Expected<FloatImage> readImageHeader(const std::filesystem::path& path);

// The threads image reading and writing may use, process-wide: OpenImageIO's own pool and
// OpenEXR's compression pool, which otherwise each start one thread per hardware core whatever
// the caller's thread budget. 1: the calling thread does all the work; 0: the libraries'
// default (every core).
void setImageThreads(int threads);

}  // namespace dynbench
