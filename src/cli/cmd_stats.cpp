// `dynbench stats FILE...`: dataset properties and camera motion, the thesis's Tables 6.1-6.6.
#include <map>
#include <optional>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "core/files.h"
#include "core/progress.h"
#include "metrics/camera_motion.h"
#include "metrics/properties.h"
#include "report/plots.h"
#include "report/stats_output.h"
#include "scene/load.h"

namespace dynbench::cli {
namespace {

namespace fs = std::filesystem;

struct StatsOptions {
  std::vector<std::string> inputs;
  double fps = 24.0;
  double sequenceRate = 24.0;
  std::optional<std::string> camera;
  std::optional<std::string> animation;
  std::string json, csv, seriesDir, plotsDir;
};

// "scene.gltf", or "scene.gltf (2)" when two inputs share a file name.
std::vector<std::string> uniqueNames(const std::vector<std::string>& inputs) {
  std::vector<std::string> names;
  std::map<std::string, int> seen;
  for (const auto& input : inputs) {
    fs::path p(input);
    std::string name = p.filename().string();
    if (name.empty()) name = p.parent_path().filename().string();
    const int n = ++seen[name];
    names.push_back(n == 1 ? name : fmt::format("{} ({})", name, n));
  }
  return names;
}

std::string fileStem(const std::string& name) {
  std::string stem;
  for (char c : name) stem += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return stem;
}

Expected<void> runStats(const StatsOptions& options) {
  const auto names = uniqueNames(options.inputs);
  std::vector<report::StatsRow> rows;
  std::optional<Progress> progress(std::in_place, "stats", options.inputs.size(), "files");
  for (std::size_t i = 0; i < options.inputs.size(); ++i) {
    const auto& input = options.inputs[i];
    progress->update(i, input);
    report::StatsRow row;
    scene::LoadOptions loadOptions;
    loadOptions.sequenceRate = options.sequenceRate;
    auto scene = scene::loadScene(input, loadOptions);
    if (!scene) return std::unexpected(scene.error());
    if (options.animation && !scene::keepOnlyAnimation(*scene, *options.animation)) {
      std::string names;
      for (std::size_t a = 0; a < scene->animations.size(); ++a)
        names += fmt::format("{}{} '{}'", a ? ", " : "", a, scene->animations[a].name);
      return fail(ErrorCode::kUsage, "{}: --animation '{}' names no animation (animations in the file: {})", input,
                  *options.animation, names.empty() ? "none" : names);
    }
    row.properties = metrics::measureProperties(*scene, options.fps);
    for (const auto& warning : row.properties.warnings) spdlog::warn("{}", warning);
    row.name = names[i];
    row.path = input;
    auto motion = metrics::measureCameraMotion(*scene, options.fps, options.camera);
    if (!motion) return std::unexpected(motion.error());
    row.motion = std::move(*motion);
    rows.push_back(std::move(row));
  }
  progress.reset();  // clears its line before the tables

  fmt::print("{}", report::statsMarkdown(rows));
  if (!options.json.empty())
    if (auto ok = writeFileAtomic(options.json, report::statsJson(rows, options.fps)); !ok) return ok;
  if (!options.csv.empty())
    if (auto ok = writeFileAtomic(options.csv, report::statsCsv(rows)); !ok) return ok;
  for (const auto& row : rows) {
    if (!row.motion.hasCamera) {
      if (!options.seriesDir.empty() || !options.plotsDir.empty())
        spdlog::warn("{}: no camera, so no series or plots", row.path);
      continue;
    }
    const std::string stem = fileStem(row.name);
    if (!options.seriesDir.empty())
      if (auto ok = writeFileAtomic(fs::path(options.seriesDir) / (stem + "_camera.csv"), report::cameraSeriesCsv(row.motion)); !ok)
        return ok;
    if (!options.plotsDir.empty()) {
      auto written = report::writeRotationPlots(row.motion, row.name, options.plotsDir, stem);
      if (!written) return std::unexpected(written.error());
    }
  }
  return {};
}

}  // namespace

void addStatsCommand(CLI::App& app, CommandRun& run) {
  auto options = std::make_shared<StatsOptions>();
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
  cmd->callback([options, &run] { run = [options] { return runStats(*options); }; });
}

}  // namespace dynbench::cli
