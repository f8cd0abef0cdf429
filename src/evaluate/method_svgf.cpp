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
static_assert(kSigmaN == 128.0, "svgf_atrous.cpp raises n . n' to 128 by seven squarings");
constexpr double kDepthReject = 10.0, kNormalReject = 16.0;       // [Falcor] reprojection consistency
constexpr double kMomentsSigmaL = 10.0;                           // [Falcor] luminance weight there
constexpr double kAlbedoFloor = 1e-3;                             // demodulation of black albedo
constexpr double kDiffuseShare = 0.96;                            // glTF dielectric: 1 - F0

float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

class SvgfMethod final : public TemporalMethod {
 public:
  std::string name() const override { return "svgf"; }
  nlohmann::json parameters() const override {
    return {{"alpha_colour", kAlphaColour}, {"alpha_moments", kAlphaMoments}, {"iterations", kIterations}, {"sigma_z", kSigmaZ},
            {"sigma_n", kSigmaN}, {"sigma_l", kSigmaL}, {"history_cap", kHistoryCap}};
  }
  void reset() override { history_.width = history_.height = 0; }

  // Every plane in single precision and kept from frame to frame (fresh vectors cost a page fault
  // every 4 KiB: at 1080p a third of the method's time when it was in double, issue 34).
  Expected<MethodOutput> process(const frames::FeatureFrame& f) override {
    const int w = f.width, h = f.height;
    const std::size_t n = f.pixelCount();
    const bool hasHistory = history_.width == w && history_.height == h;
    planes_.resize(w, h);
    next_.resize(n);

    // 1-2. Per pixel, rows in parallel (each pixel reads the inputs and the history alone):
    // the depth gradient; demodulation; temporal accumulation; the à-trous planes.
    const long kept = sumOverRows(h, [&](int y) {
      long keptInRow = 0;
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x, j = planes_.at(x, y);
        const bool surface = f.hit[i] > 0;
        // Depth gradient: central differences where the neighbours are surfaces (the depth weight's
        // scale).
        auto dz = [&](int x0, int y0, int x1, int y1) {
          const std::size_t a = static_cast<std::size_t>(std::clamp(y0, 0, h - 1)) * w + std::clamp(x0, 0, w - 1);
          const std::size_t b = static_cast<std::size_t>(std::clamp(y1, 0, h - 1)) * w + std::clamp(x1, 0, w - 1);
          return f.hit[a] > 0 && f.hit[b] > 0 ? (f.depth[b] - f.depth[a]) / static_cast<float>(std::max(1, (x1 - x0) + (y1 - y0))) : 0.0f;
        };
        // 1. Demodulate: illumination = radiance / albedo ([S17] §3). The radiance buffer holds the
        // specular reflection too, which is not proportional to the base colour: a glTF dielectric
        // reflects 0.96 base colour diffusely plus a 4 % (F0) white specular lobe (glTF 2.0,
        // Appendix B), so the demodulating albedo is 0.96 base + 0.04. Dividing by the base colour
        // alone magnifies the specular part of dark texels and spreads it over bright ones.
        const float gradX = dz(x - 1, y, x + 1, y), gradY = dz(x, y - 1, x, y + 1);
        float c[3], m1 = 0.0f, variance = 0.0f, length = 1.0f;
        for (int k = 0; k < 3; ++k) c[k] = (f.direct[3 * i + k] + f.indirect[3 * i + k]) / albedo(f, i, k);
        m1 = luminance(c[0], c[1], c[2]);
        // 2. Temporal accumulation of the illumination and its luminance moments ([S17] §4.1). The
        // moments are kept as the mean m1 and the variance v = m2 - m1^2 rather than m2, so single
        // precision does not cancel two large second moments: blending history taps gives
        // v = sum w v_k + sum w (m1_k - m1)^2 (weights normalised), and the exponential average
        // m2 <- m2 + a (l^2 - m2) becomes v <- (1 - a) v + a (1 - a) (l - m1)^2.
        if (surface && hasHistory) {
          const History& p = history_;
          // The motion vector starts at this pixel's sample; the previous buffers are at its samples.
          const glm::dvec2 q = glm::dvec2(x + 0.5, y + 0.5) + f.camera.jitter + glm::dvec2(f.motion[2 * i], f.motion[2 * i + 1]) - p.jitter;
          if (std::abs(f.motion[2 * i]) < 1e8 && q.x >= 0 && q.y >= 0 && q.x <= w && q.y <= h) {
            const discard::BilinearTaps taps = discard::bilinearTaps(q.x, q.y, w, h);
            const float fwidthZ = std::abs(gradX) + std::abs(gradY);
            const glm::vec3 normal(f.normal[3 * i], f.normal[3 * i + 1], f.normal[3 * i + 2]);
            float weight[4], sumW = 0.0f;
            for (int k = 0; k < 4; ++k) {
              const std::size_t t = taps.index[k];
              weight[k] = 0.0f;
              if (taps.weight[k] <= 0 || p.hit[t] <= 0 || p.id[t] != f.id[i]) continue;  // the same instance
              if (std::abs(p.depth[t] - f.depth[i]) / (fwidthZ + 1e-2f) > kDepthReject) continue;
              // [Falcor]'s normal test distance / (fwidth(n) + 0.01) > 16, with fwidth(n) taken as 0.
              const glm::vec3 previousNormal(p.normal[3 * t], p.normal[3 * t + 1], p.normal[3 * t + 2]);
              if (glm::length(previousNormal - normal) / 1e-2f > kNormalReject) continue;
              weight[k] = static_cast<float>(taps.weight[k]), sumW += weight[k];
            }
            if (sumW >= 0.01f) {  // [Falcor] too little valid history below
              float colour[3] = {0, 0, 0}, mean = 0.0f, len = 0.0f;
              for (int k = 0; k < 4; ++k) {
                const float wk = weight[k] / sumW;
                const std::size_t t = taps.index[k];
                colour[0] += wk * p.r[t], colour[1] += wk * p.g[t], colour[2] += wk * p.b[t];
                mean += wk * p.moment1[t], len += wk * p.length[t];
              }
              float spread = 0.0f;
              for (int k = 0; k < 4; ++k) {
                const float d = p.moment1[taps.index[k]] - mean;
                spread += weight[k] / sumW * (p.variance[taps.index[k]] + d * d);
              }
              length = static_cast<float>(std::min(kHistoryCap, static_cast<int>(std::lround(len)) + 1));
              const float a = std::max(static_cast<float>(kAlphaColour), 1.0f / length);
              const float am = std::max(static_cast<float>(kAlphaMoments), 1.0f / length);
              for (int k = 0; k < 3; ++k) c[k] = colour[k] + a * (c[k] - colour[k]);
              const float deviation = m1 - mean;
              m1 = mean + am * deviation;
              variance = (1.0f - am) * spread + am * (1.0f - am) * deviation * deviation;
              ++keptInRow;
            }
          }
        }
        next_.moment1[i] = m1, next_.variance[i] = variance, next_.length[i] = length;
        planes_.depth[j] = f.depth[i], planes_.hit[j] = surface ? 1.0f : 0.0f;
        // The normal is 0 where nothing was hit (AtrousPlanes).
        planes_.nx[j] = surface ? f.normal[3 * i] : 0.0f, planes_.ny[j] = surface ? f.normal[3 * i + 1] : 0.0f;
        planes_.nz[j] = surface ? f.normal[3 * i + 2] : 0.0f;
        planes_.gradX[j] = gradX, planes_.gradY[j] = gradY;
        planes_.r[j] = c[0], planes_.g[j] = c[1], planes_.b[j] = c[2];
        planes_.moment1[j] = m1, planes_.temporalVariance[j] = variance, planes_.historyLength[j] = length;
      }
      return keptInRow;
    });

