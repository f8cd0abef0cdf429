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
  std::string name() const override { return kSvgfMethod; }
  nlohmann::json parameters() const override {
    return {{"alpha_colour", kAlphaColour}, {"alpha_moments", kAlphaMoments}, {"iterations", kIterations}, {"sigma_z", kSigmaZ},
            {"sigma_n", kSigmaN}, {"sigma_l", kSigmaL}, {"history_cap", kHistoryCap}};
  }
  void reset() override { hasHistory_ = false; }

  // Every plane in single precision and kept from frame to frame (fresh vectors cost a page fault
  // every 4 KiB: at 1080p a third of the method's time when it was in double, issue 34).
  Expected<MethodOutput> process(const frames::FeatureFrame& f) override {
    const int w = f.width, h = f.height;
    const std::size_t n = f.pixelCount();
    const bool hasHistory = hasHistory_ && previous_.width == w && previous_.height == h;
    planes_.resize(w, h);

    // 1-2. Per pixel, rows in parallel (each pixel reads the inputs and the history alone).
    const long kept = sumOverRows(h, [&](int y) { return temporalRow(f, y, hasHistory); });

    // 3. Variance: from the temporal moments, or where the history is short (< 4 frames) from the
    // 7x7 bilateral neighbourhood's moments, boosted by 4 / length ([S17] §4.2, [Falcor]); then
    // 4. the à-trous wavelet filter, 5 iterations with steps 1, 2, 4, 8, 16 ([S17] §4.3-4.4). Both
    // over SIMD lanes (svgf_atrous.h); the first iteration's output is the colour history of the
    // next frame. Pixels that hit nothing pass through (their albedo is 1: the radiance). The filters
    // read `planes_.luminance`, written in step 1.
    svgf::estimateVariance(planes_, static_cast<float>(kSigmaZ), static_cast<float>(kMomentsSigmaL));
    // The last iteration writes the output, remodulated with the albedo (5.).
    RgbImage out{w, h, std::vector<float>(3 * n)};
    const svgf::Remodulation remodulation{f.albedo.data(), static_cast<float>(kDiffuseShare), static_cast<float>(1.0 - kDiffuseShare),
                                          static_cast<float>(kAlbedoFloor), out.rgb.data()};
    static_assert(kIterations >= 2, "the colour history is kept after the second iteration");
    for (int iteration = 0; iteration < kIterations; ++iteration) {
      const bool last = iteration + 1 == kIterations;
      svgf::atrousIteration(planes_, 1 << iteration, {static_cast<float>(kSigmaZ), static_cast<float>(kSigmaL)}, filtered_,
                            last ? &remodulation : nullptr);
      if (last) break;
      std::swap(planes_.r, filtered_.r), std::swap(planes_.g, filtered_.g), std::swap(planes_.b, filtered_.b);
      std::swap(planes_.variance, filtered_.variance), std::swap(planes_.luminance, filtered_.luminance);
      // After the second iteration's swap the scratch holds the first's output: the next frame's
      // colour history, swapped in rather than copied (the history planes' old contents, two
      // frames old, become scratch).
      if (iteration == 1)
        std::swap(filtered_.r, planes_.historyR), std::swap(filtered_.g, planes_.historyG), std::swap(filtered_.b, planes_.historyB);
    }

    // This frame's planes are the next one's history.
    hasHistory_ = true, previousJitter_ = f.camera.jitter;
    std::swap(planes_, previous_);
    return MethodOutput{std::move(out), static_cast<double>(kept) / static_cast<double>(n)};
  }

 private:
  // The demodulating albedo of a channel whose base colour is `base` (step 1): 1 where nothing was hit.
  static float demodulatingAlbedo(bool surface, float base) {
    if (!surface) return 1.0f;
    return std::max(static_cast<float>(kDiffuseShare) * base + static_cast<float>(1.0 - kDiffuseShare), static_cast<float>(kAlbedoFloor));
  }

  // Steps 1-2 for row y: the depth gradient, the demodulation, the temporal accumulation; writes
  // the à-trous planes (with the illumination's luminance) and the next frame's history. Returns
  // the pixels whose history was kept.
  long temporalRow(const frames::FeatureFrame& f, int y, bool hasHistory) {
    const int w = f.width, h = f.height;
    const std::size_t row = static_cast<std::size_t>(y) * w, j0 = planes_.at(0, y);
    const std::size_t above = static_cast<std::size_t>(std::max(y - 1, 0)) * w, below = static_cast<std::size_t>(std::min(y + 1, h - 1)) * w;
    const float *hit = f.hit.data(), *depth = f.depth.data(), *id = f.id.data() + row, *normal = f.normal.data() + 3 * row;
    const float *albedo = f.albedo.data() + 3 * row, *direct = f.direct.data() + 3 * row, *indirect = f.indirect.data() + 3 * row;
    const float* motion = f.motion.data() + 2 * row;
    float *pz = planes_.depth.data() + j0, *phit = planes_.hit.data() + j0, *pnx = planes_.nx.data() + j0, *pny = planes_.ny.data() + j0;
    float *pnz = planes_.nz.data() + j0, *pgx = planes_.gradX.data() + j0, *pgy = planes_.gradY.data() + j0;
    float *pr = planes_.r.data() + j0, *pg = planes_.g.data() + j0, *pb = planes_.b.data() + j0;
    float *pl = planes_.luminance.data() + j0, *pm1 = planes_.moment1.data() + j0, *pv = planes_.temporalVariance.data() + j0, *plen = planes_.historyLength.data() + j0;
    float* pid = planes_.id.data() + j0;
    // The previous frame's planes, read at the reprojected taps (padded indices).
    const svgf::AtrousPlanes& p = previous_;
    const float *histR = p.historyR.data(), *histG = p.historyG.data(), *histB = p.historyB.data(), *histM1 = p.moment1.data();
    const float *histV = p.temporalVariance.data(), *histLength = p.historyLength.data(), *histZ = p.depth.data(), *histHit = p.hit.data();
    const float *histId = p.id.data(), *histNx = p.nx.data(), *histNy = p.ny.data(), *histNz = p.nz.data();
    const glm::dvec2 jitterShift = f.camera.jitter - previousJitter_;
    // Step 1 for every pixel of the row, then step 2 for those with history, reading back what
    // step 1 wrote.
    for (int x = 0; x < w; ++x) {
      const std::size_t i = row + x;
      const bool surface = hit[i] > 0;
      // Depth gradient: central differences (half the difference of the clamped neighbours) where
      // both neighbours are surfaces (the depth weight's scale).
      const std::size_t left = row + std::max(x - 1, 0), right = row + std::min(x + 1, w - 1);
      pgx[x] = hit[left] > 0 && hit[right] > 0 ? (depth[right] - depth[left]) * 0.5f : 0.0f;
      pgy[x] = hit[above + x] > 0 && hit[below + x] > 0 ? (depth[below + x] - depth[above + x]) * 0.5f : 0.0f;
      // 1. Demodulate: illumination = radiance / albedo ([S17] §3). The radiance buffer holds the
      // specular reflection too, which is not proportional to the base colour: a glTF dielectric
      // reflects 0.96 base colour diffusely plus a 4 % (F0) white specular lobe (glTF 2.0,
      // Appendix B), so the demodulating albedo is 0.96 base + 0.04. Dividing by the base colour
      // alone magnifies the specular part of dark texels and spreads it over bright ones.
      float c[3];
      for (int k = 0; k < 3; ++k) c[k] = (direct[3 * x + k] + indirect[3 * x + k]) / demodulatingAlbedo(surface, albedo[3 * x + k]);
      pr[x] = c[0], pg[x] = c[1], pb[x] = c[2], pl[x] = pm1[x] = luminance(c[0], c[1], c[2]);
      pv[x] = 0.0f, plen[x] = 1.0f;
      // The normal is 0 where nothing was hit (AtrousPlanes).
      pnx[x] = surface ? normal[3 * x] : 0.0f, pny[x] = surface ? normal[3 * x + 1] : 0.0f, pnz[x] = surface ? normal[3 * x + 2] : 0.0f;
      pid[x] = id[x], pz[x] = depth[i], phit[x] = surface ? 1.0f : 0.0f;
    }
    if (!hasHistory) return 0;
    long keptInRow = 0;
    for (int x = 0; x < w; ++x) {
      // 2. Temporal accumulation of the illumination and its luminance moments ([S17] §4.1). The
      // moments are kept as the mean m1 and the variance v = m2 - m1^2 rather than m2, so single
      // precision does not cancel two large second moments: blending history taps gives
      // v = sum w v_k + sum w (m1_k - m1)^2 (weights normalised), and the exponential average
      // m2 <- m2 + a (l^2 - m2) becomes v <- (1 - a) v + a (1 - a) (l - m1)^2.
      if (phit[x] <= 0 || !(std::abs(motion[2 * x]) < 1e8)) continue;
      // The motion vector starts at this pixel's sample; the previous buffers are at its samples.
      const glm::dvec2 q = glm::dvec2(x + 0.5, y + 0.5) + jitterShift + glm::dvec2(motion[2 * x], motion[2 * x + 1]);
      if (!(q.x >= 0 && q.y >= 0 && q.x <= w && q.y <= h)) continue;
      const reprojection::BilinearTaps taps = reprojection::bilinearTaps(q.x, q.y, w, h, p.stride, p.at(0, 0));
      const float fwidthZ = std::abs(pgx[x]) + std::abs(pgy[x]);
      float weight[4], sumW = 0.0f;
      for (int k = 0; k < 4; ++k) {
        const std::size_t t = taps.index[k];
        weight[k] = 0.0f;
        if (taps.weight[k] <= 0 || histHit[t] <= 0 || histId[t] != pid[x]) continue;  // the same instance
        if (std::abs(histZ[t] - pz[x]) / (fwidthZ + 1e-2f) > kDepthReject) continue;  // [Falcor]
        // [Falcor]'s normal test distance / (fwidth(n) + 0.01) > 16, with fwidth(n) taken as 0:
        // |n' - n| > 0.16, compared squared.
        const float dx = histNx[t] - pnx[x], dy = histNy[t] - pny[x], dz = histNz[t] - pnz[x];
        if (dx * dx + dy * dy + dz * dz > static_cast<float>(kNormalReject * 1e-2 * kNormalReject * 1e-2)) continue;
        weight[k] = static_cast<float>(taps.weight[k]), sumW += weight[k];
      }
      if (sumW < 0.01f) continue;  // [Falcor] too little valid history below
      float colour[3] = {0, 0, 0}, mean = 0.0f, len = 0.0f;
      for (int k = 0; k < 4; ++k) {
        weight[k] /= sumW;
        const std::size_t t = taps.index[k];
        colour[0] += weight[k] * histR[t], colour[1] += weight[k] * histG[t], colour[2] += weight[k] * histB[t];
        mean += weight[k] * histM1[t], len += weight[k] * histLength[t];
      }
      float spread = 0.0f;
      for (int k = 0; k < 4; ++k) {
        const float d = histM1[taps.index[k]] - mean;
        spread += weight[k] * (histV[taps.index[k]] + d * d);
      }
      // (len >= 0: adding 0.5 and truncating rounds half up, as lround.)
      const float length = static_cast<float>(std::min(kHistoryCap, static_cast<int>(static_cast<double>(len) + 0.5) + 1));
      const float a = std::max(static_cast<float>(kAlphaColour), 1.0f / length);
      const float am = std::max(static_cast<float>(kAlphaMoments), 1.0f / length);
      const float c[3] = {colour[0] + a * (pr[x] - colour[0]), colour[1] + a * (pg[x] - colour[1]), colour[2] + a * (pb[x] - colour[2])};
      const float deviation = pm1[x] - mean;
      pr[x] = c[0], pg[x] = c[1], pb[x] = c[2], pl[x] = luminance(c[0], c[1], c[2]);
      pm1[x] = mean + am * deviation;
      pv[x] = (1.0f - am) * spread + am * (1.0f - am) * deviation * deviation;
      plen[x] = length;
      ++keptInRow;
    }
    return keptInRow;
  }

  // This frame's à-trous planes and the previous frame's (the history: its geometry, moments,
  // history length and illumination after the first iteration), swapped after each frame; the
  // iterations' scratch. Kept between frames to save their allocation.
  svgf::AtrousPlanes planes_, previous_, filtered_;
  bool hasHistory_ = false;
  glm::dvec2 previousJitter_{0.0};
};

}  // namespace

std::unique_ptr<TemporalMethod> makeSvgfMethod() { return std::make_unique<SvgfMethod>(); }

}  // namespace dynbench::evaluate
