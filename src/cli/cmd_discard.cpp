// `dynbench discard FRAMES_DIR`: reprojection discard percentages (thesis §3.2.2, Table 6.7).
#include <optional>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "core/progress.h"
#include "discard/discard.h"
#include "pipeline/stages.h"

namespace dynbench::cli {
namespace {

namespace fs = std::filesystem;

struct DiscardCli {
  std::string frames, json, csv, masks, plots;
  discard::Thresholds thresholds;
  std::optional<double> position;  // default by the geometry test
  bool includeCuts = false;
};

Expected<void> runDiscardCommand(const DiscardCli& cli) {
  const discard::Thresholds thresholds = discard::withPositionDefault(cli.thresholds, cli.position);
  std::optional<Progress> progress;
  auto outcome = pipeline::runDiscard({cli.frames, thresholds, cli.includeCuts, cli.json, cli.csv, cli.masks, cli.plots},
                                      [&](std::size_t done, std::size_t total) {
                                        if (!progress) progress.emplace("discard", total, "frames");
                                        progress->update(done);
                                      });
  progress.reset();
  if (!outcome) return std::unexpected(outcome.error());
  for (const auto& w : outcome->run.warnings) spdlog::warn("{}: {}", cli.frames, w);
  fmt::print("{}", outcome->markdown);
  return {};
}

}  // namespace

void addDiscardCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<DiscardCli>();
  auto* cmd = app.add_subcommand("discard", "Reprojection discard percentages of a frames folder (thesis Table 6.7)");
  cmd->footer("FRAMES_DIR holds frame_NNNNN.exr + frame_NNNNN.json per frame (docs/feature-buffers.md), e.g. from\n"
              "`dynbench render`. Definitions and defaults: docs/metrics.md.\n"
              "Example: dynbench discard frames/run1 --json discard.json --masks masks/");
  cmd->add_option("FRAMES_DIR", o->frames, "Folder of feature-buffer frames")->required();
  using Geometry = discard::Thresholds::GeometryTest;
  cmd->add_option("--geometry-test", o->thresholds.geometryTest,
                  "taps (default): each bilinear tap of the history on its own, its distance from the pixel's tangent plane against "
                  "--threshold-position x the view depth (as SVGF and NRD test history); bilinear: the thesis's test on the bilinear "
                  "sample, position in scene units (docs/metrics.md)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, Geometry>{{"taps", Geometry::kTaps}, {"bilinear", Geometry::kBilinear}}));
  cmd->add_option("--threshold-position", o->position,
                  fmt::format("World position: taps: plane distance as a fraction of the view depth (default {}); bilinear: distance in "
                              "scene units (default {}), a fraction of the scene's size with --relative-position",
                              discard::Thresholds{}.position, discard::kBilinearPositionThreshold))
      ->check(nonNegative());
  cmd->add_flag("--relative-position", o->thresholds.relativePosition,
                "The thesis's bilinear test (implies --geometry-test bilinear) with the position threshold as a fraction of the first "
                "frame's scene size");
  cmd->add_option("--threshold-normal", o->thresholds.normal, "Shading-normal vector distance (0.1: a turn of about 5.7 degrees)")->check(nonNegative());
  cmd->add_option("--threshold-direct", o->thresholds.direct,
                  "Direct radiance distance, a fraction of the frame's mean luminance")
      ->check(nonNegative());
  cmd->add_option("--threshold-indirect", o->thresholds.indirect,
                  "Indirect radiance distance, a fraction of the frame's mean luminance")
      ->check(nonNegative());
  cmd->add_flag("--absolute-radiance", o->thresholds.absoluteRadiance, "Radiance thresholds in radiance units, not relative");
  using Test = discard::Thresholds::RadianceTest;
  cmd->add_option("--radiance-test", o->thresholds.radianceTest,
                  fmt::format("pairs (default): the frames' radiance-change pairs (render --converge or --pairs) decide each pixel, no noise "
                              "where nothing changed (docs/metrics.md); expected: the image-against-image test, each pixel counting with the "
                              "probability that its radiance truly changed given its noise (*.var channels), with 95% intervals; noise-aware: "
                              "the change must also exceed {} standard deviations of the noise; plain: the thesis's test on the rendered values",
                              discard::Thresholds{}.noiseSigmas))
      ->transform(CLI::CheckedTransformer(std::map<std::string, Test>(discard::radianceTestsByName().begin(), discard::radianceTestsByName().end())));
  cmd->add_flag_callback("--noise-aware", [o] { o->thresholds.radianceTest = Test::kNoiseAware; },
                         fmt::format("Same as --radiance-test noise-aware: radiance discards only when the change exceeds {} standard "
                                     "deviations of the pixels' noise (needs *.var channels)",
                                     discard::Thresholds{}.noiseSigmas));
  cmd->add_flag("--include-cuts", o->includeCuts, "Average camera-cut pairs too (frames whose sidecar says cut; left out by default)");
  cmd->add_option("--json", o->json, "Per-frame and mean percentages as JSON");
  cmd->add_option("--csv", o->csv, "Per-frame percentages as CSV");
  cmd->add_option("--plots", o->plots, "Write NAME_discard.png and .svg: per-frame discard percentages (gnuplot)");
  cmd->add_option("--masks", o->masks, "Write discard_NNNNN.png per frame: discarded pixels coloured by reason over the dimmed image");
  cmd->callback([o, &run] { run = [o] { return runDiscardCommand(*o); }; });
}

}  // namespace dynbench::cli
