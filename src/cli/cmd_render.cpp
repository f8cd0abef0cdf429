// `dynbench render DATASET -o DIR`: path-traced feature buffers for every frame
// (docs/feature-buffers.md), with dynbench's Embree path tracer or Blender Cycles.
#include <optional>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "frames/radiance_change.h"
#include "core/progress.h"
#include "render/backend.h"
#include "render/render_job_json.h"
#include "pipeline/cluster_jobs.h"
#include "pipeline/stages.h"

namespace dynbench::cli {
namespace {

// The job's defaults are the library's (render::RenderJob, render::RenderSettings); the help text
// prints them from there.
struct RenderCli {
  render::RenderJob job;
  std::string frames;
  std::string resolution = fmt::format("{}x{}", render::RenderSettings{}.width, render::RenderSettings{}.height);
  std::optional<std::string> envConstant;
  bool noEnvironment = false;
  std::string pixelFilter = render::pixelFilterName(render::PixelFilterSpec{}.type);
  std::optional<double> pixelFilterWidth;
  std::optional<bool> pairs;  // --pairs / --no-pairs; unset: with --converge on the embree engine
  bool slurm = false;
  cluster::Options slurmOptions;
  std::filesystem::path jobFile;           // --job: the whole job from a file (render/render_job_json.h)
  std::vector<std::string> givenWithJob;   // the job options given beside --job (an error)
  bool threadsGiven = false;
};

// render --slurm: the same job as a Slurm job array (pipeline/cluster_jobs.h), waited for on a terminal
// with progress, and a non-zero exit naming what is missing when tasks failed.
Expected<void> renderOnSlurm(const render::RenderJob& job, const cluster::Options& options) {
  std::optional<Progress> progress;
  const auto started = std::chrono::steady_clock::now();
  pipeline::RenderArrayProgress report = [&](const pipeline::RenderArrayStatus& s) {
    if (!progress) progress.emplace("slurm render", s.framesTotal, "frames");
    progress->update(s.framesComplete,
                     fmt::format("tasks {} pending, {} running, {} failed", s.tasks.pending, s.tasks.running, s.tasks.failed));
  };
  auto outcome = pipeline::renderArray({job}, options, report);
  progress.reset();
  if (!outcome) return std::unexpected(outcome.error());
  fmt::print("{}: Slurm job {}, {} task(s) of at most {} frame(s), script {}\n", job.output.string(), outcome->jobId, outcome->tasks,
             options.framesPerTask, outcome->script.string());
  if (!outcome->waited) return {};
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!outcome->missing.empty()) {
    std::size_t missing = 0;
    for (const auto& [task, frames] : outcome->missing) missing += frames.size();
    return fail(ErrorCode::kIncomplete, "Slurm job {} ended with {} frame(s) missing:\n{}Rerun only those tasks: {}", outcome->jobId, missing,
                pipeline::missingFramesText(*outcome), outcome->resubmit);
  }
  std::size_t frames = 0;
  for (const auto& c : outcome->chunks) frames += c.size();
  fmt::print("{}: all {} frame(s) complete in {:.1f} s\n", job.output.string(), frames, seconds);
  return {};
}

Expected<void> renderJob(const render::RenderJob& job);

// The job of `render --job FILE [--frames A:B] [--threads N]`: the file's, with this run's frames and
// threads. The frames are a part of the file's (a Slurm task's chunk): the scene is stepped from the
// file's first frame, so that they are the whole job's bytes (RenderJob::stepFrom).
Expected<render::RenderJob> jobFromFile(const RenderCli& cli) {
  if (auto ok = nothingBesideJob(cli.jobFile, cli.givenWithJob, "--frames, --threads"); !ok) return std::unexpected(ok.error());
  auto job = render::readRenderJob(cli.jobFile);
  if (!job) return std::unexpected(job.error());
  if (!cli.frames.empty()) {
    auto range = render::parseFrameRange(cli.frames);
    if (!range) return std::unexpected(range.error());
    job->stepFrom = job->frames.first;
    job->frames = *range;
  }
  if (cli.threadsGiven) job->threads = cli.job.threads;
  return job;
}

Expected<void> runRenderCommand(const RenderCli& cli) {
  if (!cli.jobFile.empty()) {
    auto job = jobFromFile(cli);
    if (!job) return std::unexpected(job.error());
    return cli.slurm ? renderOnSlurm(*job, cli.slurmOptions) : renderJob(*job);
  }
  if (cli.job.dataset.empty() || cli.job.output.empty())
    return fail(ErrorCode::kUsage, "render: DATASET and -o DIR are required (or --job FILE)");
  render::RenderJob job = cli.job;
  auto res = parseResolution(cli.resolution);
  if (!res) return std::unexpected(res.error());
  job.settings.width = res->first;
  job.settings.height = res->second;
  job.settings.useEnvironment = !cli.noEnvironment;
  auto filter = render::parsePixelFilter(cli.pixelFilter);
  if (!filter) return std::unexpected(filter.error());
  job.settings.pixelFilter = {*filter, cli.pixelFilterWidth.value_or(render::defaultPixelFilterWidth(*filter))};
  if (cli.envConstant) {
    double r = 0, g = 0, b = 0;
    const int n = std::sscanf(cli.envConstant->c_str(), "%lf,%lf,%lf", &r, &g, &b);
    if (n == 1) g = b = r;
    else if (n != 3) return fail(ErrorCode::kUsage, "--env-constant '{}': expected L or R,G,B", *cli.envConstant);
    if (!(r >= 0 && g >= 0 && b >= 0)) return fail(ErrorCode::kUsage, "--env-constant '{}': radiance must be non-negative", *cli.envConstant);
    job.settings.constantEnvironment = glm::dvec3(r, g, b);
  }
  job.settings.pairs = cli.pairs.value_or(job.settings.converge && job.engine == "embree");
  if (!cli.frames.empty()) {
    auto range = render::parseFrameRange(cli.frames);
    if (!range) return std::unexpected(range.error());
    job.frames = *range;
  }
  if (cli.slurm) return renderOnSlurm(job, cli.slurmOptions);
  return renderJob(job);
}

// Renders `job` here, with progress on a terminal and a summary line.
Expected<void> renderJob(const render::RenderJob& job) {
  // Progress on a terminal only: rows (of all frames) done, frames done, samples per second.
  std::optional<Progress> progress;
  render::RenderProgress report;
  const double samplesPerRow = static_cast<double>(job.settings.samplesPerPixel) * job.settings.width;
  const auto started = std::chrono::steady_clock::now();
  if (Progress("render", 0, "rows").enabled()) {
    report = [&](std::size_t rows, std::size_t rowsTotal, std::size_t frames, std::size_t framesTotal) {
      if (!progress) progress.emplace("render", rowsTotal, "rows");
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      const double samplesPerSecond = seconds > 0 ? rows * samplesPerRow / seconds : 0.0;
      // Adaptive sampling has no fixed samples per row: frames only.
      progress->update(rows, job.settings.converge ? fmt::format("{}/{} frames", frames, framesTotal)
                                                   : fmt::format("{}/{} frames, {:.2f} M samples/s", frames, framesTotal, samplesPerSecond / 1e6));
    };
  }
  std::vector<std::string> sceneWarnings;
  auto summary = pipeline::runRender({job}, report, &sceneWarnings);
  progress.reset();
  if (!summary) return std::unexpected(summary.error());
  for (const auto& w : sceneWarnings) spdlog::warn("{}", w);
  for (const auto& w : summary->warnings) spdlog::warn("{}", w);
  fmt::print("{}: {} frame(s) rendered, {} already complete (skipped), {:.1f} s", job.output.string(), summary->rendered.size(),
             summary->skipped.size(), summary->seconds);
  if (summary->cameraSamples > 0 && summary->seconds > 0)
    fmt::print(", {:.2f} M samples/s, {:.2f} M rays/s", summary->cameraSamples / summary->seconds / 1e6, summary->rays / summary->seconds / 1e6);
  if (summary->pixels > 0)
    fmt::print(", {:.1f} spp on average", static_cast<double>(summary->cameraSamples) / static_cast<double>(summary->pixels));
  if (job.settings.converge) fmt::print(", {} pixel(s) reached --max-spp before the tolerance", summary->cappedPixels);
  if (job.settings.pairs && summary->pixels > 0)
    fmt::print(", {:.1f} radiance-change pairs per pixel on average, {} pixel(s) undecided at --max-pairs",
               summary->pairs / static_cast<double>(summary->pixels), summary->undecidedPixels);
  fmt::print("\n");
  return {};
}

}  // namespace

