#pragma once
// The one way dynbench finds files it needs at run time (the image module, the Blender scripts, the
// Cube 2 client): an environment variable naming the file, then where `cmake --install` puts it
// relative to the executable (PREFIX/bin/dynbench -> PREFIX/lib/dynbench/..., PREFIX/share/dynbench/...),
// then where the build made it (running from the build tree).
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench {

struct RuntimeFile {
  std::string description;          // for errors: "the Blender script render_cycles.py"
  std::string environment;          // variable that overrides the search, e.g. DYNBENCH_BLENDER_SCRIPT
  std::filesystem::path installed;  // relative to the install prefix, e.g. share/dynbench/blender/render_cycles.py
  std::filesystem::path buildTree;  // absolute path in the build or source tree; may be empty
};

// Every place the file may be, in search order (existing or not).
std::vector<std::filesystem::path> runtimeFileCandidates(const RuntimeFile& file);
// The first candidate that exists, or an error (kExternalTool) naming the places looked at.
Expected<std::filesystem::path> findRuntimeFile(const RuntimeFile& file);
// The install prefix of the running executable: the folder above the one it is in.
std::filesystem::path executablePrefix();

}  // namespace dynbench
