// `dynbench merge-camera DATASET CAMERA_RUN -o OUT`: swap in another camera run (thesis §5.5).
#include <optional>

#include "cli/commands.h"
#include "camera/merge_camera.h"

namespace dynbench::cli {
namespace {

struct MergeCli {
  std::string dataset, run, output;
  std::optional<std::string> camera;
  double offset = 0.0;
};

Expected<void> runMerge(const MergeCli& cli) {
  camera::MergeCameraOptions options;
  options.dataset = cli.dataset;
  options.run = cli.run;
  options.output = cli.output;
  options.camera = cli.camera;
  options.offsetSeconds = cli.offset;
  auto report = camera::mergeCamera(options);
  if (!report) return std::unexpected(report.error());
  fmt::print("{}: camera node {} now follows {} ({} keys, {:.3f} s to {:.3f} s)\n", cli.output, report->cameraNode, cli.run,
             report->keys, report->startTime, report->endTime);
  return {};
}

}  // namespace

void addMergeCameraCommand(CLI::App& app, CommandRun& run) {
  auto options = std::make_shared<MergeCli>();
  auto* cmd = app.add_subcommand("merge-camera", "Replace a dataset's camera animation with another camera run (thesis §5.5)");
  cmd->footer("CAMERA_RUN is a capture directory (its first camera) or a CSV pose log: time,x,y,z,qx,qy,qz,qw per line\n"
              "(a header line is allowed; roll is kept). The run's first pose is aligned to the dataset's start.\n"
              "Example: dynbench merge-camera run1.gltf headset.csv -o run1_vr.gltf --offset 2.5");
  cmd->add_option("DATASET", options->dataset, "The dataset (.gltf with its .bin)")->required();
  cmd->add_option("CAMERA_RUN", options->run, "Capture directory or CSV pose log")->required();
  cmd->add_option("-o,--output", options->output, "The new dataset (.gltf, beside DATASET)")->required();
  cmd->add_option("--camera", options->camera, "Camera node to replace: index or name (default: the first animated camera)");
  cmd->add_option("--offset", options->offset, "Seconds added to the run's times after aligning its start");
  cmd->callback([options, &run] { run = [options] { return runMerge(*options); }; });
}

}  // namespace dynbench::cli
