// dynbench: the command-line front end. Parses arguments, runs one subcommand, maps its Error to
// an exit status. Library code never exits; this file is the only place that decides a status.
#include <cstdio>
#include <iostream>

#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "dynbench/version.h"

namespace dynbench::cli {

int exitCode(const Error& error) { return static_cast<int>(error.code); }

}  // namespace dynbench::cli

int main(int argc, char** argv) {
  using namespace dynbench;
  CLI::App app{"dynbench: dynamic benchmarks for temporal rendering (capture, convert, stats, render, "
               "discard, report).\nSee docs/cli.md for every command, docs/metrics.md for what the numbers mean.",
               "dynbench"};
  app.set_version_flag("--version", std::string("dynbench ") + kVersion);
  app.require_subcommand(0, 1);
  app.fallthrough(false);
  spdlog::set_pattern("dynbench: %l: %v");

  cli::CommandRun run;
  cli::addStatsCommand(app, run);
  cli::addCaptureCheckCommand(app, run);
  cli::addConvertCommand(app, run);
  cli::addMergeCameraCommand(app, run);
  cli::addRenderCommand(app, run);
  cli::addDiscardCommand(app, run);
  cli::addReportCommand(app, run);
  cli::addCaptureCommand(app, run);
  cli::addDemoCommand(app, run);

  // `dynbench help [COMMAND]`
  std::string helpTopic;
  auto* help = app.add_subcommand("help", "Show help for dynbench or for one command");
  help->add_option("command", helpTopic, "The command to explain");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  if (help->parsed()) {
    if (helpTopic.empty()) {
      std::cout << app.help();
      return 0;
    }
    try {
      std::cout << app.get_subcommand(helpTopic)->help();
      return 0;
    } catch (const CLI::OptionNotFound&) {
      std::cerr << "dynbench: no command named '" << helpTopic << "'; run `dynbench --help` for the list\n";
      return static_cast<int>(ErrorCode::kUsage);
    }
  }
  if (!run) {
    std::cout << app.help();
    return 0;
  }
  auto result = run();
  if (!result) {
    std::cerr << "dynbench: error: " << result.error().message << "\n";
    return cli::exitCode(result.error());
  }
  return 0;
}
