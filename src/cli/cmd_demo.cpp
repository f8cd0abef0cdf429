// `dynbench demo [-o DIR]`: the whole chain on a seeded Cube 2 match (src/pipeline/demo.h).
#include "capture/cube2.h"
#include "cli/commands.h"
#include "pipeline/demo.h"

namespace dynbench::cli {
namespace {

struct DemoCli {
  demo::DemoOptions options;
  std::string resolution = fmt::format("{}x{}", demo::DemoOptions{}.width, demo::DemoOptions{}.height);
};

Expected<void> runDemo(const DemoCli& cli) {
  demo::DemoOptions o = cli.options;
  auto res = parseResolution(cli.resolution);
  if (!res) return std::unexpected(res.error());
  std::tie(o.width, o.height) = *res;
  auto report = demo::runDemo(o, [](const std::string& line) {
    fmt::print("{}\n", line);
    std::fflush(stdout);
  });
  if (!report) return std::unexpected(report.error());
  fmt::print("report: {}\n", report->string());
  return {};
}

}  // namespace

void addDemoCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<DemoCli>();
  auto* cmd = app.add_subcommand("demo", "The whole chain on a seeded Cube 2 bot match: capture, convert, stats, render, discard, report");
  cmd->footer("Also makes a smooth fly-through over the same match as a second dataset, so the report shows the contrast.\n"
              "A rerun reuses the capture when --map, --bots, --seconds and --seed are the same, and the frames already rendered.\n"
              "Example: dynbench demo -o demo --seconds 20");
  cmd->add_option("-o,--output", o->options.output, "Output folder");
  cmd->add_option("--map", o->options.map, "Map");
  cmd->add_option("--bots", o->options.bots, "Bots")->check(between(capture::kBotsRange.first, capture::kBotsRange.second));
  cmd->add_option("--seconds", o->options.seconds, "Game seconds captured")->check(positive());
  cmd->add_option("--seed", o->options.seed, "Seed");
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
  cmd->callback([o, &run] { run = [o] { return runDemo(*o); }; });
}

}  // namespace dynbench::cli
