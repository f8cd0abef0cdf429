// Feature-buffer storage on disk (run by hand; not part of the test suite):
//   build/release/bench/bench_storage FRAMES_DIR
// Rewrites every frame of a rendered folder with OpenEXR's lossless codecs, at 32-bit float and at
// the contract's precision (frames::Storage), and prints bytes per pixel; then each buffer alone
// (contract precision, ZIP), so docs/feature-buffers.md can say where the bytes go.
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

// The frame as one EXR image: every buffer, or only `only` when given.
FloatImage toImage(const frames::FeatureFrame& f, bool float32, const std::string& compression, const char* only = nullptr) {
  FloatImage image;
  image.width = f.width;
  image.height = f.height;
  image.compression = compression;
  std::vector<const frames::BufferSpec*> specs;
  for (const auto& spec : frames::contractBuffers())
    if (!(f.*spec.member).empty() && (!only || std::string(only) == spec.name)) specs.push_back(&spec);
  for (const auto* spec : specs) {
    image.channelNames.insert(image.channelNames.end(), spec->channels.begin(), spec->channels.end());
    const bool half = !float32 && frames::storedAsHalf(*spec, f.*spec->member);
    image.formats.insert(image.formats.end(), spec->channels.size(), half ? SampleFormat::kFloat16 : SampleFormat::kFloat32);
  }
  image.channels = static_cast<int>(image.channelNames.size());
  const std::size_t pixels = f.pixelCount();
  image.pixels.reserve(pixels * image.channelNames.size());
  for (std::size_t i = 0; i < pixels; ++i)
    for (const auto* spec : specs)
      for (std::size_t c = 0; c < spec->channels.size(); ++c) image.pixels.push_back((f.*spec->member)[i * spec->channels.size() + c]);
  return image;
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
  auto bytes = [&](bool float32, const std::string& codec, const char* only) {
    std::uintmax_t total = 0;
    const auto start = std::chrono::steady_clock::now();
    for (const auto& f : all) {
      if (auto ok = writeImage(tmp, toImage(f, float32, codec, only)); !ok) {
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
  for (const char* codec : {"none", "rle", "zips", "zip", "zip:9", "piz", "b44"}) {
    const double full = bytes(true, codec, nullptr), contract = bytes(false, codec, nullptr);
    std::printf("%-8s %14.2f %14.2f %11.1f ms/frame\n", codec, full, contract, 1e3 * writeSeconds / static_cast<double>(all.size()));
  }
  std::printf("\nper buffer, contract precision, zip:\n");
  for (const auto& spec : frames::contractBuffers())
    if (!(all[0].*spec.member).empty()) std::printf("  %-13s %6.2f B/px\n", spec.name, bytes(false, "zip", spec.name));
  fs::remove(tmp);
  return 0;
}
