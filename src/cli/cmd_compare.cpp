// `dynbench compare REFERENCE TEST...`: ꟻLIP, PSNR, SSIM, relMSE and SMAPE of test images against
// a reference (docs/metrics.md, "Image metrics").
#include "cli/commands.h"
#include "evaluate/compare.h"

namespace dynbench::cli {

void addCompareCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<evaluate::CompareOptions>();
  auto reference = std::make_shared<std::string>();
  auto tests = std::make_shared<std::vector<std::string>>();
  auto json = std::make_shared<std::string>(), heatmaps = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("compare", "Image metrics of test images against a reference: FLIP, PSNR, SSIM, relMSE, SMAPE");
  cmd->footer("EXR (or HDR) images are linear radiance and get HDR-FLIP; PNG images are sRGB and get LDR-FLIP. A dynbench frame\n"
              "(docs/feature-buffers.md) is compared as direct + indirect. Definitions: docs/metrics.md.\n"
              "Example: dynbench compare converged.exr noisy.exr denoised.exr --json scores.json --heatmap heat/");
  cmd->add_option("REFERENCE", *reference, "The reference image")->required();
  cmd->add_option("TEST", *tests, "Test images, the reference's size")->required();
  cmd->add_option("--json", *json, "Scores as JSON");
  cmd->add_option("--heatmap", *heatmaps, "Write flip_<TEST>.png per test: the FLIP error map in the magma colour map");
  cmd->add_option("--ppd", o->pixelsPerDegree,
                  "Pixels per degree of visual angle (default: a 0.7 m wide 4K display seen from 0.7 m, as FLIP's authors)")
      ->check(positive());
  cmd->callback([o, reference, tests, json, heatmaps, &run] {
    run = [o, reference, tests, json, heatmaps]() -> Expected<void> {
      o->reference = *reference;
      o->tests.assign(tests->begin(), tests->end());
      o->json = *json;
      o->heatmapDir = *heatmaps;
      auto result = evaluate::runCompare(*o);
      if (!result) return std::unexpected(result.error());
      fmt::print("{}", result->markdown);
      return {};
    };
  });
}

}  // namespace dynbench::cli
