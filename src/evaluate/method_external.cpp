// `external:DIR`: another program's output frames, scored like a built-in method. The contract
// (docs/metrics.md, "External methods"): DIR/frame_NNNNN.exr for every frame of FRAMES, the same
// size, channels R, G, B of linear radiance in the dataset's units (as direct + indirect).
#include <fmt/format.h>

#include "evaluate/compare.h"
#include "evaluate/method.h"
#include "frames/feature_frame.h"

namespace dynbench::evaluate {
namespace {

class ExternalMethod final : public TemporalMethod {
 public:
  explicit ExternalMethod(std::filesystem::path dir) : dir_(std::move(dir)) {}
  std::string name() const override { return "external:" + dir_.string(); }
  nlohmann::json parameters() const override { return {{"dir", dir_.string()}}; }
  void reset() override {}
  Expected<MethodOutput> process(const frames::FeatureFrame& frame) override {
    const std::filesystem::path path = frames::frameImagePath(dir_, frame.frame);
    auto image = loadImage(path);
    if (!image) return std::unexpected(image.error());
    if (!image->hdr) return fail(ErrorCode::kInvalidData, "{}: expected an EXR of linear radiance", path.string());
    if (image->linear.width != frame.width || image->linear.height != frame.height)
      return fail(ErrorCode::kInvalidData, "{}: {}x{} pixels, but frame {} of the input is {}x{}", path.string(), image->linear.width,
                  image->linear.height, frame.frame, frame.width, frame.height);
    return MethodOutput{std::move(image->linear), std::nullopt};
  }

 private:
  std::filesystem::path dir_;
};

}  // namespace

Expected<std::unique_ptr<TemporalMethod>> makeExternalMethod(const std::filesystem::path& dir) {
  std::error_code ec;
  if (dir.empty() || !std::filesystem::is_directory(dir, ec))
    return fail(ErrorCode::kIo, "external:{}: not a folder (expected frame_NNNNN.exr per frame)", dir.string());
  return std::make_unique<ExternalMethod>(dir);
}

}  // namespace dynbench::evaluate
