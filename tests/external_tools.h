#pragma once
// The external programs some tests need, each detected in one place. Each function returns an
// empty string when the tool is there, else why not and how to install it. A test that needs one
// uses DYNBENCH_NEEDS(...): it skips when the tool is missing, unless DYNBENCH_REQUIRE_ALL=1 (set
// by .ci/run), where it fails, so CI can never pass by skipping Cube 2, Blender or Chromium.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "capture/cube2.h"
#include "capture/openarena.h"

namespace dynbench::test {

inline bool onPath(const char* program) {
  return std::system((std::string("command -v ") + program + " >/dev/null 2>&1").c_str()) == 0;
}

inline std::string missingBlender() {
  return onPath("blender") ? "" : "Blender is not installed (Debian packages blender and python3-numpy; scripts/setup.sh --all)";
}
inline std::string missingChromium() {
  return onPath("chromium") ? "" : "Chromium is not installed (Debian package chromium; scripts/setup.sh --all)";
}
inline std::string missingFfmpeg() {
  return onPath("ffmpeg") ? "" : "ffmpeg is not installed (Debian package ffmpeg; scripts/setup.sh)";
}
inline std::string missingSlurm() {
  for (const char* program : {"/usr/sbin/slurmctld", "/usr/sbin/slurmd", "/usr/sbin/munged"})
    if (!std::filesystem::exists(program)) return "Slurm is not installed (Debian packages slurm-wlm and munge; scripts/setup.sh --all)";
  return onPath("sbatch") ? "" : "sbatch is not on PATH (Debian package slurm-client; scripts/setup.sh --all)";
}
inline std::string missingGltfValidator() {
  if (!onPath("node")) return "node is not installed (Debian package nodejs; scripts/setup.sh --all)";
  const auto validator = std::filesystem::path(DYNBENCH_SOURCE_DIR) / "tools/gltf-validator/node_modules/gltf-validator";
  return std::filesystem::exists(validator) ? "" : "the Khronos glTF validator is not installed (scripts/setup.sh --all runs npm ci)";
}
inline std::string missingCube2() {
  if (!capture::findCube2Client({})) return "the Cube 2 client is not built (scripts/setup.sh, then cmake --build)";
  if (!std::filesystem::exists("/usr/share/games/cube2/packages/base/colos.ogz")) return "Debian's cube2-data is not installed";
  if (!onPath("Xvfb")) return "Xvfb is not installed (Debian package xvfb)";
  return {};
}

inline std::string missingOpenArena() {
  if (!capture::findOpenArenaModules({})) return "OpenArena's game modules are not built (scripts/setup.sh --all, then cmake --build)";
  if (!std::filesystem::exists("/usr/lib/ioquake3/ioquake3") || !std::filesystem::exists("/usr/lib/openarena/baseoa"))
    return "Debian's openarena is not installed (scripts/setup.sh --all)";
  if (!onPath("Xvfb")) return "Xvfb is not installed (Debian package xvfb)";
  return {};
}

// OpenArena's default, --game-cpu emulated, runs the engine under qemu-x86_64.
inline std::string missingEmulatedOpenArena() {
  if (auto missing = missingOpenArena(); !missing.empty()) return missing;
  return onPath("qemu-x86_64") ? "" : "qemu-x86_64 is not installed (Debian package qemu-user; scripts/setup.sh --all)";
}

inline bool requireAll() {
  const char* v = std::getenv("DYNBENCH_REQUIRE_ALL");
  return v && std::string(v) == "1";
}

}  // namespace dynbench::test

#define DYNBENCH_NEEDS(missing)                                                                            \
  do {                                                                                                     \
    const std::string dynbenchMissing_ = (missing);                                                        \
    if (!dynbenchMissing_.empty()) {                                                                       \
      if (::dynbench::test::requireAll()) FAIL() << dynbenchMissing_ << " (DYNBENCH_REQUIRE_ALL=1: no skips)"; \
      GTEST_SKIP() << dynbenchMissing_;                                                                    \
    }                                                                                                      \
  } while (0)
