#pragma once
// The stages as Slurm job arrays (docs/cluster.md): a render's frames and a capture's seeds split
// into array tasks, each running dynbench itself, through the cluster room's client (cluster/slurm.h).
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "capture/cube2.h"
#include "cluster/slurm.h"
#include "core/error.h"
#include "pipeline/stages.h"

namespace dynbench::pipeline {

// ---- render as an array ------------------------------------------------------------------------
struct RenderArrayStatus {
  std::size_t framesComplete = 0, framesTotal = 0;
  cluster::ArrayStatus tasks;
};
using RenderArrayProgress = std::function<void(const RenderArrayStatus&)>;

struct RenderArrayOutcome {
  std::string jobId;
  std::filesystem::path script;
  std::filesystem::path jobFile;                   // DIR/slurm/render-job.json, the job every task runs
  int tasks = 0;
  std::vector<std::vector<long>> chunks;           // task k's frames
  std::map<int, std::vector<long>> missing;        // after the wait: task -> its frames not complete
  std::map<int, std::string> taskStates;           // scontrol's final state of the tasks that missed frames
  std::string resubmit;                            // the command that reruns only those tasks
  bool waited = false;
};

// Renders `stage`'s frames as a Slurm job array: DIR/slurm/render.sbatch, one task per
// options.framesPerTask frames, each `dynbench render --job DIR/slurm/render-job.json` of its chunk
// (frames are the same bytes as a local render: the seed is per frame). Waits unless submitOnly.
Expected<RenderArrayOutcome> renderArray(const RenderStage& stage, const cluster::Options& options, const RenderArrayProgress& progress = {});

// The missing frames by task, one line each: "  task 3 (CANCELLED): frames 12-15".
std::string missingFramesText(const RenderArrayOutcome& outcome);

// ---- capture as an array -----------------------------------------------------------------------
struct CaptureArrayOutcome {
  std::string jobId;
  std::filesystem::path script;
  std::filesystem::path jobFile;             // DIR/slurm/capture-job.json, the options every task runs
  std::vector<unsigned> seeds;               // task k captures seeds[k] into DIR/seed_N
  std::vector<std::filesystem::path> captures;
  std::vector<int> failed;                   // tasks whose capture is missing after the wait
  std::string resubmit;
  bool waited = false;
};
using CaptureArrayProgress = std::function<void(const cluster::ArrayStatus&)>;
// One Cube 2 capture per seed, firstSeed..lastSeed, as a Slurm job array: DIR/slurm/capture.sbatch,
// task k capturing seed firstSeed + k into DIR/seed_N (through DIR/seed_N.partial, renamed when
// complete, so a folder under its final name is a whole capture). Waits unless submitOnly.
Expected<CaptureArrayOutcome> captureArray(const capture::Cube2Options& capture, unsigned firstSeed, unsigned lastSeed, const cluster::Options& options,
                                           const CaptureArrayProgress& progress = {});

}  // namespace dynbench::pipeline
