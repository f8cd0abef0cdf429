#include "core/json_fields.h"
#include "evaluate/compare.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/files.h"
#include "core/image_io.h"
#include "evaluate/image_metrics.h"

namespace dynbench::evaluate {
namespace {

namespace fs = std::filesystem;

bool isHdrFile(const fs::path& path) {
  const std::string ext = lowercaseExtension(path);
  return ext == ".exr" || ext == ".hdr";
}

int channelIndex(const FloatImage& image, const std::string& name) {
  if (image.channelNames.empty()) {
    static const char* defaults[] = {"R", "G", "B", "A"};
    for (int i = 0; i < std::min(image.channels, 4); ++i)
      if (name == defaults[i]) return i;
    return -1;
  }
  for (int i = 0; i < static_cast<int>(image.channelNames.size()); ++i)
    if (image.channelNames[i] == name) return i;
  return -1;
}

}  // namespace

Expected<LoadedImage> loadImage(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return fail(ErrorCode::kIo, "{}: no such image file", path.string());
  auto file = readImage(path);
  if (!file) return std::unexpected(file.error());
  LoadedImage out;
  out.hdr = isHdrFile(path);
  RgbImage& img = out.linear;
  img.width = file->width, img.height = file->height;
  img.rgb.resize(3 * img.pixelCount());
  // Which channels make R, G and B (summed when a colour is split, as direct + indirect).
  std::vector<std::vector<int>> sources(3);
  const char* rgb[] = {"R", "G", "B"};
  for (int k = 0; k < 3; ++k) {
    if (int c = channelIndex(*file, rgb[k]); c >= 0) {
      sources[k] = {c};
    } else if (int d = channelIndex(*file, fmt::format("direct.{}", rgb[k])), i = channelIndex(*file, fmt::format("indirect.{}", rgb[k]));
               d >= 0 && i >= 0) {
      sources[k] = {d, i};
    } else if (file->channels == 1 || (file->channels == 2 && channelIndex(*file, "A") == 1)) {
      sources[k] = {0};  // grey (with alpha)
    } else {
      std::string names;
      for (int c = 0; c < file->channels; ++c)
        names += (c ? ", " : "") + (file->channelNames.empty() ? fmt::format("#{}", c) : file->channelNames[c]);
      return fail(ErrorCode::kInvalidData,
                  "{}: no channel {} (expected R, G, B, a grey image, or a dynbench frame's direct.* and indirect.*; it has {})",
                  path.string(), rgb[k], names);
    }
  }
  for (std::size_t p = 0; p < img.pixelCount(); ++p) {
    for (int k = 0; k < 3; ++k) {
      float v = 0.0f;
      for (int c : sources[k]) v += file->pixels[p * file->channels + c];
      if (!std::isfinite(v))
        return fail(ErrorCode::kInvalidData, "{}: pixel ({}, {}) channel {} is {} (expected a finite number)", path.string(),
                    p % img.width, p / img.width, rgb[k], v);
      img.rgb[3 * p + k] = v;
    }
    if (!out.hdr) {
      const glm::dvec3 linear = flip::srgbToLinear(glm::clamp(glm::dvec3(img.rgb[3 * p], img.rgb[3 * p + 1], img.rgb[3 * p + 2]), 0.0, 1.0));
      for (int k = 0; k < 3; ++k) img.rgb[3 * p + k] = static_cast<float>(linear[k]);
    }
  }
  return out;
}

namespace {

// An LDR image (linear, decoded from sRGB) back to the values its file encodes.
RgbImage encodeSrgb(RgbImage image) {
  for (std::size_t p = 0; p < image.pixelCount(); ++p) {
    const glm::dvec3 c = flip::linearToSrgb(glm::dvec3(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]));
    for (int k = 0; k < 3; ++k) image.rgb[3 * p + k] = static_cast<float>(c[k]);
  }
  return image;
}

}  // namespace

PreparedReference::PreparedReference(const RgbImage& reference, bool hdr_, double ppd) : linear(reference), hdr(hdr_), pixelsPerDegree(ppd) {
  // PSNR and SSIM on display values: HDR through the reference's display exposure and ACES, LDR as
  // the file encodes it (sRGB).
  if (hdr) {
    displayScale = evaluate::displayScale(reference);
    display = toDisplay(reference, displayScale);
    flip.emplace(reference, ppd);
  } else {
    display = encodeSrgb(reference);
  }
}

