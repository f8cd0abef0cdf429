// dynbench: the command-line front end. Parses arguments, runs one subcommand, maps its Error to
// an exit status. Library code never exits; this file is the only place that decides a status.
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "cli/commands.h"
#include "dynbench/version.h"

namespace dynbench::cli {

int exitCode(const Error& error) { return static_cast<int>(error.code); }

namespace {

// A number check on an option's text: empty when `accept` holds, else the reason.
CLI::Validator numberCheck(std::string description, std::function<bool(double)> accept, std::string expected) {
  return CLI::Validator(
      [accept, expected](std::string& text) -> std::string {
        double value = 0;
        if (!CLI::detail::lexical_cast(text, value)) return fmt::format("expected a number, got '{}'", text);
        return accept(value) ? std::string() : fmt::format("must be {} (got {})", expected, text);
      },
      std::move(description));
}

}  // namespace

CLI::Validator positive() { return numberCheck("POSITIVE", [](double v) { return v > 0; }, "positive"); }
CLI::Validator nonNegative() { return numberCheck("NON-NEGATIVE", [](double v) { return v >= 0; }, "0 or more"); }
CLI::Validator between(double low, double high) {
  return numberCheck(fmt::format("IN [{}, {}]", low, high), [=](double v) { return v >= low && v <= high; },
                     fmt::format("from {} to {}", low, high));
}

}  // namespace dynbench::cli

namespace {
int runCommandLine(int argc, char** argv) {
  using namespace dynbench;
  CLI::App app{"dynbench: dynamic benchmarks for temporal rendering (capture, convert, stats, render, "
               "discard, report).\nSee docs/cli.md for every command, docs/metrics.md for what the numbers mean.",
               "dynbench"};
  app.set_version_flag("--version", std::string("dynbench ") + kVersion);
  app.require_subcommand(0, 1);
  app.fallthrough(false);
  // Every option's help shows its default, taken from the options struct it is bound to: the
  // struct is the one place a default is written.
  app.option_defaults()->always_capture_default();
  // Warnings and errors go to standard error, so that a command's output (a Markdown table, JSON
  // on standard output) stays what it says it is when piped.
  spdlog::set_default_logger(spdlog::stderr_color_st("dynbench"));
  spdlog::set_pattern("dynbench: %l: %v");

  cli::CommandRun run;
  cli::addStatsCommand(app, run);
  cli::addCaptureCheckCommand(app, run);
  cli::addConvertCommand(app, run);
  cli::addMergeCameraCommand(app, run);
  cli::addFlythroughCommand(app, run);
  cli::addVrCameraCommand(app, run);
  cli::addRenderCommand(app, run);
  cli::addDiscardCommand(app, run);
  cli::addReportCommand(app, run);
  cli::addCaptureCommand(app, run);
  cli::addCompareCommand(app, run);
  cli::addFidelityCommand(app, run);
  cli::addEvaluateCommand(app, run);
  cli::addMapLightsCommand(app, run);
  cli::addDemoCommand(app, run);
  cli::addSuiteCommand(app, run);

  // `dynbench help [COMMAND]`
  std::string helpTopic;
  auto* help = app.add_subcommand("help", "Show help for dynbench or for one command");
  help->add_option("command", helpTopic, "The command to explain");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end parsing with a "success" exception.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    // Any other: a usage error, with the same status in every command (docs/cli.md).
    std::cerr << "dynbench: error: " << e.what() << "\n(`dynbench help COMMAND` lists the options)\n";
    return static_cast<int>(ErrorCode::kUsage);
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
  Expected<void> result;
  try {
    result = run();
  } catch (const std::exception& e) {
    // Library code returns errors as values; an exception reaching here is a bug.
    std::cerr << "dynbench: internal error (please report it): " << e.what() << "\n";
    return static_cast<int>(ErrorCode::kInternal);
  }
  if (!result) {
    std::cerr << "dynbench: error: " << result.error().message << "\n";
    return cli::exitCode(result.error());
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  // Every object of the command has been destroyed and every output file closed and renamed by
  // now. What is left are the libraries' static objects, and OpenImageIO 2.4's teardown of them
  // crashed (SIGSEGV in the destructor of an unordered_map in libOpenImageIO's .bss, run by
  // exit()) after a `fidelity` that had written all its results. The cause was found later: the
  // maps were corrupted by parallel opens of PNGs with ICC profiles (src/core/image_io_oiio.cpp
  // now serialises them). The process still ends without running the libraries' destructors,
  // with the status the command decided: nothing of ours depends on them. Under AddressSanitizer
  // it returns normally, so that LeakSanitizer still checks at exit.
  const int status = runCommandLine(argc, argv);
#if defined(__SANITIZE_ADDRESS__)
  return status;
#else
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(status);
#endif
}
