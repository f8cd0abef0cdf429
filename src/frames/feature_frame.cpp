#include "frames/feature_frame.h"

#include <fmt/format.h>

namespace dynbench::frames {

void FeatureFrame::resize(int w, int h) {
  width = w;
  height = h;
  camera.width = w;
  camera.height = h;
  const std::size_t n = pixelCount();
  for (const auto& spec : contractBuffers()) (this->*spec.member).assign(n * spec.channels.size(), 0.0f);
}

const std::vector<BufferSpec>& contractBuffers() {
  static const std::vector<BufferSpec> buffers{
      {"P", {"P.X", "P.Y", "P.Z"}, &FeatureFrame::position, true},
      {"N", {"N.X", "N.Y", "N.Z"}, &FeatureFrame::normal, true},
      {"direct", {"direct.R", "direct.G", "direct.B"}, &FeatureFrame::direct, true},
      {"indirect", {"indirect.R", "indirect.G", "indirect.B"}, &FeatureFrame::indirect, true},
      {"albedo", {"albedo.R", "albedo.G", "albedo.B"}, &FeatureFrame::albedo, false},
      {"Z", {"Z"}, &FeatureFrame::depth, false},
      {"id", {"id"}, &FeatureFrame::id, false},
      {"motion", {"motion.X", "motion.Y"}, &FeatureFrame::motion, false},
      {"direct.var", {"direct.var"}, &FeatureFrame::directVariance, false},
      {"indirect.var", {"indirect.var"}, &FeatureFrame::indirectVariance, false},
      {"hit", {"hit"}, &FeatureFrame::hit, true},
      {"spp", {"spp"}, &FeatureFrame::spp, false},
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