ScoredImage scoreImage(const PreparedReference& reference, const RgbImage& test) {
  ScoredImage out;
  ImageScores& s = out.scores;
  s.hdr = reference.hdr;
  if (reference.hdr) {
    flip::HdrFlipResult r = reference.flip->compare(test);
    out.flipError = std::move(r.error);
    s.exposures = r.exposures;
  } else {
    out.flipError = flip::ldrFlip(reference.linear, test, reference.pixelsPerDegree);
  }
  s.flip = flip::pool(out.flipError);
  const RgbImage testDisplay = reference.hdr ? toDisplay(test, reference.displayScale) : encodeSrgb(test);
  s.psnr = psnr(reference.display, testDisplay);
  s.ssim = ssim(reference.display, testDisplay);
  s.relMse = relMse(reference.linear, test);
  s.smape = smape(reference.linear, test);
  return out;
}

ScoredImage scoreImage(const RgbImage& reference, const RgbImage& test, bool hdr, double ppd) {
  return scoreImage(PreparedReference(reference, hdr, ppd), test);
}

nlohmann::json scoresJson(const ImageScores& s) {
  nlohmann::json j;
  j["mode"] = s.hdr ? "hdr" : "ldr";
  j["flip"] = {{"mean", s.flip.mean},
               {"weighted_median", s.flip.weightedMedian},
               {"weighted_q1", s.flip.weightedQ1},
               {"weighted_q3", s.flip.weightedQ3},
               {"max", s.flip.max}};
  if (s.exposures) j["exposures"] = {{"start", s.exposures->start}, {"stop", s.exposures->stop}, {"count", s.exposures->count}};
  j["psnr"] = std::isfinite(s.psnr) ? nlohmann::json(s.psnr) : nlohmann::json(nullptr);
  j["ssim"] = s.ssim ? nlohmann::json(*s.ssim) : nlohmann::json(nullptr);
  j["relmse"] = s.relMse;
  j["smape"] = s.smape;
  return j;
}

Expected<CompareResult> runCompare(const CompareOptions& options) {
  auto reference = loadImage(options.reference);
  if (!reference) return std::unexpected(reference.error());
  CompareResult result;
  nlohmann::json doc = {{"reference", options.reference.string()}, {"pixels_per_degree", options.pixelsPerDegree}, {"images", nlohmann::json::array()}};
  result.markdown = "| test | ꟻLIP mean | weighted median | Q1 | Q3 | PSNR (dB) | SSIM | relMSE | SMAPE |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  if (!options.heatmapDir.empty()) {
    std::error_code ec;
    fs::create_directories(options.heatmapDir, ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot create the heatmap folder: {}", options.heatmapDir.string(), ec.message());
  }
  for (const fs::path& path : options.tests) {
    auto test = loadImage(path);
    if (!test) return std::unexpected(test.error());
    if (test->linear.width != reference->linear.width || test->linear.height != reference->linear.height)
      return fail(ErrorCode::kInvalidData, "{}: {}x{} pixels, but the reference {} is {}x{} (images must be the same size)", path.string(),
                  test->linear.width, test->linear.height, options.reference.string(), reference->linear.width, reference->linear.height);
    if (test->hdr != reference->hdr)
      return fail(ErrorCode::kInvalidData, "{}: an {} image, but the reference {} is {} (compare HDR with HDR, LDR with LDR)", path.string(),
                  test->hdr ? "HDR" : "LDR", options.reference.string(), reference->hdr ? "HDR" : "LDR");
    ScoredImage scored = scoreImage(reference->linear, test->linear, reference->hdr, options.pixelsPerDegree);
    const ImageScores& s = scored.scores;
    nlohmann::json entry = scoresJson(s);
    entry["test"] = path.string();
    doc["images"].push_back(entry);
    result.markdown += fmt::format("| {} | {:.4f} | {:.4f} | {:.4f} | {:.4f} | {} | {} | {:.4g} | {:.4g} |\n", path.filename().string(), s.flip.mean,
                                   s.flip.weightedMedian, s.flip.weightedQ1, s.flip.weightedQ3,
                                   std::isfinite(s.psnr) ? fmt::format("{:.2f}", s.psnr) : "∞", s.ssim ? fmt::format("{:.4f}", *s.ssim) : "n/a",
                                   s.relMse, s.smape);
    if (!options.heatmapDir.empty()) {
      FloatImage heat;
      heat.width = test->linear.width, heat.height = test->linear.height, heat.channels = 3;
      heat.pixels = magma(scored.flipError);
      auto written = writeImage(options.heatmapDir / fmt::format("flip_{}.png", path.stem().string()), heat);
      if (!written) return std::unexpected(written.error());
    }
    result.scores.push_back(s);
  }
  if (!options.json.empty()) {
    auto written = writeFileAtomic(options.json, jsonFileText(doc));
    if (!written) return std::unexpected(written.error());
  }
  result.document = std::move(doc);
  return result;
}

}  // namespace dynbench::evaluate
