#pragma once
// One dataset measured end to end, as the demo and the suite do it: stats (Tables 6.1-6.6), a
// converged reference render of a window of frames, discard (Table 6.7), the same window rendered
// as a real-time renderer's input, and evaluate (the temporal methods against the reference). The
// files are those the commands write, in one RUN folder (docs/cli.md, `demo`).
#include <filesystem>
#include <algorithm>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "capture/cube2.h"
#include "capture/openarena.h"
#include "core/error.h"
#include "core/json_fields.h"
#include "core/rates.h"
#include "discard/discard.h"
#include "evaluate/evaluate.h"
#include "metrics/camera_motion.h"
#include "camera/flythrough.h"
#include "pipeline/stages.h"

namespace dynbench::pipeline {

// Frames of a dataset's window rendered again with another seed for the reference's noise floor:
// the demo's and a suite manifest's default (/render/floor_frames).
inline constexpr int kDefaultFloorFrames = 4;

struct DatasetRunSettings {
  double fps = kDefaultFrameRate;  // stats, render and discard sample the dataset at this rate
  // Converged feature buffers (render --converge) of a window of renderFrames consecutive frames
  // in the middle of the dataset: fewer pixels rather than less convergence, so Table 6.7
  // describes the dataset, not the noise. The defaults are the demo's budget (issue 47: the
  // README's main job in 10 minutes on a fresh 2-core machine): 24 frames at 16-128 spp render a
  // dataset's window in 30 s where 48 at 16-512 took 217 s, and Table 6.7's radiance intervals
  // are no wider (the demo's bot: direct ± 1.23 against ± 1.41, indirect ± 4.50 against ± 5.14;
  // they come from the pairs left undecided, not from the image's samples).
  int width = 96, height = 54, samplesPerPixel = 16, bounces = 2;
  double tolerance = 0.5;
  int maxSamplesPerPixel = 128;
  // Radiance-change pairs per pixel at most (render --max-pairs): the demo's and suite's budget.
  // Pixels still undecided there bound the radiance columns both ways and are counted (a † above
  // 0.5 %); 1,024, render's default, cost the demo about 14 minutes more on two cores.
  int maxPairs = 64;
  int renderFrames = 24;
  // The temporal methods' input: the window again at this many samples per pixel, scored against
  // the converged frames.
  int inputSamplesPerPixel = 4;
  std::vector<std::string> methods = evaluate::builtInMethodNames();
  // The input each method gets (evaluate::kJitteredInput or kStillInput) where it is not its own:
  // a method not named here gets the input it is built for (evaluate::builtForInput; methodInput
  // below), in the demo as in every suite. With any "still", the window is also rendered
  // unjittered (RUN/input-still) and `none` is scored on both inputs, so each method's ratio to
  // `none` is on its own input.
  std::map<std::string, std::string> methodInputs;
  // The reference's noise floor (evaluate::referenceNoiseFloor): this many frames of the window,
  // evenly spaced, rendered again as the reference is but with seed + 2 (0: none), and written to
  // RUN/floor.json.
  int floorFrames = kDefaultFloorFrames;
  unsigned seed = 1;  // the reference's; the input's is seed + 1, the floor's seed + 2
  int threads = 0;    // render threads (0: all cores)
};

// The settings' JSON spelling, shared by a suite manifest's "render" object and the demo's job file
// (docs/suite.md, docs/cli.md "Job files"): width, height, frames, spp, max_spp, bounces, input_spp,
// tolerance, fps; and, with `all`, max_pairs, methods, seed and threads, which a manifest does not hold.
nlohmann::json datasetRunSettingsJson(const DatasetRunSettings& settings, bool all);
// Reads those keys under `prefix` ("/render" or ""), each optional, into `settings`; the values'
// ranges are checked, and max_spp against spp.
Expected<void> readDatasetRunSettings(const JsonSettingsReader& reader, const std::string& prefix, DatasetRunSettings& settings, bool all);
// The keys readDatasetRunSettings knows (for a job file's unknown-key check).
const std::vector<const char*>& datasetRunSettingsKeys(bool all);

// One line per stage (for the terminal and logs).
using RunLog = std::function<void(const std::string&)>;

// ---- a match's datasets (demo and suite) ------------------------------------------------------
// A Cube 2 or OpenArena capture into options.output and the dataset converted from it, each made
// only when stale: the capture unless `record` (a file) holds its match options and the adapter
// version, the dataset unless it is newer than the capture. Anything made after a capture follows
// from it.
Expected<void> captureAndConvert(const capture::Cube2Options& options, const std::filesystem::path& record, const std::filesystem::path& dataset,
                                 const RunLog& log);
Expected<void> captureAndConvert(const capture::OpenArenaOptions& options, const std::filesystem::path& record,
                                 const std::filesystem::path& dataset, const RunLog& log);
// The fly-through of `bot` as the dataset `fly` (its pose log `csv`), made unless `fly` is newer
// than `bot`.
Expected<void> flyThroughUnlessNewer(const std::filesystem::path& bot, const std::filesystem::path& fly, const std::filesystem::path& csv,
                                     const camera::FlythroughOptions& options, const RunLog& log);

// The renders of a dataset: converged reference frames (RUN/frames) and the temporal methods'
// input (RUN/input), of the same window of frames around the middle of the dataset, and with
// floorFrames > 0 the reference again with another seed (RUN/floor) on a few of its frames.
struct DatasetRenders {
  RenderStage reference, input;
  std::optional<RenderStage> stillInput;  // the input unjittered, when a method asks for it
  std::optional<RenderStage> floor;
};
DatasetRenders datasetRenders(const std::filesystem::path& dataset, const std::filesystem::path& run, const DatasetRunSettings& settings,
                              long animationFrames);

// The most frame renders one dataset needs (a window shorter than the dataset's animation needs
// fewer): the reference and input windows and the floor's frames. What --slurm divides among tasks.
// The input `method` gets: settings.methodInputs' entry, or the one it is built for.
std::string methodInput(const DatasetRunSettings& settings, const std::string& method);
bool needsStillInput(const DatasetRunSettings& settings);
inline int datasetFrameRenders(const DatasetRunSettings& s) {
  const int window = std::max(2, s.renderFrames);
  return (needsStillInput(s) ? 3 : 2) * window + std::min(window, s.floorFrames);
}

// The dataset's stats at settings.fps; with `files`, RUN/stats.json and the camera series too.
Expected<StatsOutcome> measureStats(const std::filesystem::path& dataset, const std::filesystem::path& run, const DatasetRunSettings& settings,
                                    bool files);

// The methods scored on each input: `jittered` on RUN/input (with `none`), `still` on
// RUN/input-still (with its own `none`; empty when no method asked for it).
struct MethodsOnTheirInputs {
  std::vector<evaluate::MethodScores> jittered, still;
};
// Each of settings.methods evaluated on its input (settings.methodInputs) against RUN/frames, with
// `none` on every input used; `extra` are scored on the jittered input beside them, `extraStill` on
// the still one. With `writeFiles`, RUN/evaluate.json, .csv and evaluate/ (and evaluate-still.*) as
// the demo writes them.
Expected<MethodsOnTheirInputs> evaluateOnTheirInputs(const std::filesystem::path& run, const DatasetRunSettings& settings,
                                                     const std::vector<std::shared_ptr<evaluate::TemporalMethod>>& extra, bool writeFiles,
                                                     const std::vector<std::shared_ptr<evaluate::TemporalMethod>>& extraStill = {});

struct DatasetRunOutcome {
  metrics::CameraMotion motion;   // Tables 6.4-6.6 (every frame of the dataset at settings.fps)
  long firstFrame = 0, lastFrame = 0;  // the rendered window
  discard::FramePercentages discard;  // Table 6.7 (the window's mean)
  MethodsOnTheirInputs methods;
  std::optional<evaluate::MeanWithError> referenceFloor;  // with floorFrames > 0
  std::size_t framesRendered = 0;  // frame renders this call made (reference, inputs, floor); 0: all were complete
};
// stats, render, discard, input render and evaluate of one dataset into RUN; renders already
// complete with the same settings are reused.
Expected<DatasetRunOutcome> measureDataset(const std::filesystem::path& dataset, const std::filesystem::path& run, const DatasetRunSettings& settings,
                                           const RunLog& log);

// One dataset of a render array: where it is, its RUN folder, and its settings.
struct DatasetJob {
  std::filesystem::path dataset, run;
  DatasetRunSettings settings;
};
// One task of a render array over several datasets (demo --slurm, suite --slurm): item i of the
// datasets' frame renders (dataset by dataset, reference before input, frame by frame), and task
// `task` renders items task*perTask .. task*perTask+perTask-1, grouped by render into frame
// ranges. Frames already complete are kept. `what` names the command in the log.
Expected<void> renderTask(const std::vector<DatasetJob>& datasets, int task, int perTask, const std::string& what, const RunLog& log);

}  // namespace dynbench::pipeline
