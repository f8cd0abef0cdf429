#pragma once
// `dynbench demo`: the whole chain on a seeded Cube 2 bot match. Capture, convert, a smooth
// fly-through of the same match as a second dataset (the contrast the thesis found against
// the ORCA fly-throughs), then per dataset stats, render, discard, and one report.
#include <filesystem>
#include <functional>
#include <algorithm>
#include <string>
#include <vector>

#include "capture/openarena.h"
#include "core/error.h"
#include "pipeline/dataset_run.h"
#include "cluster/slurm.h"

namespace dynbench::demo {

// What one run of the demo does: all of it, or one part of `demo --slurm`'s chain (each part reuses
// what the parts before it made).
enum class DemoPart {
  kAll,         // capture, convert, fly-through, then stats, render, discard, evaluate and report
  kDatasets,    // capture, convert and fly-through only
  kRenderTask,  // only task renderTask's frames of the renders (framesPerTask frame renders a task)
};

// The demo's datasets are measured with DatasetRunSettings' defaults: converged feature buffers
// (render --converge, 16-128 spp) of 24 frames in the middle of the match at 96x54, which two
// cores render in about 30 s a dataset (fewer pixels rather than less convergence, so Table 6.7
// describes the match, not the noise), and the methods' 4-spp input.
struct DemoOptions : pipeline::DatasetRunSettings {
  std::filesystem::path output = "dynbench-demo";
  std::string engine = "cube2";  // or "openarena"
  std::string map;               // empty: the engine's default (colos, oa_dm1)
  int bots = 6;
  double seconds = 10.0;  // game time captured
  capture::GameCpu gameCpu = capture::GameCpu::kEmulated;  // openarena: the CPU the game runs on
  DemoPart part = DemoPart::kAll;
  int renderTask = 0, framesPerTask = 8;  // with kRenderTask
};

// The number of frame renders the demo makes (two datasets, reference and input, renderFrames
// each at most): what `demo --slurm` divides among its render tasks.
inline int demoFrameRenders(const DemoOptions& o) { return 2 * pipeline::datasetFrameRenders(o); }

// The map the demo plays: --map, or the engine's default (colos for Cube 2, oa_dm1 for OpenArena).
std::string demoMap(const DemoOptions& options);

// One line per stage (for the terminal and logs).
using DemoLog = std::function<void(const std::string&)>;

// Returns the report's path (kAll), the fly-through dataset (kDatasets) or the output folder.
Expected<std::filesystem::path> runDemo(const DemoOptions& options, const DemoLog& log);

// ---- the demo as a job file (docs/cli.md, "Job files") ----------------------------------------------
// The demo's options but its part as one JSON document: what `demo --job FILE` reads and each of
// `demo --slurm`'s jobs runs (OUT/slurm/demo-job.json), so the options are spelled once.
inline constexpr int kDemoJobVersion = 1;  // the document's "dynbench_demo"
nlohmann::json demoJobJson(const DemoOptions& options);
// Keys left out take DemoOptions' defaults; an unknown key, a wrong type or a value out of range is
// an error naming `source` and the JSON pointer.
Expected<DemoOptions> parseDemoJob(const nlohmann::json& document, const std::filesystem::path& source);
Expected<DemoOptions> readDemoJob(const std::filesystem::path& path);

// ---- the demo as a chain of Slurm jobs (cluster/slurm.h's chainOfJobs) ---------------------------
// `demo --slurm`: three jobs in OUT/slurm, each the demo itself: datasets.sbatch (capture, convert,
// fly-through), render.sbatch (an array: the frame renders, options.framesPerTask a task) after it,
// and report.sbatch (the whole demo, reusing everything, so only stats, discard, evaluate and the
// report are left) after the renders, chained with --dependency=afterok and
// --kill-on-invalid-dep=yes. Waits for the report unless submitOnly.
Expected<cluster::ChainOutcome> demoChain(const DemoOptions& demo, const cluster::Options& options,
                                                  const std::function<void(const cluster::ChainStatus&)>& progress = {});

}  // namespace dynbench::demo
