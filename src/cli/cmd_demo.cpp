// `dynbench demo [-o DIR]`: the whole chain on a seeded Cube 2 match (src/suite/demo.h).
#include "capture/cube2.h"
#include "capture/openarena.h"
#include "cli/commands.h"
#include "core/progress.h"
#include "suite/demo.h"
#include "pipeline/cluster_jobs.h"

namespace dynbench::cli {
namespace {

struct DemoCli {
  demo::DemoOptions options;
  std::string resolution = fmt::format("{}x{}", demo::DemoOptions{}.width, demo::DemoOptions{}.height);
  std::string part = "all";
  std::string gameCpu{capture::gameCpuName(demo::DemoOptions{}.gameCpu)};  // parsed by capture::parseGameCpu, the names' one home
  bool slurm = false;
  cluster::Options slurmOptions;
  std::filesystem::path jobFile;          // --job: the options from a file (suite/demo.h)
  std::vector<std::string> givenWithJob;  // options given beside --job (an error)
  bool threadsGiven = false;
};

// demo --slurm: the chain of jobs (cluster/slurm.h), waited for with progress.
Expected<void> demoOnSlurm(const demo::DemoOptions& o, cluster::Options slurm) {
  slurm.framesPerTask = o.framesPerTask;
  std::optional<Progress> progress;
  const bool terminal = Progress("slurm demo", 3, "jobs").enabled();
  std::string last;
  auto outcome = demo::demoChain(o, slurm, [&](const cluster::ChainStatus& s) {
    const std::string line = fmt::format("datasets {}, render tasks {} pending, {} running, {} done, report {}", s.datasets, s.render.pending,
                                         s.render.running, s.render.done, s.report);
    if (terminal) {
      if (!progress) progress.emplace("slurm demo", 3, "jobs");
      progress->update(static_cast<std::size_t>((s.datasets == "done") + (s.render.pending + s.render.running == 0 && s.datasets == "done") +
                                                (s.report == "done")),
                       line);
    } else if (line != last) {
      fmt::print("{}\n", line);  // in a log: each change once
      std::fflush(stdout);
    }
    last = line;
  });
  progress.reset();
  if (!outcome) return std::unexpected(outcome.error());
  fmt::print("Slurm jobs: datasets {} ({}), render {} ({} tasks, {}), report {} ({})\n", outcome->datasetsJob, outcome->datasetsScript.string(),
             outcome->renderJob, outcome->renderTasks, outcome->renderScript.string(), outcome->reportJob, outcome->reportScript.string());
  if (!outcome->waited) return {};
  if (!outcome->failure.empty())
    return fail(ErrorCode::kIncomplete, "demo --slurm: {}. Rerun `dynbench demo ... --slurm`: every part reuses what is complete", outcome->failure);
  fmt::print("report: {}\n", outcome->report.string());
  return {};
}

Expected<void> runDemoCommand(const DemoCli& cli) {
  demo::DemoOptions o = cli.options;
  if (!cli.jobFile.empty()) {
    if (auto ok = nothingBesideJob(cli.jobFile, cli.givenWithJob, "--part, --render-task, --frames-per-task, --threads"); !ok) return ok;
    auto job = demo::readDemoJob(cli.jobFile);
    if (!job) return std::unexpected(job.error());
    job->renderTask = o.renderTask;
    job->framesPerTask = o.framesPerTask;
    if (cli.threadsGiven) job->threads = o.threads;
    o = *job;
  } else {
    auto res = parseResolution(cli.resolution);
    if (!res) return std::unexpected(res.error());
    std::tie(o.width, o.height) = *res;
    auto cpu = capture::parseGameCpu(cli.gameCpu);
    if (!cpu) return std::unexpected(cpu.error());
    o.gameCpu = *cpu;
  }
  o.part = cli.part == "datasets" ? demo::DemoPart::kDatasets : cli.part == "render" ? demo::DemoPart::kRenderTask : demo::DemoPart::kAll;
  if (cli.slurm) {
    if (o.part != demo::DemoPart::kAll) return fail(ErrorCode::kUsage, "--part: not with --slurm (the jobs it submits run the parts)");
    return demoOnSlurm(o, cli.slurmOptions);
  }
  auto report = demo::runDemo(o, [](const std::string& line) {
    fmt::print("{}\n", line);
    std::fflush(stdout);
  });
  if (!report) return std::unexpected(report.error());
  if (o.part == demo::DemoPart::kAll) fmt::print("report: {}\n", report->string());
  return {};
}

}  // namespace

void addDemoCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<DemoCli>();
  auto* cmd = app.add_subcommand("demo", "The whole chain on a seeded bot match (Cube 2 or OpenArena): capture, convert, stats, render, discard, report");
  cmd->footer("Also makes a smooth fly-through over the same match as a second dataset, so the report shows the contrast.\n"
              "A rerun reuses the capture when --engine, --map, --bots, --seconds, --seed and --game-cpu are the same, and the frames already rendered.\n"
              "Example: dynbench demo -o demo --seconds 20");
  cmd->add_option("-o,--output", o->options.output, "Output folder");
  cmd->add_option("--engine", o->options.engine, "The game captured: cube2 (Cube 2: Sauerbraten) or openarena (OpenArena, id Tech 3)")
      ->check(CLI::IsMember({"cube2", "openarena"}))->capture_default_str();
  cmd->add_option("--map", o->options.map, "Map (empty: colos for cube2, oa_dm1 for openarena)");
  cmd->add_option("--bots", o->options.bots, "Bots (cube2: 1-32, openarena: 1-16)")->check(between(capture::kBotsRange.first, capture::kBotsRange.second));
  cmd->add_option("--seconds", o->options.seconds, "Game seconds captured")->check(positive());
  cmd->add_option("--seed", o->options.seed, "Seed");
  cmd->add_option("--game-cpu", o->gameCpu,
                  "openarena: emulated (under qemu-x86_64, the same match on every host) or host (faster; the match follows the CPU's "
                  "vendor): capture openarena --game-cpu")
      ->capture_default_str();
  cmd->add_option("--fps", o->options.fps, "Sampling rate of stats, render and discard")->check(positive());
  cmd->add_option("--res", o->resolution, "Render resolution");
  cmd->add_option("--spp", o->options.samplesPerPixel, "Samples per pixel of the first round (render --converge)")->check(positive());
  cmd->add_option("--tolerance", o->options.tolerance, "Convergence tolerance (render --tolerance)")->check(CLI::Range(1e-4, 10.0));
  cmd->add_option("--max-spp", o->options.maxSamplesPerPixel, "Samples per pixel at most (render --max-spp)")->check(positive());
  cmd->add_option("--render-frames", o->options.renderFrames, "Consecutive frames rendered, around the middle of each dataset")
      ->check(between(2, 1000000));
  cmd->add_option("--bounces", o->options.bounces, "Bounces")->check(nonNegative());
  cmd->add_option("--input-spp", o->options.inputSamplesPerPixel, "Samples per pixel of the temporal methods' input (evaluate)")
      ->check(positive());
  cmd->add_option("--methods", o->options.methods, "Temporal methods evaluated on each dataset (evaluate --methods)")->delimiter(',');
  cmd->add_option("--threads", o->options.threads, "Render threads (0: all cores)")->check(nonNegative());
  cmd->add_option("--frames-per-task", o->options.framesPerTask, "Frame renders per render task (with --slurm, or --part render)")
      ->check(positive())->capture_default_str();
  cmd->add_option("--part", o->part, "Run one part of the chain, as `demo --slurm`'s jobs do: datasets (capture, convert, fly-through) "
                                     "or render (task --render-task's frame renders); all: everything")
      ->check(CLI::IsMember({"all", "datasets", "render"}));
  cmd->add_option("--render-task", o->options.renderTask, "With --part render: which task's frame renders")->check(nonNegative());
  addSlurmOptions(cmd, o->slurm, o->slurmOptions,
                  "OUT/slurm: datasets, then an array of render tasks of --frames-per-task frame renders, then the report, chained with afterok",
                  false);
  cmd->add_option("--job", o->jobFile,
                  "The demo's options from a JSON file (docs/cli.md, \"Job files\"; what demo --slurm's jobs run) instead of the "
                  "options above; --part, --render-task, --frames-per-task and --threads may still be given")
      ->check(CLI::ExistingFile);
  cmd->callback([o, cmd, &run] {
    o->threadsGiven = cmd->count("--threads") > 0;
    if (!o->jobFile.empty()) o->givenWithJob = optionsGivenBesideJob(cmd, {"--part", "--render-task", "--frames-per-task", "--threads"});
    run = [o] { return runDemoCommand(*o); };
  });
}

}  // namespace dynbench::cli
