#include "pipeline/cluster_jobs.h"

#include <algorithm>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "capture/cube2_job.h"
#include "frames/frame_io.h"
#include "render/render_job_json.h"

namespace dynbench::pipeline {
namespace {
namespace fs = std::filesystem;
using namespace cluster;

// "0:3" for frames 0..3 every frame, "0:6:2" for 0, 2, 4, 6.
std::string frameRangeArgument(const std::vector<long>& chunk, long step) {
  if (chunk.size() == 1) return std::to_string(chunk.front());
  return step == 1 ? fmt::format("{}:{}", chunk.front(), chunk.back()) : fmt::format("{}:{}:{}", chunk.front(), chunk.back(), step);
}

// Frames as ranges: "12-15, 40".
std::string framesText(const std::vector<long>& frames) {
  std::string out;
  for (std::size_t i = 0; i < frames.size();) {
    std::size_t j = i;
    while (j + 1 < frames.size() && frames[j + 1] == frames[j] + 1) ++j;
    out += (out.empty() ? "" : ", ") + (i == j ? std::to_string(frames[i]) : fmt::format("{}-{}", frames[i], frames[j]));
    i = j + 1;
  }
  return out;
}

}  // namespace

Expected<RenderArrayOutcome> renderArray(const RenderStage& stageIn, const Options& options, const RenderArrayProgress& progress) {
  if (auto ok = checkCluster(options); !ok) return std::unexpected(ok.error());
  // Absolute paths: the job may start in another folder, on another machine of the cluster.
  RenderStage stage = stageIn;
  stage.job.dataset = fs::absolute(stage.job.dataset).lexically_normal();
  stage.job.output = fs::absolute(stage.job.output).lexically_normal();
  auto frames = renderFrames(stage);  // also checks the dataset loads, before anything is submitted
  if (!frames) return std::unexpected(frames.error());
  if (frames->empty()) return fail(ErrorCode::kUsage, "{}: --frames selects no frame of the dataset", stage.job.dataset.string());

  RenderArrayOutcome out;
  for (std::size_t k = 0; k < frames->size(); k += static_cast<std::size_t>(options.framesPerTask))
    out.chunks.emplace_back(frames->begin() + static_cast<std::ptrdiff_t>(k),
                            frames->begin() + static_cast<std::ptrdiff_t>(std::min(frames->size(), k + options.framesPerTask)));
  out.tasks = static_cast<int>(out.chunks.size());

  const fs::path jobDir = stage.job.output / "slurm";
  std::error_code ec;
  fs::create_directories(jobDir, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create the job's folder: {}", jobDir.string(), ec.message());
  out.script = jobDir / "render.sbatch";
  // The job is the one document every task reads (render/render_job_json.h), its frames the task's chunk.
  out.jobFile = jobDir / "render-job.json";
  if (auto ok = render::writeRenderJob(stage.job, out.jobFile); !ok) return std::unexpected(ok.error());

  std::string script = scriptHeader("dynbench-render", out.tasks, jobDir, options);
  script += fmt::format(
      "#\n"
      "# dynbench render as a Slurm job array, written by `dynbench render --slurm` (docs/cluster.md).\n"
      "# Task k renders chunk k below with the same settings and seed as a local render; frames already\n"
      "# complete are skipped, so a requeued or resubmitted task resumes from its last complete frame.\n"
      "# Submit it all again: sbatch {0}\n"
      "# Only some tasks:     sbatch --array=3,5 {0}\n"
      "set -u\n",
      shellQuote(out.script.string()));
  script += "chunks=(";
  for (const auto& c : out.chunks) {
    if (&c != &out.chunks.front()) script += ' ';
    script += frameRangeArgument(c, stage.job.frames.step);
  }
  script += ")\n";
  script += "frames=${chunks[$SLURM_ARRAY_TASK_ID]}\n";
  script += fmt::format("output={}\n", shellQuote(stage.job.output.string()));
  // The render's unfinished files are NAME.tmp-PID (finished ones are renamed into place).
  script += signalTrap("frames $frames", "rm -f \"$output\"/*.tmp-\"$child\"");
  script += jobCommand(options, "render", {"--job", out.jobFile.string()}) + " --frames \"$frames\" --threads \"${SLURM_CPUS_PER_TASK:-1}\" &\n";
  script += "child=$!\nwait \"$child\"\n";
  if (auto ok = writeScript(out.script, script); !ok) return std::unexpected(ok.error());

  auto id = submit(out.script);
  if (!id) return std::unexpected(id.error());
  out.jobId = *id;
  if (options.submitOnly) return out;

  // Wait: frames complete from the files, tasks from squeue, until no task is queued any more.
  const auto record = render::renderRecord(stage.job);
  std::vector<bool> done(frames->size(), false);
  auto countComplete = [&] {
    std::size_t n = 0;
    for (std::size_t i = 0; i < frames->size(); ++i) {
      if (!done[i]) done[i] = frames::frameComplete(stage.job.output, (*frames)[i], record);
      n += done[i];
    }
    return n;
  };
  // Task k's frames are items k*F .. of the frame list, as the chunks were cut.
  auto chunkFirst = [&](int task) { return static_cast<std::size_t>(task) * static_cast<std::size_t>(options.framesPerTask); };
  auto chunkComplete = [&](int task) {
    const std::size_t first = chunkFirst(task);
    return std::all_of(done.begin() + static_cast<std::ptrdiff_t>(first),
                       done.begin() + static_cast<std::ptrdiff_t>(first + out.chunks[static_cast<std::size_t>(task)].size()), [](bool d) { return d; });
  };
  auto failed = waitForArray(
      out.jobId, out.tasks, chunkComplete,
      [&](const ArrayStatus& tasks) {
        RenderArrayStatus status{countComplete(), frames->size(), tasks};
        if (progress) progress(status);
      },
      options);
  if (!failed) return std::unexpected(failed.error());
  out.waited = true;
  countComplete();
  for (int k = 0; k < out.tasks; ++k) {
    const auto& chunk = out.chunks[static_cast<std::size_t>(k)];
    for (std::size_t i = 0; i < chunk.size(); ++i)
      if (!done[chunkFirst(k) + i]) out.missing[k].push_back(chunk[i]);
  }
  if (!out.missing.empty()) {
    const auto states = taskStates(out.jobId);
    std::vector<int> tasks;
    for (const auto& [task, missingFrames] : out.missing) {
      tasks.push_back(task);
      if (auto s = states.find(task); s != states.end()) out.taskStates[task] = s->second;
    }
    out.resubmit = resubmitCommand(tasks, out.script);
  }
  return out;
}

std::string missingFramesText(const RenderArrayOutcome& outcome) {
  std::string text;
  for (const auto& [task, frames] : outcome.missing) {
    const auto state = outcome.taskStates.find(task);
    text += fmt::format("  task {}{}: frames {}\n", task, state != outcome.taskStates.end() ? " (" + state->second + ")" : "", framesText(frames));
  }
  return text;
}

Expected<CaptureArrayOutcome> captureArray(const capture::Cube2Options& captureIn, unsigned firstSeed, unsigned lastSeed, const Options& options,
                                           const CaptureArrayProgress& progress) {
  if (lastSeed < firstSeed) return fail(ErrorCode::kUsage, "--seeds {}:{}: the last seed is before the first", firstSeed, lastSeed);
  if (captureIn.window) return fail(ErrorCode::kUsage, "--window: a cluster's nodes have no display; capture there under Xvfb (the default)");
  if (auto ok = checkCluster(options); !ok) return std::unexpected(ok.error());
  capture::Cube2Options capture = captureIn;
  const fs::path dir = fs::absolute(capture.output).lexically_normal();
  CaptureArrayOutcome out;
  for (unsigned long long seed = firstSeed; seed <= lastSeed; ++seed) {
    out.seeds.push_back(static_cast<unsigned>(seed));
    out.captures.push_back(dir / fmt::format("seed_{}", seed));
  }
  const int tasks = static_cast<int>(out.seeds.size());
  const fs::path jobDir = dir / "slurm";
  std::error_code ec;
  fs::create_directories(jobDir, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create the job's folder: {}", jobDir.string(), ec.message());
  out.script = jobDir / "capture.sbatch";
  // The options every task reads (capture/cube2_job.h), with absolute paths: a task may start in
  // another folder, on another machine; its output and seed are the task's.
  capture.data = fs::absolute(capture.data);
  if (!capture.client.empty()) capture.client = fs::absolute(capture.client);
  capture.output.clear();
  out.jobFile = jobDir / "capture-job.json";
  if (auto ok = capture::writeCube2Job(capture, out.jobFile); !ok) return std::unexpected(ok.error());
  std::string script = scriptHeader("dynbench-capture", tasks, jobDir, options);
  script += fmt::format(
      "#\n"
      "# dynbench capture cube2 as a Slurm job array, written by `dynbench capture cube2 --slurm` (docs/cluster.md).\n"
      "# Task k captures seed k of the list below into seed_N, through seed_N.partial, renamed when complete.\n"
      "# Submit it all again: sbatch {0}\n"
      "# Only some tasks:     sbatch --array=3,5 {0}\n"
      "set -u\n",
      shellQuote(out.script.string()));
  script += fmt::format("seeds=({})\n", fmt::join(out.seeds, " "));
  script += "seed=${seeds[$SLURM_ARRAY_TASK_ID]}\n";
  script += fmt::format("final={}/seed_$seed\npartial=$final.partial\n", shellQuote(dir.string()));
  script += "if [[ -f $final/Capture.txt ]]; then echo \"dynbench: $final already holds a capture\"; exit 0; fi\n";
  script += "rm -rf \"$partial\"\n";
  script += signalTrap("the capture of seed $seed", "rm -rf \"$partial\"");
  script += jobCommand(options, "capture cube2", {"--job", out.jobFile.string()}) + " -o \"$partial\" --seed \"$seed\" &\n";
  script += "child=$!\nwait \"$child\" || exit $?\n";
  script += "mv \"$partial\" \"$final\"\n";
  if (auto ok = writeScript(out.script, script); !ok) return std::unexpected(ok.error());
  auto id = submit(out.script);
  if (!id) return std::unexpected(id.error());
  out.jobId = *id;
  if (options.submitOnly) return out;
  auto failed = waitForArray(
      out.jobId, tasks, [&](int k) { return fs::is_regular_file(out.captures[static_cast<std::size_t>(k)] / "Capture.txt"); }, progress, options);
  if (!failed) return std::unexpected(failed.error());
  out.waited = true;
  out.failed = *failed;
  if (!out.failed.empty()) out.resubmit = resubmitCommand(out.failed, out.script);
  return out;
}

}  // namespace dynbench::pipeline
