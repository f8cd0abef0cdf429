// `dynbench flythrough DATASET -o OUT.gltf`: the demo's fly-through for any dataset with an animated
// camera, with its ORCA-range check (camera/flythrough.h).
#include <nlohmann/json.hpp>

#include "core/json_fields.h"
#include "cli/commands.h"
#include "core/files.h"
#include "camera/flythrough.h"

namespace dynbench::cli {
namespace {

struct FlythroughCli {
  std::string dataset, output, csv, json;
  bool requireOrca = false;
  camera::FlythroughOptions options;
};

Expected<void> runFlythrough(const FlythroughCli& cli) {
  const std::filesystem::path output(cli.output);
  const std::filesystem::path csv = cli.csv.empty() ? std::filesystem::path(output).replace_extension(".csv") : std::filesystem::path(cli.csv);
  auto made = camera::makeFlythroughDataset(cli.dataset, output, csv, cli.options);
  if (!made) return std::unexpected(made.error());
  fmt::print("{}: {}\n", output.string(), camera::describe(*made));
  fmt::print("{:<42} {:>10} {:>10} {:>10}\n", "measure (the new dataset at --fps)", "value", "ORCA low", "ORCA high");
  for (const auto& c : made->checks)
    fmt::print("{:<42} {:>10.4f} {:>10.3f} {:>10.3f}{}\n", c.measure, c.value, c.low, c.high, c.inside() ? "" : "  outside");
  if (!cli.json.empty()) {
    if (auto ok = writeFileAtomic(cli.json, jsonFileText(camera::flythroughJson(*made, cli.dataset, output, csv))); !ok) return std::unexpected(ok.error());
  }
  if (cli.requireOrca && !made->insideOrca())
    return fail(ErrorCode::kInvalidData, "{}: the fly-through is outside ORCA's ranges (--require-orca); the dataset is written", output.string());
  return {};
}

}  // namespace

void addFlythroughCommand(CLI::App& app, CommandRun& run) {
  auto cli = std::make_shared<FlythroughCli>();
  auto* cmd = app.add_subcommand("flythrough", "A smooth fly-through camera, ORCA-like, over a dataset's animated camera path");
  cmd->footer(
      "Follows one of the camera's stretches without a cut (the longest whose flight falls inside the ranges of the thesis's\n"
      "ORCA rows in Tables 6.4-6.6, else the closest), smoothed clear of static geometry, flown at constant speed, looking\n"
      "ahead. Writes OUT (the dataset with the new camera) and its pose log (OUT with .csv), and prints the new dataset's\n"
      "Tables 6.4-6.6 against ORCA's ranges. Definitions: docs/cli.md#flythrough.\n"
      "Example: dynbench flythrough colos_bot.gltf -o colos_flythrough.gltf --json fly.json");
  cmd->add_option("DATASET", cli->dataset, "The dataset whose animated camera the path follows (.gltf)")->required();
  cmd->add_option("-o,--output", cli->output, "The new dataset (.gltf, beside DATASET)")->required();
  cmd->add_option("--csv", cli->csv, "The pose log (default: OUT with .csv)");
  cmd->add_option("--json", cli->json, "The report and checks as JSON");
  cmd->add_option("--speed", cli->options.speed, "m/s flown (less when the stretch is shorter)")->capture_default_str()->check(positive());
  cmd->add_option("--look-ahead", cli->options.lookAhead, "m along the path the camera looks at")->capture_default_str()->check(positive());
  cmd->add_option("--smoothing", cli->options.maxSmoothing, "Widest moving average of the path, scene units (halved until clear of walls)")
      ->capture_default_str()
      ->check(nonNegative());
  cmd->add_option("--fps", cli->options.frameRate, "Frame rate the dataset is rendered and measured at")->capture_default_str()->check(positive());
  cmd->add_option("--metres-per-unit", cli->options.metresPerUnit, "Scene units to metres (Cube 2: 0.125)")->capture_default_str()->check(positive());
  cmd->add_option("--pitch-target", cli->options.pitchTarget, "Mean pitch change a frame (°) the nod brings a flat path to; 0: no nod")
      ->capture_default_str()
      ->check(nonNegative());
  cmd->add_option("--candidates", cli->options.candidates, "How many of the longest stretches are flown and compared")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_flag("--require-orca", cli->requireOrca, "Exit with status 5 when the new dataset is outside ORCA's ranges");
  cmd->callback([cli, &run] { run = [cli] { return runFlythrough(*cli); }; });
}

}  // namespace dynbench::cli
