#pragma once
// `dynbench evaluate`: temporal methods run over a low-sample frames folder in order, each output
// scored against the converged render of the same frames (docs/metrics.md, "Temporal methods").
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "discard/discard.h"
#include "evaluate/flip.h"
#include "evaluate/method.h"

namespace dynbench::evaluate {

struct EvaluateOptions {
  std::filesystem::path frames;     // the input: noisy radiance, G-buffers, motion
  std::filesystem::path reference;  // converged frames of the same frame numbers and size
  std::vector<std::string> methods = builtInMethodNames();
  // Methods the caller made (the Python module's), scored after `methods` exactly as they are: reset
  // at the first frame and at every cut, then given every frame in order.
  std::vector<std::shared_ptr<TemporalMethod>> callerMethods;
  // The history tests of `accumulate` and of the warped-error mask: discard's default geometry
  // test (per tap: plane distance 1 % of the view depth, normal 0.1).
  discard::Thresholds thresholds;
  double pixelsPerDegree = flip::defaultPixelsPerDegree();
  std::filesystem::path json, csv;  // optional outputs
  // Optional: OUT/METHOD/frame_NNNNN.exr per frame (the external-method contract, so an output can
  // be scored again with external:OUT/METHOD) and OUT/METHOD/flip_worst.png, the ꟻLIP heatmap of the
  // method's worst frame.
  std::filesystem::path outDir;
};

// One frame of one method. Temporal scores are absent at the first frame and at cuts.
struct FrameScores {
  long frame = 0;
  bool cut = false;                       // history reset here (first frame, sidecar cut, or a gap)
  double flip = 0.0;                      // HDR-ꟻLIP mean
  double psnr = 0.0;                      // dB, display values
  std::optional<double> ssim;
  double relMse = 0.0;
  std::optional<double> tPsnr;            // dB, PSNR of the frame difference against the reference's
  std::optional<double> tRelMse;          // relMSE of the frame difference, relative to the reference
  std::optional<double> warpedErrorChange;  // RMS of e_t - warp(e_{t-1}), display units
  std::optional<double> warpValid;        // fraction of pixels the warp covers (not disoccluded)
  std::optional<double> historyUse;       // fraction of pixels whose history the method kept
};

// A mean over frames with its standard error (sd / sqrt(count); frames are correlated, so it is a
// lower bound of the uncertainty: docs/metrics.md).
struct MeanWithError {
  double mean = 0.0, standardError = 0.0;
  long count = 0;
};

struct MethodScores {
  std::string name;
  nlohmann::json parameters;
  std::vector<FrameScores> frames;
  MeanWithError flip, psnr, ssim, relMse, tPsnr, tRelMse, warpedErrorChange, historyUse;
  long worstFrame = -1;  // the frame with the highest ꟻLIP mean
};

struct EvaluateRun {
  std::filesystem::path frames, reference;
  int width = 0, height = 0;
  std::vector<MethodScores> methods;
  std::vector<std::string> warnings;
};

// (frames done, frames total).
using EvaluateProgress = std::function<void(std::size_t, std::size_t)>;
Expected<EvaluateRun> runEvaluate(const EvaluateOptions& options, const EvaluateProgress& progress = {});

// The reference's noise floor (issue 48): the mean HDR-ꟻLIP between two converged renders of the
// same frames with other seeds, `reference` as the reference and `other` as the test, over every
// frame of `other` (each must be in `reference`, the same size). A method whose ꟻLIP differs from
// another's by less than this cannot be told apart from it by this reference: the reference's own
// noise is as large (docs/suite.md, "The reference's noise floor").
Expected<MeanWithError> referenceNoiseFloor(const std::filesystem::path& reference, const std::filesystem::path& other,
                                            double pixelsPerDegree = flip::defaultPixelsPerDegree());

// Whether a method's ꟻLIP difference with `none` on its own input is within the reference's noise
// floor (strictly less): the reference cannot tell the two apart there (docs/suite.md). The one
// rule the suites' ≈ and the report's share.
inline bool withinNoiseFloor(double flipOverNone, double floor) { return std::abs(flipOverNone) < floor; }
// RUN/floor.json: {"format": "dynbench-noise-floor", "flip": {"mean", "stderr"}, "frames", "seeds":
// [reference, other]}, written atomically; read back with the file and pointer named in errors.
Expected<void> writeNoiseFloorJson(const std::filesystem::path& path, const MeanWithError& floor, unsigned referenceSeed, unsigned otherSeed);
Expected<MeanWithError> readNoiseFloorJson(const std::filesystem::path& path);

// Method x metric table (means with standard errors).
std::string evaluateMarkdown(const EvaluateRun& run);
// The `evaluate --json` document (docs/cli.md); what `report` reads.
nlohmann::json evaluateJson(const EvaluateRun& run);
// Reads back evaluateJson's document; errors name the file and JSON pointer.
Expected<EvaluateRun> readEvaluateJson(const std::filesystem::path& path);

// The folder name of a method's outputs under --out: its name with characters other than letters,
// digits, '-' and '_' replaced by '_'.
std::string methodFolder(const std::string& name);

}  // namespace dynbench::evaluate
