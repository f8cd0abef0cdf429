#pragma once
// The one way dynbench runs another program (Blender, the Cube 2 client under Xvfb, gnuplot): an
// argument vector (no shell, so no quoting of file names), extra environment variables, a
// working folder, stdout and stderr merged and handed over line by line, and the last few
// kilobytes kept for the error message when the program fails.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"

namespace dynbench {

struct ProcessOptions {
  std::vector<std::string> argv;  // argv[0] is looked up on PATH when it has no '/'
  std::vector<std::pair<std::string, std::string>> environment;  // added to (or replacing in) this process's
  std::filesystem::path workingDirectory;                        // empty: this process's
  // Each output line, without its '\n'; returning false stops the program (SIGTERM), e.g. after
  // the caller failed on what it printed.
  std::function<bool(std::string_view line)> onLine;
  // Asked about once a second while the program runs (and after each line); returning true stops
  // it (SIGTERM), e.g. a program that has done its work but does not exit.
  std::function<bool()> stopIf;
  std::size_t tailBytes = 4000;                                  // output kept for ProcessResult::tail
};

struct ProcessResult {
  int exitStatus = -1;  // the program's exit status, or -1 when a signal ended it
  int signal = 0;       // the signal that ended it, else 0
  std::string tail;     // the end of its output (stdout and stderr interleaved)
  bool stoppedByCaller = false;  // onLine returned false or stopIf true, and it was sent SIGTERM
  bool succeeded() const { return exitStatus == 0; }
};

// Starts the program and waits for it. Fails (kExternalTool) only when it cannot be started; a
// program that runs and fails is a result with a non-zero status, for the caller to word.
Expected<ProcessResult> runProcess(const ProcessOptions& options);

}  // namespace dynbench
