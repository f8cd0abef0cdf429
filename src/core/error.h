#pragma once
// Errors as values: library code returns Expected<T> and never exits; only the CLI maps an
// ErrorCode to a process exit code (see src/cli/main.cpp and docs/cli.md).
#include <expected>
#include <string>
#include <utility>

#include <fmt/format.h>

namespace dynbench {

enum class ErrorCode {
  kInternal = 1,       // a bug: an exception escaped the library (main catches it)
  kUsage = 2,          // bad command-line arguments
  kIo = 3,             // a file could not be read or written
  kParse = 4,          // a file is not valid syntax (JSON, GLB container, OBJ, ...)
  kInvalidData = 5,    // well-formed but violates the format (glTF spec, ranges, keyframes)
  kUnsupported = 6,    // valid, but uses something dynbench does not implement
  kExternalTool = 7,   // a helper program (gnuplot) is missing or failed
  kIncomplete = 8,     // work run elsewhere (a Slurm job array) ended with results missing
};

struct Error {
  ErrorCode code;
  std::string message;  // complete sentence naming the file and location: "a.gltf: /accessors/3: ..."
};

template <typename T>
using Expected = std::expected<T, Error>;

template <typename... Args>
[[nodiscard]] std::unexpected<Error> fail(ErrorCode code, fmt::format_string<Args...> format,
                                          Args&&... args) {
  return std::unexpected(Error{code, fmt::format(format, std::forward<Args>(args)...)});
}

// Readers and writers whose many nested helpers would each have to pass an Expected up (the glTF
// reader, the capture reader, convert) may throw the one exception type, Failure, and turn it back
// into an Expected at their library function's boundary. Nothing else is thrown on purpose, and
// no exception leaves the library (the CLI's main catches any that does, as an internal error).
struct Failure {
  Error error;
};

template <typename... Args>
[[noreturn]] void raise(ErrorCode code, fmt::format_string<Args...> format, Args&&... args) {
  throw Failure{Error{code, fmt::format(format, std::forward<Args>(args)...)}};
}
[[noreturn]] inline void raise(Error error) { throw Failure{std::move(error)}; }

}  // namespace dynbench
