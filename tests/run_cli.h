#pragma once
// Runs the dynbench executable (DYNBENCH_EXE) for CLI tests: exit status, stdout, stderr.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace dynbench {

// The small CC0 example scene (examples/orbit, made by examples/make_orbit.py) the CLI tests render.
inline const std::filesystem::path kOrbit = std::filesystem::path(DYNBENCH_SOURCE_DIR) / "examples" / "orbit" / "orbit.gltf";

namespace test {
// A whole file's text; a missing or unreadable file is a test failure (and "" is returned), so a
// test never dereferences an empty result.
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    ADD_FAILURE() << path << ": cannot read";
    return {};
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}
}  // namespace test

// Runs a shell command; returns its exit status (-1 if it did not exit) and appends its stdout.
inline int runShell(const std::string& command, std::string& out) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buf{};
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) out.append(buf.data(), n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

namespace test {
// The Khronos glTF validator's report on a file (node + npm gltf-validator, installed by
// scripts/setup.sh); `status` gets its exit status.
inline std::string validateGltf(const std::filesystem::path& file, int& status) {
  std::string out;
  status = runShell("node " + std::string(DYNBENCH_SOURCE_DIR) + "/tools/gltf-validator/validate.mjs '" + file.string() + "' 2>&1", out);
  return out;
}

// What Blender's glTF importer makes of a dataset (tools/blender/import_gltf.py's summary), or
// null after a test failure naming its output.
inline nlohmann::json blenderImport(const std::filesystem::path& dataset) {
  std::string out;
  const int status = runShell("blender --background --factory-startup --python " + std::string(DYNBENCH_SOURCE_DIR) +
                                  "/tools/blender/import_gltf.py -- '" + dataset.string() + "' 2>&1",
                              out);
  const auto at = out.find("DYNBENCH_IMPORT ");
  if (status != 0 || at == std::string::npos) {
    ADD_FAILURE() << "blender exited " << status << ":\n" << out;
    return nullptr;
  }
  return nlohmann::json::parse(out.substr(at + 16, out.find('\n', at) - at - 16));
}
}  // namespace test

struct Run {
  int status = -1;
  std::string out, err;
};

inline Run dynbench(const std::string& args, const std::filesystem::path& dir) {
  const std::filesystem::path errFile = dir / "stderr.txt";
  const std::string cmd = std::string(DYNBENCH_EXE) + " " + args + " 2>" + errFile.string();
  Run r;
  r.status = runShell(cmd, r.out);
  std::ifstream e(errFile);
  std::stringstream ss;
  ss << e.rdbuf();
  r.err = ss.str();
  return r;
}

namespace test {
// Whether dynbench refuses `args`: exits with `status` and says `message` on stderr (for
// EXPECT_TRUE, which then reports the command, its status and its stderr).
inline testing::AssertionResult refuses(const std::string& args, const std::filesystem::path& dir, int status, const std::string& message) {
  const Run r = dynbench(args, dir);
  if (r.status != status) return testing::AssertionFailure() << "dynbench " << args << " exited " << r.status << ", not " << status << ":\n" << r.err;
  if (r.err.find(message) == std::string::npos) return testing::AssertionFailure() << "dynbench " << args << " did not say '" << message << "':\n" << r.err;
  return testing::AssertionSuccess();
}
}  // namespace test

}  // namespace dynbench
