// `svgf`: spatiotemporal variance-guided filtering, Schied et al., "Spatiotemporal Variance-Guided
// Filtering: Real-Time Reconstruction for Path-Traced Global Illumination", HPG 2017 ([S17]).
// Constants are the paper's unless marked [Falcor]: the authors' reference implementation of SVGF
// in NVIDIA Falcor (SVGFReproject, SVGFFilterMoments, SVGFAtrous passes), where the paper leaves a
// value open. Background pixels (no hit) have noise-free environment radiance and no G-buffer: they
// are passed through and do not count as history kept.
#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>

#include "evaluate/method.h"
#include "evaluate/svgf_atrous.h"

namespace dynbench::evaluate {
namespace {

constexpr double kAlphaColour = 0.2, kAlphaMoments = 0.2;  // [S17] §4.1: alpha = 0.2 for colour and moments
constexpr int kHistoryCap = 32;                           // [Falcor] the history length saturates
constexpr int kIterations = 5;                             // [S17] §4.3: five a-trous iterations
constexpr double kSigmaZ = 1.0, kSigmaN = 128.0, kSigmaL = 4.0;  // [S17] §4.4
constexpr double kDepthReject = 10.0, kNormalReject = 16.0;       // [Falcor] reprojection consistency
constexpr double kMomentsSigmaL = 10.0;                           // [Falcor] luminance weight there
constexpr double kAlbedoFloor = 1e-3;                             // demodulation of black albedo
constexpr double kDiffuseShare = 0.96;                            // glTF dielectric: 1 - F0
constexpr std::array<double, 3> kAtrous{3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0};  // [S17] §4.3: B3 spline 5x5

double luminance(glm::dvec3 c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; }

// max(0, n.n')^sigma_n with sigma_n = 128 = 2^7: seven squarings (std::pow was most of the filter's time).
static_assert(kSigmaN == 128.0);
double normalWeight(const glm::dvec3& a, const glm::dvec3& b) {
  double w = std::max(0.0, glm::dot(a, b));
  for (int i = 0; i < 7; ++i) w *= w;
  return w;
}

class SvgfMethod final : public TemporalMethod {
 public:
  std::string name() const override { return "svgf"; }
  nlohmann::json parameters() const override {
    return {{"alpha_colour", kAlphaColour}, {"alpha_moments", kAlphaMoments}, {"iterations", kIterations}, {"sigma_z", kSigmaZ},
            {"sigma_n", kSigmaN}, {"sigma_l", kSigmaL}, {"history_cap", kHistoryCap}};
  }
  void reset() override { history_.reset(); }

  Expected<MethodOutput> process(const frames::FeatureFrame& f) override {
    const int w = f.width, h = f.height;
    const std::size_t n = f.pixelCount();
    auto at = [&](const std::vector<float>& b, std::size_t i) { return glm::dvec3(b[3 * i], b[3 * i + 1], b[3 * i + 2]); };
    auto index = [w](int x, int y) { return static_cast<std::size_t>(y) * w + x; };
    // Depth gradient (central differences where the neighbours are surfaces) for the depth weight.
    // Rows in parallel here and below: each pixel's result depends on the inputs alone.
    std::vector<glm::dvec2> gradZ(n, glm::dvec2(0.0));
    tbb::parallel_for(0, h, [&](int y) {
      for (int x = 0; x < w; ++x) {
        auto dz = [&](int x0, int y0, int x1, int y1) {
          const std::size_t a = index(std::clamp(x0, 0, w - 1), std::clamp(y0, 0, h - 1)), b = index(std::clamp(x1, 0, w - 1), std::clamp(y1, 0, h - 1));
          return f.hit[a] > 0 && f.hit[b] > 0 ? (f.depth[b] - f.depth[a]) / std::max(1, (x1 - x0) + (y1 - y0)) : 0.0;
        };
        gradZ[index(x, y)] = {dz(x - 1, y, x + 1, y), dz(x, y - 1, x, y + 1)};
      }
    });

    // 1. Demodulate: illumination = radiance / albedo ([S17] §3). The radiance buffer holds the
    // specular reflection too, which is not proportional to the base colour: a glTF dielectric
    // reflects 0.96 base colour diffusely plus a 4 % (F0) white specular lobe (glTF 2.0, Appendix
    // B), so the demodulating albedo is 0.96 base + 0.04. Dividing by the base colour alone
    // magnifies the specular part of dark texels and spreads it over bright ones.
    std::vector<glm::dvec3> albedo(n), illumination(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
      albedo[i] = f.hit[i] > 0 ? glm::max(kDiffuseShare * at(f.albedo, i) + (1.0 - kDiffuseShare), kAlbedoFloor) : glm::dvec3(1.0);
      illumination[i] = (at(f.direct, i) + at(f.indirect, i)) / albedo[i];
    });

