#include "frames/feature_frame.h"

#include <fmt/format.h>

namespace dynbench::frames {

glm::dvec2 jitterOffset(long frame) {
  auto halton = [](long index, int base) {
    double f = 1.0, r = 0.0;
    for (long i = index; i > 0; i /= base) {
      f /= base;
      r += f * static_cast<double>(i % base);
    }
    return r;
  };
  const long index = 1 + ((frame % 8) + 8) % 8;
  return {halton(index, 2) - 0.5, halton(index, 3) - 0.5};
}

void FeatureFrame::resize(int w, int h) {
  width = w;
  height = h;
  camera.width = w;
  camera.height = h;
  const std::size_t n = pixelCount();
  for (const auto& spec : contractBuffers())
    if (!spec.onRequest) (this->*spec.member).assign(n * spec.channels.size(), 0.0f);
}

const std::vector<BufferSpec>& contractBuffers() {
  // Precision per buffer: what discard and evaluation need (docs/feature-buffers.md). Positions
  // keep 32 bits: a world coordinate of 1000 in half is off by 0.25. Motion is half only in a frame
  // whose vectors are all within 256 pixels (off by at most 1/16 pixel, as RG16F motion buffers of
  // game engines); a frame with a longer vector, or -1e9 ("behind the previous camera"), keeps 32 bits.
  using enum Storage;
  static const std::vector<BufferSpec> buffers{
      {"P", {"P.X", "P.Y", "P.Z"}, &FeatureFrame::position, true, kFloat32},
      {"N", {"N.X", "N.Y", "N.Z"}, &FeatureFrame::normal, true, kFloat16},
      {"direct", {"direct.R", "direct.G", "direct.B"}, &FeatureFrame::direct, true, kFloat16},
      {"indirect", {"indirect.R", "indirect.G", "indirect.B"}, &FeatureFrame::indirect, true, kFloat16},
      {"albedo", {"albedo.R", "albedo.G", "albedo.B"}, &FeatureFrame::albedo, false, kFloat16},
      {"Z", {"Z"}, &FeatureFrame::depth, false, kFloat32},
      {"id", {"id"}, &FeatureFrame::id, false, kFloat16WhenExact},
      {"motion", {"motion.X", "motion.Y"}, &FeatureFrame::motion, false, kFloat16, 256.0f},
      {"direct.var", {"direct.var"}, &FeatureFrame::directVariance, false, kFloat16},
      {"indirect.var", {"indirect.var"}, &FeatureFrame::indirectVariance, false, kFloat16},
      {"hit", {"hit"}, &FeatureFrame::hit, true, kFloat16WhenExact},
      {"spp", {"spp"}, &FeatureFrame::spp, false, kFloat16WhenExact},
      // Differences of two nearly equal luminances keep 32 bits: half's 2^-11 of the halves' size
      // would be noise of its own on a change a hundred times smaller.
      {"change.direct", {"change.direct.mean", "change.direct.se", "change.direct.gathered"}, &FeatureFrame::directChange, false, kFloat32,
       65504.0f, true},
      {"change.indirect", {"change.indirect.mean", "change.indirect.se", "change.indirect.gathered"}, &FeatureFrame::indirectChange, false,
       kFloat32, 65504.0f, true},
      {"change.pairs", {"change.pairs"}, &FeatureFrame::changePairs, false, kFloat16WhenExact, 65504.0f, true},
  };
  return buffers;
}

std::vector<std::string> contractChannelNames() {
  std::vector<std::string> names;
  for (const auto& spec : contractBuffers()) names.insert(names.end(), spec.channels.begin(), spec.channels.end());
  return names;
}

std::filesystem::path frameImagePath(const std::filesystem::path& dir, long frame) {
  return dir / fmt::format("frame_{:05d}.exr", frame);
}
std::filesystem::path frameSidecarPath(const std::filesystem::path& dir, long frame) {
  return dir / fmt::format("frame_{:05d}.json", frame);
}

}  // namespace dynbench::frames
