// `dynbench report RUN... -o report.html`: datasets side by side (Tables 6.1-6.7, figures).
#include "cli/commands.h"
#include "pipeline/stages.h"

namespace dynbench::cli {
namespace {

struct ReportCli {
  std::vector<std::string> runs;
  std::string output, title = "dynbench report";
  int thumbnails = 3;
  int videoFrames = 240;
  std::string reference;
};

Expected<void> runReportCommand(const ReportCli& cli) {
  report::ReportOptions options;
  for (const auto& r : cli.runs) options.runs.emplace_back(r);
  options.output = cli.output;
  options.title = cli.title;
  options.thumbnails = cli.thumbnails;
  options.videoFrames = cli.videoFrames;
  options.reference = cli.reference;
  auto files = pipeline::runReport(options);
  if (!files) return std::unexpected(files.error());
  fmt::print("{}: {:.2f} MB, self-contained ({} images, {} videos inline)\n{}\n", files->html.string(), files->htmlBytes / 1e6,
             files->images, files->videos, files->markdown.string());
  return {};
}

}  // namespace

void addReportCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<ReportCli>();
  auto* cmd = app.add_subcommand("report", "Compare datasets: Tables 6.1-6.7 and figures in one HTML file and a Markdown twin");
  cmd->footer("A RUN folder holds stats.json (dynbench stats DATASET --json RUN/stats.json) and discard.json (dynbench discard\n"
              "FRAMES --json RUN/discard.json); optionally *_camera.csv (stats --series RUN) for Figures A.1/A.2, frames/\n"
              "(feature buffers) for thumbnails and a video, and masks/ (discard --masks RUN/masks).\n"
              "Example: dynbench report runs/cube2 runs/flythrough -o report.html");
  cmd->add_option("RUN", o->runs, "Run folders, one row per run")->required();
  cmd->add_option("-o,--output", o->output, "The report (.html; report.md and report_files/ beside it)")->required();
  cmd->add_option("--title", o->title, "Report title");
  cmd->add_option("--thumbnails", o->thumbnails, "Thumbnails and masks per run (0: none)")->check(nonNegative());
  cmd->add_option("--video-frames", o->videoFrames,
                  "Per run, a VP9 video of its first N frames beside their discard masks (0: none; needs ffmpeg)")
      ->check(nonNegative());
  cmd->add_option("--reference", o->reference, "thesis: add the thesis's published rows (Tables 6.1-6.7), marked as published")
      ->check(CLI::IsMember({"thesis"}));
  cmd->callback([o, &run] { run = [o] { return runReportCommand(*o); }; });
}

}  // namespace dynbench::cli
