#include "evaluate/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "evaluate/magma.h"  // generated from Debian's matplotlib (tools/colormap/magma_header.py)

namespace dynbench::evaluate {

double displayScale(const RgbImage& reference) {
  const std::size_t n = reference.pixelCount();
  if (n == 0) return 1.0;
  double logSum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double y = 0.2126 * reference.rgb[3 * i] + 0.7152 * reference.rgb[3 * i + 1] + 0.0722 * reference.rgb[3 * i + 2];
    logSum += std::log(1e-4 + std::max(0.0, y));
  }
  return 0.18 / std::exp(logSum / static_cast<double>(n));
}

RgbImage toDisplay(const RgbImage& linear, double scale) {
  RgbImage out = linear;
  for (std::size_t i = 0; i < out.pixelCount(); ++i) {
    glm::dvec3 c(linear.rgb[3 * i], linear.rgb[3 * i + 1], linear.rgb[3 * i + 2]);
    c = glm::dvec3(flip::acesToneMap(scale * c.x), flip::acesToneMap(scale * c.y), flip::acesToneMap(scale * c.z));
    c = flip::linearToSrgb(glm::clamp(c, 0.0, 1.0));
    for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<float>(c[k]);
  }
  return out;
}

double psnr(const RgbImage& reference, const RgbImage& test) {
  double sum = 0.0;
  for (std::size_t i = 0; i < reference.rgb.size(); ++i) {
    const double d = static_cast<double>(test.rgb[i]) - reference.rgb[i];
    sum += d * d;
  }
  const double mse = sum / static_cast<double>(reference.rgb.size());
  return mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(1.0 / mse);
}

std::optional<double> ssim(const RgbImage& reference, const RgbImage& test) {
  constexpr int kSize = 11, kRadius = 5;
  constexpr double kSigma = 1.5, c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;  // (K1 L)^2, (K2 L)^2 with L = 1
  const int w = reference.width, h = reference.height;
  if (w < kSize || h < kSize) return std::nullopt;
  double kernel[kSize], kernelSum = 0.0;
  for (int i = 0; i < kSize; ++i) kernelSum += kernel[i] = std::exp(-(i - kRadius) * (i - kRadius) / (2.0 * kSigma * kSigma));
  for (double& k : kernel) k /= kernelSum;
  // Windowed means of x, y, x^2, y^2, xy, separably over the valid region.
  const int vw = w - kSize + 1, vh = h - kSize + 1;
  double total = 0.0;
  for (int channel = 0; channel < 3; ++channel) {
    std::vector<double> rows(5 * static_cast<std::size_t>(vw) * h);  // horizontal pass, 5 moments
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < vw; ++x) {
        double m[5] = {0, 0, 0, 0, 0};
        for (int k = 0; k < kSize; ++k) {
          const std::size_t p = 3 * (static_cast<std::size_t>(y) * w + x + k) + channel;
          const double a = reference.rgb[p], b = test.rgb[p];
          m[0] += kernel[k] * a, m[1] += kernel[k] * b, m[2] += kernel[k] * a * a, m[3] += kernel[k] * b * b, m[4] += kernel[k] * a * b;
        }
        std::copy(m, m + 5, rows.begin() + 5 * (static_cast<std::ptrdiff_t>(y) * vw + x));
      }
    double channelSum = 0.0;
    for (int y = 0; y < vh; ++y)
      for (int x = 0; x < vw; ++x) {
        double m[5] = {0, 0, 0, 0, 0};
        for (int k = 0; k < kSize; ++k)
          for (int j = 0; j < 5; ++j) m[j] += kernel[k] * rows[5 * (static_cast<std::size_t>(y + k) * vw + x) + j];
        const double muA = m[0], muB = m[1], varA = m[2] - muA * muA, varB = m[3] - muB * muB, cov = m[4] - muA * muB;
        channelSum += ((2 * muA * muB + c1) * (2 * cov + c2)) / ((muA * muA + muB * muB + c1) * (varA + varB + c2));
      }
    total += channelSum / (static_cast<double>(vw) * vh);
  }
  return total / 3.0;
}

double relMse(const RgbImage& reference, const RgbImage& test) {
  double sum = 0.0;
  for (std::size_t i = 0; i < reference.rgb.size(); ++i) {
    const double r = reference.rgb[i], d = static_cast<double>(test.rgb[i]) - r;
    sum += d * d / (r * r + 0.01);
  }
  return reference.rgb.empty() ? 0.0 : sum / static_cast<double>(reference.rgb.size());
}

double smape(const RgbImage& reference, const RgbImage& test) {
  double sum = 0.0;
  for (std::size_t i = 0; i < reference.rgb.size(); ++i) {
    const double r = reference.rgb[i], t = test.rgb[i];
    sum += std::abs(t - r) / (std::abs(t) + std::abs(r) + 0.01);
  }
  return reference.rgb.empty() ? 0.0 : sum / static_cast<double>(reference.rgb.size());
}

glm::vec3 magmaColour(float value) {
  // The authors' tool indexes its 256-entry map by value * 255 rounded to nearest.
  const float v = std::isfinite(value) ? std::clamp(value, 0.0f, 1.0f) : 1.0f;
  const auto& c = generated::kMagma[static_cast<std::size_t>(v * 255.0f + 0.5f)];
  return {c[0], c[1], c[2]};
}

std::vector<float> magma(const std::vector<float>& error) {
  std::vector<float> rgb(3 * error.size());
  for (std::size_t i = 0; i < error.size(); ++i) {
    const glm::vec3 c = magmaColour(error[i]);
    rgb[3 * i] = c.r, rgb[3 * i + 1] = c.g, rgb[3 * i + 2] = c.b;
  }
  return rgb;
}

}  // namespace dynbench::evaluate
