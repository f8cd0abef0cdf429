// `dynbench stats FILE...`: dataset properties and camera motion, the thesis's Tables 6.1-6.6.
#include <optional>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "core/progress.h"
#include "pipeline/stages.h"

namespace dynbench::cli {
namespace {

Expected<void> runStatsCommand(const pipeline::StatsStage& stage) {
  std::optional<Progress> progress(std::in_place, "stats", stage.inputs.size(), "files");
  auto outcome = pipeline::runStats(stage, [&](std::size_t i, const std::filesystem::path& input) { progress->update(i, input.string()); });
  progress.reset();  // clears its line before the tables
  if (!outcome) return std::unexpected(outcome.error());
  for (const auto& warning : outcome->warnings) spdlog::warn("{}", warning);
  fmt::print("{}", outcome->markdown);
  return {};
}

}  // namespace

void addStatsCommand(CLI::App& app, CommandRun& run) {
  auto options = std::make_shared<pipeline::StatsStage>();
  auto* cmd = app.add_subcommand("stats", "Measure datasets: properties and camera motion (thesis Tables 6.1-6.6)");
  cmd->footer(
      "FILE is a .gltf/.glb, anything assimp reads (.fbx, .dae, .obj, ...), or an OBJ key-frame sequence given as a\n"
      "folder of .obj files or a quoted glob ('frames/*.obj'). Tables go to stdout as Markdown.\n"
      "Example: dynbench stats scene.glb other.fbx --json stats.json --plots plots/");
  cmd->add_option("FILE", options->inputs, "Datasets to measure (one table row each)")->required();
  cmd->add_option("--fps", options->fps, "Sampling rate in frames per second")
      ->check(positive());
  cmd->add_option("--camera", options->camera,
                  "Camera to measure: a camera index or a camera/node name (default: the first animated camera)");
  cmd->add_option("--animation", options->animation,
                  "Play only this animation: an index or a name (default: all animations together on one clock)");
  cmd->add_option("--json", options->json, "Also write the numbers as JSON to PATH");
  cmd->add_option("--csv", options->csv, "Also write one CSV row per dataset to PATH");
  cmd->add_option("--series", options->seriesDir, "Write per-frame camera series, DIR/<dataset>_camera.csv");
  cmd->add_option("--plots", options->plotsDir,
                  "Write Figures A.1 and A.2 (rotation per frame) as PNG and SVG to DIR (needs gnuplot)");
  cmd->add_option("--sequence-rate", options->sequenceRate,
                  "Key frames per second of an OBJ sequence")
      ->check(positive());
  cmd->callback([options, &run] { run = [options] { return runStatsCommand(*options); }; });
}

}  // namespace dynbench::cli
