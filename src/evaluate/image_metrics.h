#pragma once
// Image metrics besides ꟻLIP (docs/metrics.md, "Image metrics"): PSNR and SSIM on display values
// in [0, 1], relMSE and SMAPE on linear values. One function each, on RgbImage (evaluate/flip.h).
#include <optional>
#include <vector>

#include "evaluate/flip.h"

namespace dynbench::evaluate {

// The scale that takes a linear HDR image to display exposure: Reinhard et al.'s key value 0.18
// over the reference's log-average luminance exp(mean(log(1e-4 + Y))) (Reinhard et al. 2002,
// Eqs. 1-2). The same scale is applied to the test image, so both are seen at one exposure.
double displayScale(const RgbImage& referenceLinear);
// Linear HDR -> display values in [0, 1]: scaled, ACES (flip::acesToneMap), clamped, sRGB-encoded.
RgbImage toDisplay(const RgbImage& linear, double scale);

// PSNR in dB of display images in [0, 1]: 10 log10(1 / MSE) over all pixels and channels; +inf for
// identical images.
double psnr(const RgbImage& reference, const RgbImage& test);
// SSIM (Wang et al. 2004, Eq. 13): 11x11 Gaussian window with sigma 1.5, K1 = 0.01, K2 = 0.03,
// dynamic range L = 1, on each channel of display images; the mean over the pixels whose whole
// window lies inside the image (Wang's 'valid' filtering), averaged over R, G, B. nullopt when the
// image is smaller than the window.
std::optional<double> ssim(const RgbImage& reference, const RgbImage& test);
// relMSE (Rousselle et al. 2011): mean over pixels and channels of (t - r)^2 / (r^2 + 0.01).
double relMse(const RgbImage& reference, const RgbImage& test);
// SMAPE (Vogels et al. 2018): mean over pixels and channels of |t - r| / (|t| + |r| + 0.01).
double smape(const RgbImage& reference, const RgbImage& test);

// An error map in [0, 1] as 8-bit RGB through matplotlib's magma (0 black-purple, 1 pale yellow),
// values in [0, 1] per channel, 3 per pixel.
std::vector<float> magma(const std::vector<float>& error);
glm::vec3 magmaColour(float value);

}  // namespace dynbench::evaluate
