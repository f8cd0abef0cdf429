// `accumulate`: reprojection with the camera matrices (thesis Eqs. 2.2-2.3, as discard), bilinear
// history, exponential blend with alpha = max(1/n, 0.1) where n counts the frames accumulated (an
// exact running mean for the first ten, then an exponential moving average), and history rejected
// by the discard stage's own world-position and shading-normal tests.
#include <algorithm>

#include "evaluate/method.h"

namespace dynbench::evaluate {
namespace {

class AccumulateMethod final : public TemporalMethod {
 public:
  explicit AccumulateMethod(const MethodContext& context) : context_(context) {}
  std::string name() const override { return kAccumulateMethod; }
  nlohmann::json parameters() const override {
    return {{"alpha_min", kAlphaMin},
            {"geometry_test", discard::geometryTestName(context_.thresholds.geometryTest)},
            {"position_threshold", context_.thresholds.position},
            {"relative_position", context_.thresholds.relativePosition},
            {"normal_threshold", context_.thresholds.normal}};
  }
  void reset() override { previous_.reset(); }

  Expected<MethodOutput> process(const frames::FeatureFrame& frame) override {
    RgbImage out = frameRadiance(frame);
    std::vector<float> count(frame.pixelCount(), 1.0f);
    long kept = 0;
    if (previous_) {
      const frames::FeatureFrame& prev = previous_->frame;
      const discard::Thresholds t = discard::absoluteThresholds(context_.thresholds, frame, context_.sceneSize);
      const int w = frame.width, h = frame.height;
      const reprojection::HistoryLookup lookup(frame, prev, t.surface(), /*useMotion=*/false);
      // Rows in parallel: each pixel reads the previous output only.
      kept = sumOverRows(h, [&](int py) {
        long keptInRow = 0;
        for (int px = 0; px < w; ++px) {
          const std::size_t i = static_cast<std::size_t>(py) * w + px;
          const auto found = lookup(px, py);
          if (!found) continue;
          const reprojection::BilinearTaps& taps = *found;
          const glm::dvec3 history = reprojection::sample3(previous_->output.rgb, taps);
          const double n = reprojection::sample1(previous_->count, taps) + 1.0, alpha = std::max(1.0 / n, kAlphaMin);
          for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<float>(history[k] + alpha * (out.rgb[3 * i + k] - history[k]));
          count[i] = static_cast<float>(n);
          ++keptInRow;
        }
        return keptInRow;
      });
    }
    previous_ = History{historyFrame(frame), out, std::move(count)};
    return MethodOutput{std::move(out), static_cast<double>(kept) / static_cast<double>(frame.pixelCount())};
  }

 private:
  static constexpr double kAlphaMin = 0.1;
  struct History {
    frames::FeatureFrame frame;
    RgbImage output;
    std::vector<float> count;
  };
  MethodContext context_;
  std::optional<History> previous_;
};

}  // namespace

std::unique_ptr<TemporalMethod> makeAccumulateMethod(const MethodContext& context) { return std::make_unique<AccumulateMethod>(context); }

}  // namespace dynbench::evaluate
