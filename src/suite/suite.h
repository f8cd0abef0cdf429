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
#include "pipeline/dataset_run.h"
#include "suite/manifest.h"
#include "suite/validity.h"
#include "cluster/slurm.h"

namespace dynbench::suite {

// "dynbench_suite_results" in suite.json (2: flip_ratio_to_none, the ranking error; 3: each method on
// its own input, the reference's noise floor, the within-match comparisons)
inline constexpr int kResultsVersion = 3;

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
  // With kAll: the datasets to make (names; empty: every one), folders or files of records made
  // elsewhere to take in (suite/record.h), and whether to make nothing: suite.json and suite.md from
  // the records alone (an error naming the datasets without one).
  std::vector<std::string> only;
  std::vector<std::filesystem::path> records;
  bool assembleOnly = false;
};
// The most frame renders a suite makes (every dataset's reference and input window): what
// `suite --slurm` divides among its render tasks.
int suiteFrameRenders(const Manifest& manifest);
struct SuiteOutcome {
  std::filesystem::path json, markdown;  // empty until every dataset has a record
  std::size_t recordsMade = 0, recordsReused = 0;
  std::vector<std::string> missing;  // datasets without a record
  std::vector<DatasetResult> datasets;
  std::vector<ValidityCell> validity;
};
// Runs (or resumes) the suite into DIR: DIR/captures, DIR/runs/NAME, DIR/records/NAME.json (each as
// soon as its dataset is finished), then DIR/suite.json, DIR/suite.md and DIR/plots assembled from
// the records once every dataset has one. A dataset with a matching record is done and not made
// again; otherwise a capture is reused when it was made with the same options, a converted dataset
// and a fly-through when newer than their sources, rendered frames when complete with the same
// settings. One run at a time in DIR (a lock; render tasks aside).
Expected<SuiteOutcome> runSuite(const SuiteOptions& options, const pipeline::RunLog& log);

// A finished suite's records (DIR/records, one for every dataset of the manifest they carry) copied
// to `to`/records, and suite.json, suite.md and plots assembled there from them alone: what a
// versioned suite's published results are (suites/results/SUITE, docs/suite.md). Records already
// there are replaced. With `partial`, a suite still being run: the records it has so far (the next
// run, on any machine, takes them in with `suite --records`), and no tables.
Expected<SuiteOutcome> publishSuite(const std::filesystem::path& dir, const std::filesystem::path& to, bool partial, const pipeline::RunLog& log);

// The files a dataset's numbers come from, relative to DIR: the dataset's .gltf and .bin, and the
// run's reference, input and noise-floor frames with their sidecars (suite.json's /files).
std::vector<std::filesystem::path> recordedFiles(const std::filesystem::path& root, const std::filesystem::path& dataset,
                                                 const std::filesystem::path& run);

// `suite --slurm`: the chain of three jobs (cluster/slurm.h's chainOfJobs) in DIR/slurm: every
// dataset's capture, convert and fly-through; an array of render tasks (slurm.framesPerTask frame
// renders each); and the whole suite again, which reuses both and writes suite.json. Waits for
// suite.json unless slurm.submitOnly.
Expected<cluster::ChainOutcome> runSuiteOnSlurm(const SuiteOptions& options, const cluster::Options& slurm,
                                                        const std::function<void(const cluster::ChainStatus&)>& progress = {});

}  // namespace dynbench::suite