    // 2. Temporal accumulation of illumination and its luminance moments ([S17] §4.1).
    std::vector<glm::dvec2> moments(n);
    std::vector<int> length(n, 1);
    const long kept = sumOverRows(h, [&](int y) {
      long keptInRow = 0;
      for (int x = 0; x < w; ++x) {
        const std::size_t i = index(x, y);
        const double l = luminance(illumination[i]);
        moments[i] = {l, l * l};
        if (f.hit[i] <= 0 || !history_ || history_->width != w || history_->height != h) continue;
        const History& p = *history_;
        // The motion vector starts at this pixel's sample; the previous buffers are at its samples.
        const glm::dvec2 q = glm::dvec2(x + 0.5, y + 0.5) + f.camera.jitter + glm::dvec2(f.motion[2 * i], f.motion[2 * i + 1]) - p.jitter;
        if (!(std::abs(f.motion[2 * i]) < 1e8) || q.x < 0 || q.y < 0 || q.x > w || q.y > h) continue;
        const discard::BilinearTaps taps = discard::bilinearTaps(q.x, q.y, w, h);
        const double fwidthZ = std::abs(gradZ[i].x) + std::abs(gradZ[i].y);
        glm::dvec3 colour(0.0);
        glm::dvec2 m(0.0);
        double weight = 0.0, len = 0.0;
        for (int k = 0; k < 4; ++k) {
          const std::size_t j = taps.index[k];
          if (taps.weight[k] <= 0 || p.hit[j] <= 0 || p.id[j] != f.id[i]) continue;  // the same instance
          if (std::abs(p.depth[j] - f.depth[i]) / (fwidthZ + 1e-2) > kDepthReject) continue;
          // [Falcor]'s normal test distance / (fwidth(n) + 0.01) > 16, with fwidth(n) taken as 0.
          if (glm::length(p.normal[j] - at(f.normal, i)) / 1e-2 > kNormalReject) continue;
          colour += taps.weight[k] * p.illumination[j], m += taps.weight[k] * p.moments[j], len += taps.weight[k] * p.length[j];
          weight += taps.weight[k];
        }
        if (weight < 0.01) continue;  // [Falcor] too little valid history
        colour /= weight, m /= weight;
        length[i] = std::min(kHistoryCap, static_cast<int>(std::lround(len / weight)) + 1);
        const double a = std::max(kAlphaColour, 1.0 / length[i]), am = std::max(kAlphaMoments, 1.0 / length[i]);
        illumination[i] = colour + a * (illumination[i] - colour);
        moments[i] = m + am * (moments[i] - m);
        ++keptInRow;
      }
      return keptInRow;
    });

