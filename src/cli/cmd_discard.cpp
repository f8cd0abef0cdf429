// `dynbench discard FRAMES_DIR`: reprojection discard percentages (thesis §3.2.2, Table 6.7).
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "core/files.h"
#include "core/image_io.h"
#include "core/progress.h"
#include "discard/discard.h"
#include "report/plots.h"
#include "report/tables.h"

namespace dynbench::cli {
namespace {

namespace fs = std::filesystem;

struct DiscardCli {
  std::string frames, json, csv, masks, plots;
  discard::Thresholds thresholds;
};

Expected<void> runDiscard(const DiscardCli& cli) {
  const auto& t = cli.thresholds;
  for (const auto& [name, value] : {std::pair{"--threshold-position", t.position}, {"--threshold-normal", t.normal},
                                    {"--threshold-direct", t.direct}, {"--threshold-indirect", t.indirect}})
    if (!(value >= 0)) return fail(ErrorCode::kUsage, "{} must be a non-negative number (got {})", name, value);
  discard::MaskSink masks;
  if (!cli.masks.empty()) {
    masks = [&](const discard::FeatureFrame& frame, const discard::DiscardResult& r) -> Expected<void> {
      FloatImage image{frame.width, frame.height, 3, discard::maskImage(frame, r.mask), {}};
      return writeImage(fs::path(cli.masks) / fmt::format("discard_{:05d}.png", frame.frame), image);
    };
  }
  std::optional<Progress> progress;
  discard::DiscardProgress report = [&](std::size_t done, std::size_t total) {
    if (!progress) progress.emplace("discard", total, "frames");
    progress->update(done);
  };
  auto run = discard::discardFolder(cli.frames, t, masks, report);
  progress.reset();
  if (!run) return std::unexpected(run.error());
  for (const auto& w : run->warnings) spdlog::warn("{}: {}", cli.frames, w);

  const std::string name = fs::path(cli.frames).filename().string().empty() ? cli.frames : fs::path(cli.frames).filename().string();
  fmt::print("{}", report::markdownTable(report::discardTable(
                       {{name, run->mean}}, fmt::format("{} frame pairs, {}x{}", run->frames.size(), run->width, run->height))));

  if (!cli.json.empty())
    if (auto ok = writeFileAtomic(cli.json, discard::discardJson(*run, cli.frames)); !ok) return ok;
  if (!cli.csv.empty()) {
    std::string csv = "frame,time,frustum,world_position,shading_normal,direct_radiance,indirect_radiance\n";
    for (const auto& f : run->frames)
      csv += fmt::format("{},{},{},{},{},{},{}\n", f.frame, f.time, f.frustum, f.position, f.normal, f.direct, f.indirect);
    if (auto ok = writeFileAtomic(cli.csv, csv); !ok) return ok;
  }
  if (!cli.plots.empty()) {
    const std::string name = fs::path(cli.frames).filename().string();
    auto written = report::writeDiscardPlot(run->frames, name, cli.plots, name.empty() ? "frames" : name);
    if (!written) return std::unexpected(written.error());
  }
  return {};
}

}  // namespace

void addDiscardCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<DiscardCli>();
  auto* cmd = app.add_subcommand("discard", "Reprojection discard percentages of a frames folder (thesis Table 6.7)");
  cmd->footer("FRAMES_DIR holds frame_NNNNN.exr + frame_NNNNN.json per frame (docs/feature-buffers.md), e.g. from\n"
              "`dynbench render`. Definitions and defaults: docs/metrics.md.\n"
              "Example: dynbench discard frames/run1 --relative-position --noise-aware --json discard.json --masks masks/");
  cmd->add_option("FRAMES_DIR", o->frames, "Folder of feature-buffer frames")->required();
  cmd->add_option("--threshold-position", o->thresholds.position, "World-position distance, scene units (a fraction of the scene's size with --relative-position)")
      ->check(nonNegative());
  cmd->add_flag("--relative-position", o->thresholds.relativePosition, "Position threshold as a fraction of the scene's size");
  cmd->add_option("--threshold-normal", o->thresholds.normal, "Shading-normal vector distance (0.1: a turn of about 5.7 degrees)")->check(nonNegative());
  cmd->add_option("--threshold-direct", o->thresholds.direct,
                  "Direct radiance distance, a fraction of the frame's mean luminance")
      ->check(nonNegative());
  cmd->add_option("--threshold-indirect", o->thresholds.indirect,
                  "Indirect radiance distance, a fraction of the frame's mean luminance")
      ->check(nonNegative());
  cmd->add_flag("--absolute-radiance", o->thresholds.absoluteRadiance, "Radiance thresholds in radiance units, not relative");
  cmd->add_flag("--noise-aware", o->thresholds.noiseAware,
                "Discard radiance only when the change exceeds 3 standard deviations of the pixels' noise (needs *.var channels)");
  cmd->add_option("--json", o->json, "Per-frame and mean percentages as JSON");
  cmd->add_option("--csv", o->csv, "Per-frame percentages as CSV");
  cmd->add_option("--plots", o->plots, "Write NAME_discard.png and .svg: per-frame discard percentages (gnuplot)");
  cmd->add_option("--masks", o->masks, "Write discard_NNNNN.png per frame: discarded pixels coloured by reason over the dimmed image");
  cmd->callback([o, &run] { run = [o] { return runDiscard(*o); }; });
}

}  // namespace dynbench::cli
