// `dynbench capture-check DIR`: validate a capture and print its summary.
#include <optional>

#include <spdlog/spdlog.h>

#include "core/json_fields.h"
#include "capture/check.h"
#include "cli/commands.h"
#include "core/files.h"
#include "core/progress.h"

namespace dynbench::cli {
namespace {

struct CheckOptions {
  std::string directory, json;
};

Expected<void> runCheck(const CheckOptions& options) {
  // The frame count is unknown until the end: frames read and their rate, no time left.
  std::optional<Progress> progress(std::in_place, "capture-check", 0, "frames");
  auto summary = capture::checkCapture(options.directory, [&](std::size_t frames) {
    if (frames % 64 == 0) progress->update(frames);
  });
  progress.reset();
  if (!summary) return std::unexpected(summary.error());
  for (const auto& warning : summary->warnings) spdlog::warn("{}", warning);
  fmt::print("{}", capture::summaryText(options.directory, *summary));
  if (!options.json.empty())
    if (auto ok = writeFileAtomic(options.json, jsonFileText(capture::summaryJson(options.directory, *summary))); !ok) return ok;
  return {};
}

}  // namespace

void addCaptureCheckCommand(CLI::App& app, CommandRun& run) {
  auto options = std::make_shared<CheckOptions>();
  auto* cmd = app.add_subcommand("capture-check", "Validate a capture directory and print its summary");
  cmd->footer("Reads models/*.txt and Capture.txt (docs/capture-format.md); errors name file:line.\n"
              "Example: dynbench capture-check captures/colos --json summary.json");
  cmd->add_option("DIR", options->directory, "The capture directory")->required();
  cmd->add_option("--json", options->json, "Also write the summary as JSON to PATH");
  cmd->callback([options, &run] { run = [options] { return runCheck(*options); }; });
}

}  // namespace dynbench::cli
