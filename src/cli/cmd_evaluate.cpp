// `dynbench evaluate FRAMES --reference REF_FRAMES`: temporal methods scored against a converged
// reference (docs/metrics.md, "Temporal methods").
#include <optional>

#include <fmt/ranges.h>

#include "cli/commands.h"
#include "core/progress.h"
#include "evaluate/evaluate.h"
#include "evaluate/method.h"

namespace dynbench::cli {

void addEvaluateCommand(CLI::App& app, CommandRun& run) {
  auto o = std::make_shared<evaluate::EvaluateOptions>();
  auto paths = std::make_shared<std::array<std::string, 5>>();  // frames, reference, json, csv, out
  auto methods = std::make_shared<std::string>(fmt::format("{}", fmt::join(evaluate::builtInMethodNames(), ",")));
  auto* cmd = app.add_subcommand("evaluate", "Run temporal methods over low-sample frames and score them against converged frames");
  std::string methodLines;
  for (const auto& m : evaluate::builtInMethods()) methodLines += fmt::format("  {:<11} {}\n", m.name, m.description);
  cmd->footer(fmt::format("Methods:\n{}  external:DIR another program's output frames (docs/metrics.md)\n"
                          "FRAMES: e.g. `dynbench render --spp 4 --jitter`; REF_FRAMES: the same frames with\n"
                          "`--converge`. Metrics and the external-method contract: docs/metrics.md.\n"
                          "Example: dynbench evaluate noisy/ --reference converged/ --methods none,accumulate,svgf --json eval.json",
                          methodLines));
  cmd->add_option("FRAMES", (*paths)[0], "Folder of input frames (noisy radiance, G-buffers, motion)")->required();
  cmd->add_option("--reference", (*paths)[1], "Folder of converged frames with the same numbers")->required();
  cmd->add_option("--methods", *methods, "Comma-separated methods");
  cmd->add_option("--json", (*paths)[2], "Per-frame and mean scores as JSON");
  cmd->add_option("--csv", (*paths)[3], "Per-frame scores as CSV");
  cmd->add_option("--out", (*paths)[4], "Write OUT/METHOD/frame_NNNNN.exr per frame and OUT/METHOD/flip_worst.png");
  cmd->add_option("--ppd", o->pixelsPerDegree, "Pixels per degree for FLIP")->check(positive());
  cmd->callback([o, paths, methods, &run] {
    run = [o, paths, methods]() -> Expected<void> {
      o->frames = (*paths)[0], o->reference = (*paths)[1], o->json = (*paths)[2], o->csv = (*paths)[3], o->outDir = (*paths)[4];
      o->methods.clear();
      for (std::size_t start = 0; start <= methods->size();) {
        const std::size_t comma = std::min(methods->find(',', start), methods->size());
        if (comma > start) o->methods.push_back(methods->substr(start, comma - start));
        start = comma + 1;
      }
      std::optional<Progress> progress;
      auto result = evaluate::runEvaluate(*o, [&](std::size_t done, std::size_t total) {
        if (!progress) progress.emplace("evaluate", total, "frames");
        progress->update(done);
      });
      progress.reset();
      if (!result) return std::unexpected(result.error());
      fmt::print("{}", evaluate::evaluateMarkdown(*result));
      return {};
    };
  });
}

}  // namespace dynbench::cli
