#pragma once
// `dynbench suite MANIFEST -o DIR`: a versioned benchmark of many datasets, from capture to method
// scores, and whether its difficulty measures predict the methods' errors (issue 37). The manifest
// (docs/suite.md) lists datasets (engine, preset, map, seed, seconds, camera: the bot's own or a
// fly-through) and one render window and method list for all. Each dataset is captured, converted,
// flown through if asked, and measured by measureDataset (dataset_run.h); DIR/suite.json records
// the tool version, the manifest, every number and a SHA-256 of every file the numbers come from,
// so `suite verify DIR` can recompute them.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "metrics/rank_correlation.h"
#include "pipeline/dataset_run.h"
#include "cluster/slurm.h"

namespace dynbench::suite {

inline constexpr int kManifestVersion = 1;  // "dynbench_suite" in a manifest
inline constexpr int kResultsVersion = 1;   // "dynbench_suite_results" in suite.json

struct DatasetSpec {
  std::string name;             // unique in the suite: the RUN folder's name
  std::string engine = "cube2";  // or "openarena" (no presets; map oa_dm1 and 4 bots unless given)
  std::string preset;           // a capture preset (calm, fps, hard) or empty
  std::string map;              // empty: the preset's (or colos)
  int bots = 0;                 // 0: the preset's (or 6)
  unsigned seed = 1;
  double seconds = 10.0;        // game time captured
  std::string camera = "bot";   // "bot" (the first-person bot) or "flythrough"
  // Pins (/datasets/N/sha256/capture and /dataset): the SHA-256 the capture folder and the dataset
  // must have (captureDigest, scene::datasetDigest); empty: not checked.
  std::string captureSha256, datasetSha256;
};

struct Manifest {
  int version = kManifestVersion;
  std::string name, description;
  pipeline::DatasetRunSettings run;  // the render window, samples and methods of every dataset
  std::vector<DatasetSpec> datasets;
  nlohmann::json document;           // as read (recorded in suite.json)
  std::filesystem::path path;        // where it was read from (errors name it)
};
// Errors name the file and the JSON pointer of the value and what was expected.
Expected<Manifest> readManifest(const std::filesystem::path& path);
// The same of a manifest already parsed (`path` names it in errors).
Expected<Manifest> parseManifest(const nlohmann::json& document, const std::filesystem::path& path);

// A capture folder's digest, what /datasets/N/sha256/capture pins: every file in it (Capture.txt,
// LICENSES.txt, models/*.txt; names starting with '.' aside) as sha256Listing (core/checksum.h)
// lists them.
Expected<std::string> captureDigest(const std::filesystem::path& folder);

// One dataset's numbers. Difficulty measures (docs/suite.md): Table 6.7's five columns over the
// render window (percent) and the camera's motion over the same frames (Tables 6.4-6.6: position
// in scene units and rotation, yaw and pitch in degrees per frame, cuts left out; cuts counted).
// Method errors: "flip" (mean ꟻLIP), "warped_error_change" and "flip_over_none" (the method's
// ꟻLIP minus `none`'s on the same frames: what history costs or gains).
struct DatasetResult {
  std::string name;
  std::map<std::string, double> measures;
  std::map<std::string, std::map<std::string, double>> errors;  // method -> error name -> value
};

// The rank correlation of one measure with one method's error over the suite's datasets.
struct ValidityCell {
  std::string measure, method, error;
  metrics::RankCorrelation correlation;
  int datasets = 0;
};

// The error each method is ranked by: flip_over_none, or flip for `none` itself.
std::string rankingError(const std::string& method);
// Every (measure, method, error) cell, over the datasets' numbers.
std::vector<ValidityCell> validity(const std::vector<DatasetResult>& datasets);

// What one run of `suite` does: all of it, or one part of `suite --slurm`'s chain (each part reuses
// what the parts before it made), as the demo's parts.
enum class SuitePart {
  kAll,         // every dataset end to end, then suite.json and suite.md
  kDatasets,    // capture, convert and fly-through of every dataset only
  kRenderTask,  // only task renderTask's frame renders (framesPerTask a task)
};
struct SuiteOptions {
  std::filesystem::path manifest, output;
  int threads = 0;  // render threads (0: all cores)
  SuitePart part = SuitePart::kAll;
  int renderTask = 0, framesPerTask = 8;  // with kRenderTask
};
// The most frame renders a suite makes (every dataset's reference and input window): what
// `suite --slurm` divides among its render tasks.
int suiteFrameRenders(const Manifest& manifest);
struct SuiteOutcome {
  std::filesystem::path json, markdown;
  std::vector<DatasetResult> datasets;
  std::vector<ValidityCell> validity;
};
// Runs (or resumes) the suite into DIR: DIR/captures, DIR/runs/NAME, DIR/suite.json, DIR/suite.md
// and DIR/plots. A capture is reused when it was made with the same options, a converted dataset
// and a fly-through when newer than their sources, rendered frames when complete with the same
// settings.
Expected<SuiteOutcome> runSuite(const SuiteOptions& options, const pipeline::RunLog& log);

// `suite --slurm`: the chain of three jobs (cluster/slurm.h's chainOfJobs) in DIR/slurm: every
// dataset's capture, convert and fly-through; an array of render tasks (slurm.framesPerTask frame
// renders each); and the whole suite again, which reuses both and writes suite.json. Waits for
// suite.json unless slurm.submitOnly.
Expected<cluster::ChainOutcome> runSuiteOnSlurm(const SuiteOptions& options, const cluster::Options& slurm,
                                                        const std::function<void(const cluster::ChainStatus&)>& progress = {});

struct VerifyOutcome {
  std::size_t files = 0, numbers = 0;    // checked
  std::vector<std::string> differences;  // one line each: what differs, recorded and found
};
// Recomputes every number of DIR/suite.json from the files it lists (their SHA-256, discard and
// evaluate on the recorded frames, the camera measures from the datasets, the validity table).
Expected<VerifyOutcome> verifySuite(const std::filesystem::path& dir, const pipeline::RunLog& log);

}  // namespace dynbench::suite
