#include "evaluate/game_agreement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/image_io.h"
#include "core/math.h"

namespace dynbench::evaluate {

namespace {

// Separable Gaussian blur of a one-channel image (sigma in pixels, kernel to 3 sigma, edges clamped).
std::vector<double> blur(const std::vector<double>& image, int w, int h, double sigma) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<double> kernel(static_cast<std::size_t>(2 * radius + 1));
  for (int k = -radius; k <= radius; ++k) kernel[static_cast<std::size_t>(k + radius)] = std::exp(-0.5 * k * k / (sigma * sigma));
  const double sum = std::accumulate(kernel.begin(), kernel.end(), 0.0);
  for (double& k : kernel) k /= sum;
  std::vector<double> tmp(image.size()), out(image.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 0;
      for (int k = -radius; k <= radius; ++k) v += kernel[static_cast<std::size_t>(k + radius)] * image[static_cast<std::size_t>(y * w + std::clamp(x + k, 0, w - 1))];
      tmp[static_cast<std::size_t>(y * w + x)] = v;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 0;
      for (int k = -radius; k <= radius; ++k) v += kernel[static_cast<std::size_t>(k + radius)] * tmp[static_cast<std::size_t>(std::clamp(y + k, 0, h - 1) * w + x)];
      out[static_cast<std::size_t>(y * w + x)] = v;
    }
  return out;
}

// Reinhard's L / (L + mean L) over the pixels in `mask`: the same for any exposure of the image.
std::vector<double> toneMapped(const std::vector<double>& luminance, const std::vector<bool>& mask) {
  double mean = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < luminance.size(); ++i)
    if (mask[i]) mean += luminance[i], ++n;
  mean = n ? mean / static_cast<double>(n) : 0.0;
  std::vector<double> out(luminance.size(), 0.0);
  if (!(mean > 0)) return out;
  for (std::size_t i = 0; i < luminance.size(); ++i) out[i] = luminance[i] / (luminance[i] + mean);
  return out;
}

}  // namespace

bool depthAgrees(double rendered, double z, double near, double far) {
  const double step = std::ldexp(1.0, -24) * (far - near) / (far * near) * z * z;
  return std::abs(rendered - z) <= 4.0 * step + 0.01 * z;
}


WindowDepthView viewDepthFromWindow(const std::vector<float>& window, const std::vector<float>& renderDepth, const std::vector<float>& renderHit,
                                    double near) {
  // A perspective depth buffer holds d = (1/n - 1/z) / (1/n - 1/f), so 1/f = 1/n - (1/n - 1/z) / d.
  // Each pixel where the render has a surface gives one value for it; the median is the game's far
  // plane (one number per frame: pixels whose geometry differs are outliers of it).
  std::vector<double> inverseFar;
  for (std::size_t i = 0; i < window.size(); ++i)
    if (renderHit[i] > 0 && window[i] > 0.01 && window[i] < 0.999999 && renderDepth[i] > near)
      inverseFar.push_back(1.0 / near - (1.0 / near - 1.0 / renderDepth[i]) / window[i]);
  WindowDepthView view;
  double inverse = 0.0;
  if (!inverseFar.empty()) {
    std::nth_element(inverseFar.begin(), inverseFar.begin() + static_cast<std::ptrdiff_t>(inverseFar.size() / 2), inverseFar.end());
    inverse = std::max(inverseFar[inverseFar.size() / 2], 1e-9);
  }
  view.far = inverse > 0 ? 1.0 / inverse : 1e9;
  view.depth.resize(window.size());
  for (std::size_t i = 0; i < window.size(); ++i)
    view.depth[i] = window[i] >= 0.999999 ? 0.0f : static_cast<float>(1.0 / (1.0 / near - window[i] * (1.0 / near - inverse)));
  return view;
}

GameAgreement compareWithGame(const GameImages& m) {
  GameAgreement f;
  f.width = m.width;
  f.height = m.height;
  const std::size_t n = static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height);
  std::size_t either = 0, agree = 0, sameKind = 0, geometry = 0, unlit = 0;
  std::vector<bool> both(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const bool game = m.gameDepth[i] > 0, render = m.renderHit[i] > 0;
    sameKind += game == render;
    if (render) {
      ++geometry;
      unlit += !(m.renderLightReach[i] > 0);
    }
    if (!game && !render) continue;
    ++either;
    if (!(game && render)) continue;
    both[i] = true;
    agree += depthAgrees(m.renderDepth[i], m.gameDepth[i], m.near, m.far);
  }
  f.depthAgreement = either ? static_cast<double>(agree) / static_cast<double>(either) : 1.0;
  f.skyAgreement = n ? static_cast<double>(sameKind) / static_cast<double>(n) : 0.0;
  if (!m.gameDepthKnown) f.depthAgreement = f.skyAgreement = std::numeric_limits<double>::quiet_NaN();
  f.unlitShare = geometry ? static_cast<double>(unlit) / static_cast<double>(geometry) : 0.0;
  std::vector<double> game(n), render(n);
  for (std::size_t i = 0; i < n; ++i) {
    game[i] = luminance(glm::dvec3(srgbToLinear<double>(m.gameColour[3 * i]), srgbToLinear<double>(m.gameColour[3 * i + 1]),
                                   srgbToLinear<double>(m.gameColour[3 * i + 2])));
    render[i] = luminance(glm::dvec3(m.renderRadiance[3 * i], m.renderRadiance[3 * i + 1], m.renderRadiance[3 * i + 2]));
  }
  const double sigma = std::max(1.0, m.height / 90.0);
  const auto a = blur(toneMapped(game, both), m.width, m.height, sigma), b = blur(toneMapped(render, both), m.width, m.height, sigma);
  double ma = 0, mb = 0, count = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (both[i]) ma += a[i], mb += b[i], ++count;
  if (count > 1) {
    ma /= count;
    mb /= count;
    double sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (both[i]) sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma), sbb += (b[i] - mb) * (b[i] - mb);
    f.correlation = saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
  }
  f.passed = (!m.gameDepthKnown || f.depthAgreement >= kFidelityMinDepthAgreement) && f.correlation >= kFidelityMinCorrelation;
  return f;
}

}  // namespace dynbench::evaluate
