// Fuzz target: the feature-frame reader (frames/frame_io.cpp): the sidecar JSON checks and the
// mapping of EXR channels to buffers. The input is the sidecar frame_00000.json; the EXR beside it
// is a valid 4x2 frame written once at start-up (OpenImageIO's EXR decoder is not ours to fuzz).
// Seeds: sidecars of a real render (tests/fuzz/make_seeds.sh).
#include "frames/frame_io.h"
#include "fuzz_input.h"

namespace {

const std::filesystem::path& framesDir() {
  static const std::filesystem::path dir = [] {
    const auto d = dynbench::fuzz::scratchDir() / "frames";
    dynbench::frames::FeatureFrame f;
    f.resize(4, 2);
    (void)dynbench::frames::writeFrame(d, f, nullptr);
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto& dir = framesDir();
  dynbench::fuzz::writeBytes(dynbench::frames::frameSidecarPath(dir, 0), data, size);
  auto entries = dynbench::frames::listFrames(dir);
  if (entries && !entries->empty()) (void)dynbench::frames::readFrame(entries->front(), {.requireVariance = true});
  return 0;
}