    // 3. Variance: from the temporal moments, or where the history is short (< 4 frames) from the
    // 7x7 bilateral neighbourhood's moments, boosted by 4 / length ([S17] §4.2, [Falcor]); then
    // 4. the à-trous wavelet filter, 5 iterations with steps 1, 2, 4, 8, 16 ([S17] §4.3-4.4). Both
    // in single precision over SIMD lanes (svgf_atrous.h); the first iteration's output is the
    // colour history of the next frame.
    planes_.resize(w, h);
    tbb::parallel_for(0, h, [&](int y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = index(x, y), j = planes_.at(x, y);
        planes_.depth[j] = f.depth[i], planes_.hit[j] = f.hit[i] > 0 ? 1.0f : 0.0f;
        planes_.nx[j] = f.normal[3 * i], planes_.ny[j] = f.normal[3 * i + 1], planes_.nz[j] = f.normal[3 * i + 2];
        planes_.gradX[j] = static_cast<float>(gradZ[i].x), planes_.gradY[j] = static_cast<float>(gradZ[i].y);
        planes_.r[j] = static_cast<float>(illumination[i].r), planes_.g[j] = static_cast<float>(illumination[i].g);
        planes_.b[j] = static_cast<float>(illumination[i].b);
        planes_.moment1[j] = static_cast<float>(moments[i].x), planes_.temporalVariance[j] = static_cast<float>(moments[i].y - moments[i].x * moments[i].x);
        planes_.historyLength[j] = static_cast<float>(length[i]);
      }
    });
    svgf::estimateVariance(planes_, static_cast<float>(kSigmaZ), static_cast<float>(kMomentsSigmaL));
    auto illuminationAt = [&](const svgf::AtrousPlanes& planes, std::size_t i, int x, int y) {
      const std::size_t j = planes.at(x, y);
      return f.hit[i] > 0 ? glm::dvec3(planes.r[j], planes.g[j], planes.b[j]) : illumination[i];
    };
    std::vector<glm::dvec3> feedback;
    for (int iteration = 0; iteration < kIterations; ++iteration) {
      svgf::atrousIteration(planes_, 1 << iteration, {static_cast<float>(kSigmaZ), static_cast<float>(kSigmaL)}, filtered_);
      std::swap(planes_.r, filtered_.r), std::swap(planes_.g, filtered_.g), std::swap(planes_.b, filtered_.b);
      std::swap(planes_.variance, filtered_.variance);
      if (iteration == 0) {
        feedback.resize(n);
        tbb::parallel_for(0, h, [&](int y) {
          for (int x = 0; x < w; ++x) feedback[index(x, y)] = illuminationAt(planes_, index(x, y), x, y);
        });
      }
    }
    tbb::parallel_for(0, h, [&](int y) {
      for (int x = 0; x < w; ++x) illumination[index(x, y)] = illuminationAt(planes_, index(x, y), x, y);
    });

    // 5. Remodulate with the albedo; keep this frame's history.
    RgbImage out = frameRadiance(f);
    History next;
    next.width = w, next.height = h, next.jitter = f.camera.jitter;
    next.moments = std::move(moments), next.length = std::move(length);
    next.depth = f.depth, next.id = f.id, next.hit = f.hit;
    next.normal.resize(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
      next.normal[i] = at(f.normal, i);
      if (f.hit[i] <= 0) return;
      const glm::dvec3 c = illumination[i] * albedo[i];
      for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<float>(c[k]);
    });
    next.illumination = feedback.empty() ? std::move(illumination) : std::move(feedback);
    history_ = std::move(next);
    return MethodOutput{std::move(out), static_cast<double>(kept) / static_cast<double>(n)};
  }

 private:
  // The à-trous planes, kept between frames to save their allocation.
  svgf::AtrousPlanes planes_, filtered_;
  struct History {
    int width = 0, height = 0;
    glm::dvec2 jitter{0.0};
    std::vector<glm::dvec3> illumination, normal;
    std::vector<glm::dvec2> moments;
    std::vector<int> length;
    std::vector<float> depth, id, hit;
  };
  std::optional<History> history_;
};

}  // namespace

std::unique_ptr<TemporalMethod> makeSvgfMethod() { return std::make_unique<SvgfMethod>(); }

}  // namespace dynbench::evaluate
