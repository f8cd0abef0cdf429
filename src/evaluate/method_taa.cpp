// `taa`: temporal anti-aliasing as in Karis 2014 ("High Quality Temporal Supersampling") and Salvi
// 2016 ("An Excursion in Temporal Supersampling"): the history is fetched where the frame's
// motion vector points with a Catmull-Rom bicubic filter (as Falcor's and Unreal's TAA do: a
// bilinear fetch blurs the history a little at every frame, and over the ~10 frames the blend
// keeps, a sub-pixel motion smears it to a visibly softer image), the 3x3 neighbourhood of the
// current input gives the mean mu and standard deviation sigma of each YCoCg channel, and the history is *variance-clipped*
// (Salvi): moved along the line towards mu until it lies in the box mu +- gamma sigma (not clamped
// per channel, and not clipped to the neighbourhood's min/max box). Then
// out = lerp(history, current, 0.1). Meant for input rendered with `render --jitter`.
#include <algorithm>
#include <cmath>

#include "evaluate/method.h"

namespace dynbench::evaluate {
namespace {

glm::dvec3 toYCoCg(glm::dvec3 c) { return {0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b}; }
glm::dvec3 fromYCoCg(glm::dvec3 v) { return {v.x + v.y - v.z, v.x + v.z, v.x - v.y - v.z}; }

}  // namespace

glm::dvec3 sampleCatmullRom(const RgbImage& image, double x, double y) {
  return reprojection::sample3(image.rgb, reprojection::catmullRomTaps(x, y, image.width, image.height));
}

namespace {

class TaaMethod final : public TemporalMethod {
 public:
  std::string name() const override { return kTaaMethod; }
  nlohmann::json parameters() const override {
    return {{"blend", kBlend}, {"gamma", kGamma}, {"history", "variance clip in YCoCg, 3x3"}, {"reprojection", "motion vectors, Catmull-Rom"}};
  }
  void reset() override { history_.reset(); }

  Expected<MethodOutput> process(const frames::FeatureFrame& frame) override {
    const RgbImage input = frameRadiance(frame);
    RgbImage out = input;
    long kept = 0;
    const int w = frame.width, h = frame.height;
    if (history_ && history_->width == w && history_->height == h) {
      // Rows in parallel: each pixel reads the input and the history only.
      kept = sumOverRows(h, [&](int py) {
        long keptInRow = 0;
        for (int px = 0; px < w; ++px) {
          const std::size_t i = static_cast<std::size_t>(py) * w + px;
          const glm::dvec2 motion(frame.motion[2 * i], frame.motion[2 * i + 1]);
          // TAA's output (and so its history) is at the pixel centres, while the input and its
          // motion vector are at the jittered sample: the history of this output pixel is at its
          // centre moved by the motion (the sample's, a fraction of a pixel away: as Karis's
          // velocity buffer is read). Reading it at centre + jitter + motion, as before, resampled
          // the still image by each frame's jitter, a shift of up to half a pixel every frame.
          const glm::dvec2 q = glm::dvec2(px + 0.5, py + 0.5) + motion;
          if (!(std::abs(motion.x) < 1e8) || q.x < 0 || q.y < 0 || q.x > w || q.y > h) continue;
          glm::dvec3 sum(0.0), sumSq(0.0);
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const std::size_t j = static_cast<std::size_t>(std::clamp(py + dy, 0, h - 1)) * w + std::clamp(px + dx, 0, w - 1);
              const glm::dvec3 c = toYCoCg({input.rgb[3 * j], input.rgb[3 * j + 1], input.rgb[3 * j + 2]});
              sum += c, sumSq += c * c;
            }
          const glm::dvec3 mean = sum / 9.0, sigma = glm::sqrt(glm::max(sumSq / 9.0 - mean * mean, 0.0));
          // Catmull-Rom's negative lobes can overshoot at an edge; the clip below pulls such a
          // value back into the neighbourhood's box.
          const glm::dvec3 history = toYCoCg(sampleCatmullRom(*history_, q.x, q.y));
          // Salvi's clip towards the box centre.
          const glm::dvec3 offset = history - mean, extent = kGamma * sigma + 1e-7;
          const glm::dvec3 units = glm::abs(offset) / extent;
          const double outside = std::max({units.x, units.y, units.z});
          const glm::dvec3 clipped = outside > 1.0 ? mean + offset / outside : history;
          const glm::dvec3 current = toYCoCg({input.rgb[3 * i], input.rgb[3 * i + 1], input.rgb[3 * i + 2]});
          const glm::dvec3 blended = fromYCoCg(clipped + kBlend * (current - clipped));
          for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<float>(blended[k]);
          ++keptInRow;
        }
        return keptInRow;
      });
    }
    history_ = out;
    return MethodOutput{std::move(out), static_cast<double>(kept) / static_cast<double>(frame.pixelCount())};
  }

 private:
  static constexpr double kBlend = 0.1;  // Karis 2014: the current frame's weight
  static constexpr double kGamma = 1.0;  // Salvi 2016 suggests 0.75-1.25
  std::optional<RgbImage> history_;
};

}  // namespace

std::unique_ptr<TemporalMethod> makeTaaMethod() { return std::make_unique<TaaMethod>(); }

}  // namespace dynbench::evaluate
