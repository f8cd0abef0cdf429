#pragma once
// `dynbench compare`: image metrics between a reference and test images of the same size, EXR
// (HDR: linear radiance) or PNG (LDR: sRGB-encoded), as the ꟻLIP authors' tool takes them.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "evaluate/flip.h"

namespace dynbench::evaluate {

// An image as the metrics take it: linear RGB (a PNG is decoded from sRGB).
struct LoadedImage {
  RgbImage linear;
  bool hdr = false;  // EXR / HDR files; PNG and JPEG are LDR
};
// Reads an image's RGB: channels R, G, B (a one-channel image is grey); a dynbench frame
// (direct.* and indirect.*, docs/feature-buffers.md) gives direct + indirect. Errors name the file
// and what is missing, and the first pixel that is NaN or infinite.
Expected<LoadedImage> loadImage(const std::filesystem::path& path);

// Every metric of one test image against the reference (docs/metrics.md).
struct ImageScores {
  bool hdr = false;
  flip::Pooled flip;                               // HDR-ꟻLIP for HDR input, else LDR-ꟻLIP
  std::optional<flip::ExposureRange> exposures;    // HDR-ꟻLIP's exposures
  double psnr = 0.0;                               // dB on display values; +inf when identical
  std::optional<double> ssim;                      // absent below 11 x 11 pixels
  double relMse = 0.0, smape = 0.0;                // on linear values
};
struct ScoredImage {
  ImageScores scores;
  std::vector<float> flipError;  // per pixel, for heatmaps
};
// Scores `test` against `reference` (same size, same range; the caller checks).
ScoredImage scoreImage(const RgbImage& reference, const RgbImage& test, bool hdr, double pixelsPerDegree);
// A reference prepared once for scoring many test images against it: its HDR-ꟻLIP half and its
// display image. scoreImage(prepared, test) equals scoreImage(reference, test, hdr, ppd).
struct PreparedReference {
  PreparedReference(const RgbImage& reference, bool hdr, double pixelsPerDegree);
  RgbImage linear, display;
  bool hdr;
  double pixelsPerDegree, displayScale = 1.0;
  std::optional<flip::HdrFlipReference> flip;
};
ScoredImage scoreImage(const PreparedReference& reference, const RgbImage& test);

struct CompareOptions {
  std::filesystem::path reference;
  std::vector<std::filesystem::path> tests;
  double pixelsPerDegree = flip::defaultPixelsPerDegree();
  std::filesystem::path json;        // optional: scores as JSON (docs/cli.md)
  std::filesystem::path heatmapDir;  // optional: flip_<test stem>.png per test, magma
};
struct CompareResult {
  std::vector<ImageScores> scores;  // one per test, in order
  std::string markdown;             // a table of the scores
  nlohmann::json document;          // the --json document (docs/cli.md)
};
Expected<CompareResult> runCompare(const CompareOptions& options);

// ImageScores as JSON: flip {mean, weighted_median, weighted_q1, weighted_q3, max}, exposures,
// psnr (null when infinite), ssim (null when absent), relmse, smape.
nlohmann::json scoresJson(const ImageScores& scores);

}  // namespace dynbench::evaluate
