// `dynbench vr-camera DATASET --trace HEAD.csv -o OUT.gltf`: the VR head camera (camera/vr_head.h),
// a real head trace riding the fly-through's path, with its Tables 6.4-6.6 beside the thesis's
// Eternal Valley VR row.
#include <nlohmann/json.hpp>

#include "camera/vr_head.h"
#include "cli/commands.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "report/reference.h"

namespace dynbench::cli {
namespace {

struct VrCameraCli {
  std::string dataset, output, csv, json, trace;
  camera::VrCameraOptions options;
};

// The thesis's Eternal Valley VR row of `table` (6.4-6.6), its cells as printed (empty when absent).
std::vector<std::string> thesisVrRow(const report::Reference& reference, const std::string& table) {
  for (const auto& t : reference.tables)
    if (t.table == table)
      for (const auto& row : t.rows)
        if (row.dataset == "Eternal Valley VR") return row.cells;
  return {};
}

Expected<void> runVrCamera(VrCameraCli cli) {
  const std::filesystem::path output(cli.output);
  const std::filesystem::path csv = cli.csv.empty() ? std::filesystem::path(output).replace_extension(".csv") : std::filesystem::path(cli.csv);
  cli.options.trace = cli.trace;
  cli.options.body.metresPerUnit = cli.options.metresPerUnit;  // one scale for the body's path and the head's offset
  auto made = camera::makeVrCameraDataset(cli.dataset, output, csv, cli.options);
  if (!made) return std::unexpected(made.error());
  fmt::print("{}: {}\n", output.string(), camera::describe(made->report));
  auto reference = report::thesisReference();
  if (!reference) return std::unexpected(reference.error());
  // The measures as flythrough checks them against ORCA (positions in metres, Table 6.5 as the
  // thesis's half angle), beside Eternal Valley VR's cells.
  fmt::print("{:<42} {:>10} {:>20}\n", "measure (the new dataset at --fps)", "value", "Eternal Valley VR");
  for (const camera::OrcaCheck& c : camera::orcaChecks(made->motion, cli.options.metresPerUnit)) {
    const auto row = thesisVrRow(*reference, c.table);
    fmt::print("{:<42} {:>10.4f} {:>20}\n", c.measure, c.value, c.column < row.size() ? row[c.column] : "-");
  }
  if (!cli.json.empty())
    if (auto ok = writeFileAtomic(cli.json, jsonFileText(camera::vrCameraJson(*made, cli.dataset, output, csv, cli.options))); !ok)
      return std::unexpected(ok.error());
  return {};
}

}  // namespace

void addVrCameraCommand(CLI::App& app, CommandRun& run) {
  auto cli = std::make_shared<VrCameraCli>();
  auto* cmd = app.add_subcommand("vr-camera", "A VR head camera: a real head trace riding the fly-through's path through the match");
  cmd->footer(
      "The body travels the fly-through's path (smooth locomotion); the head's rotation and its offset from where it started\n"
      "come from TRACE (time,x,y,z,qx,qy,qz,qw in metres, Y up, looking along -Z: data/vr-head/ or a headset's own log),\n"
      "resampled to the poses, its starting heading turned onto the path's, its offset scaled by --metres-per-unit and cut\n"
      "short before walls. Writes OUT and its pose log (OUT with .csv) and prints Tables 6.4-6.6 beside the thesis's\n"
      "Eternal Valley VR row. Definitions: docs/cli.md#vr-camera.\n"
      "Example: dynbench vr-camera colos_bot.gltf --trace data/vr-head/eyenavgs_nthu_london_user7_quickturns.csv -o colos_vr.gltf");
  cmd->add_option("DATASET", cli->dataset, "The dataset whose match the head moves through (.gltf)")->required();
  cmd->add_option("-o,--output", cli->output, "The new dataset (.gltf, beside DATASET)")->required();
  cmd->add_option("--trace", cli->trace, "The head trace (CSV: time,x,y,z,qx,qy,qz,qw; metres)")->required();
  cmd->add_option("--trace-start", cli->options.traceStart, "Seconds into the trace where the dataset starts")
      ->capture_default_str()
      ->check(nonNegative());
  cmd->add_option("--metres-per-unit", cli->options.metresPerUnit, "Scene units to metres: the capture's k (Cube 2 0.125, OpenArena 0.03125)")
      ->capture_default_str()
      ->check(positive());
  cmd->add_option("--clearance", cli->options.clearance, "Metres kept between the head and a static surface")->capture_default_str()->check(nonNegative());
  cmd->add_option("--fps", cli->options.body.frameRate, "Frame rate the dataset is rendered and measured at")->capture_default_str()->check(positive());
  cmd->add_option("--speed", cli->options.body.speed, "m/s the body travels (the fly-through's; less when the stretch is shorter)")
      ->capture_default_str()
      ->check(positive());
  cmd->add_option("--csv", cli->csv, "The pose log (default: OUT with .csv)");
  cmd->add_option("--json", cli->json, "The report and Tables 6.4-6.6 as JSON");
  cmd->callback([cli, &run] { run = [cli] { return runVrCamera(*cli); }; });
}

}  // namespace dynbench::cli