Expected<std::pair<int, int>> parseResolution(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w <= 0 || h <= 0 || w > 65536 ||
      h > 65536)
    return fail(ErrorCode::kUsage, "--res '{}': expected WIDTHxHEIGHT, e.g. 480x270", text);
  return std::pair{w, h};
}

void addRenderCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<RenderCli>();
  auto* cmd = app.add_subcommand("render", "Path-trace the feature buffers of every frame (P, N, direct, indirect, ...)");
  cmd->footer("Writes DIR/frame_NNNNN.exr and DIR/frame_NNNNN.json per frame (docs/feature-buffers.md). Frames already\n"
              "complete with the same settings are skipped, so an interrupted render resumes.\n"
              "Example: dynbench render dataset.gltf -o frames --frames 0:47 --spp 64");
  cmd->add_option("DATASET", o->job.dataset, "Animated dataset (glTF, GLB, FBX, DAE, ...)");
  cmd->add_option("-o,--output", o->job.output, "Output folder");
  cmd->add_option("--job", o->jobFile,
                  "The whole job from a JSON file (docs/cli.md, \"Job files\"; what a Slurm task runs) instead of DATASET, -o and the "
                  "options below; --frames and --threads may still be given")
      ->check(CLI::ExistingFile);
  cmd->add_option("--res", o->resolution, "Resolution WIDTHxHEIGHT (the thesis used 1920x1080)");
  cmd->add_option("--spp", o->job.settings.samplesPerPixel, "Samples per pixel (the thesis used 1024)")->check(positive());
  cmd->add_option("--bounces", o->job.settings.bounces, "Bounces after the first hit, as Cycles counts them (the thesis used 12)")
      ->check(nonNegative());
  cmd->add_option("--fps", o->job.fps, "Frames per second: frame i is at t = start + i / fps")->check(positive());
  cmd->add_option("--frames", o->frames, "Frames A:B[:STEP] (inclusive), A: or A (empty: every frame)");
  cmd->add_option("--camera", o->job.camera, "Camera node: index or name (default: the first animated camera)");
  cmd->add_option("--animation", o->job.animation, "Play only this animation (index or name)");
  cmd->add_option("--seed", o->job.settings.seed, "Random seed; the same seed and options give the same images");
  std::string engineHelp = "Renderer:";
  for (const auto& b : render::renderBackends()) {
    engineHelp += fmt::format(" {} ({}){}", b.name, b.description, &b == &render::renderBackends().back() ? "" : ";");
  }
  cmd->add_option("--engine", o->job.engine, engineHelp)->check(CLI::IsMember(render::backendNames()));
  cmd->add_option("--threads", o->job.threads, "Threads for loading, rendering and writing frames (0: all cores)")->check(nonNegative());
  cmd->add_option("--blender", o->job.blender, "Blender executable for --engine cycles");
  cmd->add_option("--env-constant", o->envConstant, "Light with a constant environment of radiance L or R,G,B instead of the dataset's");
  cmd->add_flag("--no-environment", o->noEnvironment, "No image-based light (black background)");
  cmd->add_flag("--jitter", o->job.settings.jitter,
                "Offset each frame's pixel samples from the centres by the 8-frame Halton (2, 3) sequence, as TAA input "
                "(recorded as camera.jitter in each sidecar; docs/feature-buffers.md)");
  cmd->add_option("--pixel-filter", o->pixelFilter,
                  "Reconstruction filter of the radiance buffers: blackman-harris (Cycles' default), box, or centre (every path from "
                  "the pixel centre's hit: radiance at a point, aliased; docs/feature-buffers.md)")
      ->capture_default_str();
  cmd->add_option("--pixel-filter-width", o->pixelFilterWidth,
                  "Filter width in pixels, as Cycles' filter_width (default: 1.5 for blackman-harris, 1 for box)")
      ->check(CLI::Range(1e-3, 8.0));
  cmd->add_flag("--converge", o->job.settings.converge,
                "Adaptive sampling: after max(--spp, 16) samples, sample each pixel in rounds until the standard error of its direct and of its "
                "indirect luminance is at most --tolerance x discard's radiance threshold (docs/feature-buffers.md), or --max-spp");
  cmd->add_option("--tolerance", o->job.settings.tolerance, "With --converge: the standard error target as a fraction of discard's threshold")
      ->check(CLI::Range(1e-4, 10.0));
  cmd->add_option("--max-spp", o->job.settings.maxSamplesPerPixel, "With --converge: samples per pixel at most")->check(positive());
  cmd->add_flag_callback("--pairs", [o] { o->pairs = true; },
                         "Radiance-change pairs for Table 6.7's radiance columns (discard's default test): each pixel's samples re-shaded "
                         "in the previous frame with the same random numbers (docs/feature-buffers.md). Default: on with --converge "
                         "(embree engine)");
  cmd->add_flag_callback("--no-pairs", [o] { o->pairs = false; }, "No radiance-change pairs, also with --converge");
  cmd->add_option("--max-pairs", o->job.settings.maxPairs,
                  "With pairs: pairs per pixel at most (from 4, doubled while the change test is undecided)")
      ->check(CLI::Range(frames::kFirstPairs, 1 << 20))
      ->capture_default_str();
  cmd->add_flag("--float32", o->job.float32,
                "Store every channel as 32-bit float (default: half where docs/feature-buffers.md allows it, about half the disk)");
  cmd->add_option("--lights-per-point", o->job.settings.lightsPerPoint,
                  "Point and spot lights evaluated per shading point at most, chosen by the light tree (unbiased; exact where no "
                  "more can reach the point; 0: every light, slow; docs/feature-buffers.md)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  cmd->add_option("--every-light-up-to", o->job.settings.everyLightUpTo,
                  "Where at most this many point and spot lights can reach a shading point, evaluate every one of them "
                  "(exact); sample --lights-per-point only where more can (0: always sample; docs/feature-buffers.md)")
      ->check(CLI::Range(0, 4096))
      ->capture_default_str();
  cmd->add_option_function<std::string>(
         "--light-selection", [o](const std::string& name) { o->job.settings.learnedLightSelection = *render::parseLightSelection(name); },
         "How the light tree picks a point's lights: learned (its importance weighted by the visibility learned from a pilot "
         "before each frame; unbiased) or tree (its importance alone, as before; for comparison). docs/feature-buffers.md")
      ->check(CLI::IsMember({"learned", "tree"}))
      ->default_str("learned");
  addSlurmOptions(cmd, o->slurm, o->slurmOptions, "DIR/slurm/render.sbatch, one task per --frames-per-task frames", true);
  cmd->callback([o, cmd, &run] {
    o->threadsGiven = cmd->count("--threads") > 0;
    if (!o->jobFile.empty()) o->givenWithJob = optionsGivenBesideJob(cmd, {"--frames", "--threads"});
    run = [o] { return runRenderCommand(*o); };
  });
}

}  // namespace dynbench::cli