    // 3. Variance: from the temporal moments, or where the history is short (< 4 frames) from the
    // 7x7 bilateral neighbourhood's moments, boosted by 4 / length ([S17] §4.2, [Falcor]); then
    // 4. the à-trous wavelet filter, 5 iterations with steps 1, 2, 4, 8, 16 ([S17] §4.3-4.4). Both
    // over SIMD lanes (svgf_atrous.h); the first iteration's output is the colour history of the
    // next frame. Pixels that hit nothing pass through (their albedo is 1: the radiance).
    svgf::estimateVariance(planes_, static_cast<float>(kSigmaZ), static_cast<float>(kMomentsSigmaL));
    for (int iteration = 0; iteration < kIterations; ++iteration) {
      svgf::atrousIteration(planes_, 1 << iteration, {static_cast<float>(kSigmaZ), static_cast<float>(kSigmaL)}, filtered_);
      std::swap(planes_.r, filtered_.r), std::swap(planes_.g, filtered_.g), std::swap(planes_.b, filtered_.b);
      std::swap(planes_.variance, filtered_.variance);
      if (iteration == 0)
        tbb::parallel_for(0, h, [&](int y) {
          const std::size_t row = static_cast<std::size_t>(y) * w, j = planes_.at(0, y);
          std::copy_n(planes_.r.data() + j, w, next_.r.data() + row);
          std::copy_n(planes_.g.data() + j, w, next_.g.data() + row);
          std::copy_n(planes_.b.data() + j, w, next_.b.data() + row);
        });
    }

    // 5. Remodulate with the albedo; keep this frame's history.
    RgbImage out{w, h, std::vector<float>(3 * n)};
    tbb::parallel_for(0, h, [&](int y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x, j = planes_.at(x, y);
        const float c[3] = {planes_.r[j], planes_.g[j], planes_.b[j]};
        for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = c[k] * albedo(f, i, k);
      }
    });
    next_.width = w, next_.height = h, next_.jitter = f.camera.jitter;
    next_.depth.assign(f.depth.begin(), f.depth.end()), next_.id.assign(f.id.begin(), f.id.end());
    next_.hit.assign(f.hit.begin(), f.hit.end()), next_.normal.assign(f.normal.begin(), f.normal.end());
    std::swap(history_, next_);
    return MethodOutput{std::move(out), static_cast<double>(kept) / static_cast<double>(n)};
  }

 private:
  // The demodulating albedo of channel k (step 1): 1 where nothing was hit.
  static float albedo(const frames::FeatureFrame& f, std::size_t i, int k) {
    if (f.hit[i] <= 0) return 1.0f;
    return std::max(static_cast<float>(kDiffuseShare) * f.albedo[3 * i + k] + static_cast<float>(1.0 - kDiffuseShare), static_cast<float>(kAlbedoFloor));
  }
  // The à-trous planes, kept between frames to save their allocation.
  svgf::AtrousPlanes planes_, filtered_;
  // The previous frame's illumination (after the first à-trous iteration), moments (mean and
  // variance, step 2), history length and geometry; `next_` is filled while `history_` is read.
  struct History {
    int width = 0, height = 0;
    glm::dvec2 jitter{0.0};
    std::vector<float> r, g, b, moment1, variance, length, depth, id, hit, normal;
    void resize(std::size_t n) {
      for (auto* plane : {&r, &g, &b, &moment1, &variance, &length}) plane->resize(n);
    }
  };
  History history_, next_;
};

}  // namespace

std::unique_ptr<TemporalMethod> makeSvgfMethod() { return std::make_unique<SvgfMethod>(); }

}  // namespace dynbench::evaluate
