// `dynbench fidelity CAPTURE DATASET -o DIR`: the dataset's renders of the frames the game kept
// (capture cube2 --game-frames) against the game's own images (docs/fidelity.md).
#include "cli/commands.h"
#include "pipeline/fidelity_run.h"

namespace dynbench::cli {

void addFidelityCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<pipeline::FidelityStage>();
  auto* cmd = app.add_subcommand("fidelity", "Compare a dataset's renders with the game's own frames of the same moments");
  cmd->footer("Renders each frame in CAPTURE_DIR/game/ from DATASET at the game's resolution and measures depth agreement and the\n"
              "correlation of the blurred, tone-mapped luminance; writes DIR/fidelity_NNNNN.png (game | render | depth agreement)\n"
              "and DIR/fidelity.json. Exit status 5 when a frame fails (docs/fidelity.md).\n"
              "Example: dynbench capture cube2 -o cap --map colos --game-frames 60,120 && dynbench convert cap -o ds/colos.gltf &&\n"
              "         dynbench fidelity cap ds/colos.gltf -o fidelity/colos");
  cmd->add_option("CAPTURE_DIR", o->capture, "A capture with game frames")->required();
  cmd->add_option("DATASET", o->dataset, "Its converted dataset")->required();
  cmd->add_option("-o,--output", o->output, "Folder for the renders, side-by-side images and fidelity.json")->required();
  cmd->add_option("--spp", o->samplesPerPixel, "Samples per pixel of the renders")->check(positive())->capture_default_str();
  cmd->add_option("--threads", o->threads, "Render threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->callback([o, &run] {
    run = [o]() -> Expected<void> {
      auto outcome = pipeline::runFidelity(*o);
      if (!outcome) return std::unexpected(outcome.error());
      fmt::print("{}", outcome->markdown);
      if (!outcome->passed)
        return fail(ErrorCode::kInvalidData, "{}: a frame does not look like the game's (depth agreement below {} or correlation below {})",
                    o->dataset.string(), evaluate::kFidelityMinDepthAgreement, evaluate::kFidelityMinCorrelation);
      return {};
    };
  });
}

}  // namespace dynbench::cli
