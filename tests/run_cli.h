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

namespace dynbench {

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

}  // namespace dynbench
