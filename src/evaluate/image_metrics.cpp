#include "evaluate/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "evaluate/vector_loops.h"

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
  // Pixels in parallel (the sRGB curve's pow per channel made this a tenth of evaluate's time).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.pixelCount()), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t i = range.begin(); i < range.end(); ++i) {
      glm::dvec3 c(linear.rgb[3 * i], linear.rgb[3 * i + 1], linear.rgb[3 * i + 2]);
      c = glm::dvec3(flip::acesToneMap(scale * c.x), flip::acesToneMap(scale * c.y), flip::acesToneMap(scale * c.z));
      c = flip::linearToSrgb(glm::clamp(c, 0.0, 1.0));
      for (int k = 0; k < 3; ++k) out.rgb[3 * i + k] = static_cast<float>(c[k]);
    }
  });
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
  double kernelSum = 0.0, kernelD[kSize];
  for (int i = 0; i < kSize; ++i) kernelSum += kernelD[i] = std::exp(-(i - kRadius) * (i - kRadius) / (2.0 * kSigma * kSigma));
  double kernel[kSize];
  for (int i = 0; i < kSize; ++i) kernel[i] = kernelD[i] / kernelSum;
  // Windowed means of x, y, x^2, y^2, xy, separably over the valid region, each filter tap
  // accumulated over a contiguous row so that the loops vectorise. In double: the variances
  // E[x^2] - mu^2 cancel, and in single precision their error reached 1e-4 of c2 on flat regions.
  const int vw = w - kSize + 1, vh = h - kSize + 1;
  // Blocks of output rows in parallel, each with the horizontal moments of its rows and the
  // kSize - 1 below them in a buffer of its own (kept in cache; the horizontal pass over the
  // extra rows costs less than writing and reading back five planes of the whole image).
  constexpr int kBlock = 64;
  const int blocks = (vh + kBlock - 1) / kBlock;
  std::vector<double> blockSums(3 * static_cast<std::size_t>(blocks), 0.0);
  tbb::parallel_for(0, 3 * blocks, [&](int task) {
    const int channel = task / blocks, y0 = (task % blocks) * kBlock, y1 = std::min(vh, y0 + kBlock);
    const int rows = y1 - y0 + kSize - 1;
    const auto plane = static_cast<std::size_t>(rows) * static_cast<std::size_t>(vw);
    std::vector<double> moments(5 * plane), products(5 * static_cast<std::size_t>(w)), sums(5 * static_cast<std::size_t>(vw));
    for (int r = 0; r < rows; ++r) {
      // The row's x, y, x^2, y^2 and xy, then each tap of the kernel over them (addScaled).
      double* p[5];
      for (int j = 0; j < 5; ++j) p[j] = products.data() + static_cast<std::size_t>(j) * w;
      for (int x = 0; x < w; ++x) {
        const std::size_t i = 3 * (static_cast<std::size_t>(y0 + r) * w + x) + channel;
        const double a = reference.rgb[i], b = test.rgb[i];
        p[0][x] = a, p[1][x] = b, p[2][x] = a * a, p[3][x] = b * b, p[4][x] = a * b;
      }
      for (int j = 0; j < 5; ++j) {
        double* m = moments.data() + j * plane + static_cast<std::size_t>(r) * vw;
        std::fill(m, m + vw, 0.0);
        for (int k = 0; k < kSize; ++k) addScaled(m, p[j] + k, kernel[k], vw);
      }
    }
    double blockSum = 0.0;
    for (int y = y0; y < y1; ++y) {
      std::fill(sums.begin(), sums.end(), 0.0);
      for (int k = 0; k < kSize; ++k)
        for (int j = 0; j < 5; ++j)
          addScaled(sums.data() + static_cast<std::size_t>(j) * vw, moments.data() + j * plane + static_cast<std::size_t>(y - y0 + k) * vw, kernel[k], vw);
      double rowSum = 0.0;
      for (int x = 0; x < vw; ++x) {
        const double muA = sums[x], muB = sums[vw + x], varA = sums[2 * vw + x] - muA * muA, varB = sums[3 * vw + x] - muB * muB;
        const double cov = sums[4 * vw + x] - muA * muB;
        rowSum += ((2 * muA * muB + c1) * (2 * cov + c2)) / ((muA * muA + muB * muB + c1) * (varA + varB + c2));
      }
      blockSum += rowSum;
    }
    blockSums[static_cast<std::size_t>(task)] = blockSum;
  });
  // Blocks added in order (the result does not depend on the schedule).
  double total = 0.0;
  for (int channel = 0; channel < 3; ++channel) {
    double channelSum = 0.0;
    for (int b = 0; b < blocks; ++b) channelSum += blockSums[static_cast<std::size_t>(channel * blocks + b)];
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
