#pragma once
// Stage runners: each pipeline stage as one library function taking a typed options struct. The
// CLI commands, `demo`, `suite` and the Slurm jobs all call these, so a stage does the same thing
// however it is started. Runners write the stage's files and return what was measured; printing
// is the caller's.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rates.h"
#include "discard/discard.h"
#include "render/render_job.h"
#include "report/html_report.h"
#include "report/stats_output.h"

namespace dynbench::pipeline {

// ---- stats: Tables 6.1-6.6 -------------------------------------------------------------------
struct StatsStage {
  std::vector<std::filesystem::path> inputs;  // datasets: one row each
  double fps = kDefaultFrameRate;             // sampling rate, frames per second (the thesis's)
  double sequenceRate = kDefaultSequenceRate;  // key frames per second of an OBJ sequence
  std::optional<std::string> camera;          // index or name; default: the first animated camera
  std::optional<std::string> animation;       // index or name; default: all together on one clock
  std::filesystem::path json, csv;            // optional outputs (empty: not written)
  std::filesystem::path seriesDir, plotsDir;  // per-frame camera CSV, Figures A.1/A.2
};
struct StatsOutcome {
  std::vector<report::StatsRow> rows;
  std::string markdown;  // Tables 6.1-6.6
  std::vector<std::string> warnings;
};
// (input index, input): called before each dataset is loaded.
using StatsProgress = std::function<void(std::size_t, const std::filesystem::path&)>;
Expected<StatsOutcome> runStats(const StatsStage& stage, const StatsProgress& progress = {});

// The file name stats gives a dataset's series and plots: its label with characters other than
// letters, digits, '-', '_' and '.' replaced by '_'.
std::string fileStem(const std::string& label);

// ---- render: feature buffers --------------------------------------------------------------------
struct RenderStage {
  render::RenderJob job;  // dataset, output, settings, frames, camera, animation, backend
};
Expected<render::RenderSummary> runRender(const RenderStage& stage, const render::RenderProgress& progress = {},
                                          std::vector<std::string>* sceneWarnings = nullptr);
// The frames the stage covers (its --frames range within the dataset's animation), loading the
// dataset as runRender does.
Expected<std::vector<long>> renderFrames(const RenderStage& stage);

// ---- discard: Table 6.7 -----------------------------------------------------------------------
struct DiscardStage {
  std::filesystem::path frames;             // a frames folder (feature-buffer contract)
  discard::Thresholds thresholds;
  bool includeCuts = false;                 // camera-cut pairs in the mean (left out by default)
  std::filesystem::path json, csv;          // optional outputs
  std::filesystem::path masks, plots;       // optional: discard_NNNNN.png per frame; NAME_discard.png/.svg
};
struct DiscardOutcome {
  discard::DiscardRun run;
  std::string markdown;  // Table 6.7
};
Expected<DiscardOutcome> runDiscard(const DiscardStage& stage, const discard::DiscardProgress& progress = {});

// ---- report -----------------------------------------------------------------------------------
Expected<report::ReportFiles> runReport(const report::ReportOptions& options);

}  // namespace dynbench::pipeline
