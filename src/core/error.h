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

// The two lexer-based readers (the glTF loader's JSON walk, scene/load_gltf.cpp, and the capture's
// record lexer, capture/record_lexer.h) throw the one exception type, Failure, from the field
// accessors every record parser calls (a number, a field count, a JSON pointer), and turn it back
// into an Expected at their library function's boundary: with an Expected from each accessor, each
// of nearly 300 field reads would need its own check, and a parser that forgot one would read on
// from a default. Everything else returns Expected (convert and the writers did throw until
// 2026-11-29). Nothing else is thrown on purpose, and no exception leaves the library (the CLI's
// main catches any that does, as an internal error).
struct Failure {
  Error error;
};

template <typename... Args>
[[noreturn]] void raise(ErrorCode code, fmt::format_string<Args...> format, Args&&... args) {
  throw Failure{Error{code, fmt::format(format, std::forward<Args>(args)...)}};
}
[[noreturn]] inline void raise(Error error) { throw Failure{std::move(error)}; }

}  // namespace dynbench
