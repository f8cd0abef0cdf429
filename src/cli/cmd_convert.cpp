// `dynbench convert CAPTURE_DIR -o DATASET.gltf`: a capture to a glTF 2.0 benchmark dataset.
#include <optional>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "convert/convert.h"
#include "core/progress.h"

namespace dynbench::cli {
namespace {

struct ConvertCliOptions {
  std::string capture, output, visibility = "both", lightRules, dataRoot, environment;
  convert::SkyParameters sky;
  bool sunGiven = false;  // --sun-elevation or --sun-azimuth: not the map's sun
  bool glb = false;
};

Expected<void> runConvert(const ConvertCliOptions& cli) {
  convert::ConvertOptions options;
  options.capture = cli.capture;
  options.output = cli.output;
  options.glb = cli.glb || std::filesystem::path(cli.output).extension() == ".glb";
  if (options.glb && std::filesystem::path(cli.output).extension() != ".glb")
    return fail(ErrorCode::kUsage, "-o {}: with --glb the output must end in .glb", cli.output);
  if (!options.glb && std::filesystem::path(cli.output).extension() != ".gltf")
    return fail(ErrorCode::kUsage, "-o {}: the output must end in .gltf (or .glb)", cli.output);
  options.visibility = cli.visibility == "node" ? convert::VisibilityMode::kNode
                       : cli.visibility == "scale" ? convert::VisibilityMode::kScale
                                                   : convert::VisibilityMode::kBoth;
  if (!cli.lightRules.empty()) {
    auto rules = convert::readLightRules(cli.lightRules);
    if (!rules) return std::unexpected(rules.error());
    options.lightRules = *rules;
  }
  if (!cli.dataRoot.empty()) options.dataRoot = cli.dataRoot;
  if (!cli.environment.empty()) options.environment = cli.environment;
  options.sky = cli.sky;
  options.sunFromCapture = !cli.sunGiven;
  std::optional<Progress> progress;
  int shownPass = 0;
  options.onProgress = [&](int pass, std::size_t frames, std::size_t total) {
    if (pass != shownPass) {
      progress.reset();
      progress.emplace(fmt::format("convert pass {}/2", pass), total, "frames");
      shownPass = pass;
    }
    if (frames % 64 == 0) progress->update(frames);
  };
  auto report = convert::convertCapture(options);
  progress.reset();
  if (!report) return std::unexpected(report.error());
  for (const auto& w : report->warnings) spdlog::warn("{}", w);
  fmt::print("{}: {} frames, {} capturables -> {} nodes, {} meshes, {} materials, {} textures, {} skins, {} morph targets, {} lights, "
             "{} channels, {} camera cuts, {:.1f} MiB of buffer\n",
             cli.output, report->frames, report->capturables, report->nodes, report->meshes, report->materials, report->textures,
             report->skins, report->morphTargets, report->lights, report->channels, report->cameraCuts,
             static_cast<double>(report->binBytes) / (1024.0 * 1024.0));
  return {};
}

}  // namespace

void addConvertCommand(CLI::App& app, CommandRun& run) {
  auto options = std::make_shared<ConvertCliOptions>();
  auto* cmd = app.add_subcommand("convert", "Convert a capture directory to a glTF 2.0 benchmark dataset (thesis §5.4)");
  cmd->footer("Writes DATASET.gltf + DATASET.bin (or one .glb), DATASET_textures/ and DATASET.README.md.\n"
              "Layout and conventions: docs/dataset.md. Example: dynbench convert captures/run1 -o datasets/run1.gltf");
  cmd->add_option("CAPTURE_DIR", options->capture, "The capture directory (docs/capture-format.md)")->required();
  cmd->add_option("-o,--output", options->output, "The dataset to write, .gltf or .glb")->required();
  cmd->add_flag("--glb", options->glb, "Write one binary .glb instead of .gltf with an external .bin");
  cmd->add_option("--visibility", options->visibility,
                  "How appearing/disappearing objects are switched: node (KHR_node_visibility), scale (scale 0), "
                  "or both (lights never use scale)")
      ->check(CLI::IsMember({"node", "scale", "both"}));
  cmd->add_option("--light-rules", options->lightRules, "JSON file overriding the light rules (docs/dataset.md)");
  cmd->add_option("--env", options->environment,
                  "Equirectangular .hdr/.exr environment copied beside the dataset (without it: a generated daylight sky)");
  cmd->add_option("--sun-elevation", options->sky.sunElevationDegrees, "Generated sky: sun elevation, degrees (default: the map's sun from the capture, else 45)")
      ->check(between(0.0, 90.0));
  cmd->add_option("--sun-azimuth", options->sky.sunAzimuthDegrees, "Generated sky: sun azimuth from -Z towards +X, degrees (default: the map's sun, else 135)");
  cmd->add_option("--turbidity", options->sky.turbidity, "Generated sky: turbidity, from clear to hazy")
      ->check(between(convert::kTurbidityRange.first, convert::kTurbidityRange.second));
  cmd->add_option("--data-root", options->dataRoot, "Where texture names are resolved (empty: the capture's data root)");
  cmd->callback([options, cmd, &run] {
    options->sunGiven = cmd->count("--sun-elevation") + cmd->count("--sun-azimuth") > 0;
    run = [options] { return runConvert(*options); };
  });
}

}  // namespace dynbench::cli
