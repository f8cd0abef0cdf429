// Feature-buffer storage on disk (run by hand; not part of the test suite):
//   build/release/bench/bench_storage FRAMES_DIR
// Rewrites every frame of a rendered folder with OpenEXR's lossless codecs, at 32-bit float and at
// the contract's precision (frames::Storage), and prints bytes per pixel; then each buffer alone
// (contract precision, ZIP), so docs/feature-buffers.md can say where the bytes go.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/image_io.h"
#include "frames/feature_frame.h"
#include "frames/frame_io.h"

namespace fs = std::filesystem;
using namespace dynbench;

namespace {

// The channels of `image` named in `names`, formats kept.
FloatImage selectChannels(const FloatImage& image, const std::vector<std::string>& names) {
  FloatImage out;
  out.width = image.width;
  out.height = image.height;
  std::vector<std::size_t> at;
  for (const auto& n : names) {
    at.push_back(static_cast<std::size_t>(std::find(image.channelNames.begin(), image.channelNames.end(), n) - image.channelNames.begin()));
    out.channelNames.push_back(n);
    out.formats.push_back(image.formats[at.back()]);
  }
  out.channels = static_cast<int>(at.size());
  const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  for (std::size_t i = 0; i < pixels; ++i)
    for (const std::size_t c : at) out.pixels.push_back(image.pixels[i * static_cast<std::size_t>(image.channels) + c]);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_storage FRAMES_DIR\n");
    return 2;
  }
  auto entries = frames::listFrames(argv[1]);
  if (!entries || entries->empty()) {
    std::fprintf(stderr, "%s: no frames\n", argv[1]);
    return 1;
  }
  std::vector<frames::FeatureFrame> all;
  std::uint64_t pixels = 0;
  for (const auto& e : *entries) {
    auto f = frames::readFrame(e);
    if (!f) {
      std::fprintf(stderr, "%s\n", f.error().message.c_str());
      return 1;
    }
    pixels += f->pixelCount();
    all.push_back(std::move(*f));
  }
  const fs::path tmp = fs::temp_directory_path() / "dynbench_bench_storage.exr";
  double writeSeconds = 0;  // of the last call
  auto bytes = [&](bool float32, const std::string& codec, const frames::BufferSpec* only) {
    std::uintmax_t total = 0;
    const auto start = std::chrono::steady_clock::now();
    for (const auto& f : all) {
      // The image writeFrame would write (frames::frameImage), with another codec.
      auto image = frames::frameImage(f, {.float32 = float32});
      if (!image) {
        std::fprintf(stderr, "%s\n", image.error().message.c_str());
        std::exit(1);
      }
      if (only) *image = selectChannels(*image, only->channels);
      image->compression = codec;
      if (auto ok = writeImage(tmp, *image); !ok) {
        std::fprintf(stderr, "%s\n", ok.error().message.c_str());
        std::exit(1);
      }
      total += fs::file_size(tmp);
    }
    writeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return static_cast<double>(total) / static_cast<double>(pixels);
  };
  std::printf("%s: %zu frames, %dx%d\n", argv[1], all.size(), all[0].width, all[0].height);
  std::printf("%-8s %14s %14s %16s   (bytes per pixel; contract = half where frames::Storage allows)\n", "codec", "float32", "contract",
              "contract write");
  for (const char* codec : {"none", "rle", "zips", "zip:1", "zip", "zip:9", "piz", "b44"}) {
    const double full = bytes(true, codec, nullptr), contract = bytes(false, codec, nullptr);
    std::printf("%-8s %14.2f %14.2f %11.1f ms/frame\n", codec, full, contract, 1e3 * writeSeconds / static_cast<double>(all.size()));
  }
  std::printf("\nper buffer, contract precision, zip:\n");
  for (const auto& spec : frames::contractBuffers())
    if (!(all[0].*spec.member).empty()) std::printf("  %-13s %6.2f B/px\n", spec.name, bytes(false, "zip", &spec));
  fs::remove(tmp);
  return 0;
}
