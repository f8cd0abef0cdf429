#include "core/runtime_files.h"

#include <cstdlib>

#include <fmt/format.h>

namespace dynbench {

namespace fs = std::filesystem;

fs::path executablePrefix() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path().parent_path();
}

std::vector<fs::path> runtimeFileCandidates(const RuntimeFile& file) {
  std::vector<fs::path> candidates;
  if (!file.environment.empty())
    if (const char* env = std::getenv(file.environment.c_str()); env && *env) candidates.emplace_back(env);
  if (const fs::path prefix = executablePrefix(); !prefix.empty()) candidates.push_back(prefix / file.installed);
  if (!file.buildTree.empty()) candidates.push_back(file.buildTree);
  return candidates;
}

Expected<fs::path> findRuntimeFile(const RuntimeFile& file) {
  std::string tried;
  for (const auto& c : runtimeFileCandidates(file)) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec)) return c;
    tried += fmt::format("{}{}", tried.empty() ? "" : ", ", c.string());
  }
  return fail(ErrorCode::kExternalTool, "cannot find {} (looked at {}{})", file.description, tried.empty() ? "nothing" : tried,
              file.environment.empty() ? "" : fmt::format("; set {} to its path", file.environment));
}

}  // namespace dynbench
