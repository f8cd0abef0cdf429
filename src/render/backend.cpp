#include "render/backend.h"

#include <fmt/format.h>

namespace dynbench::render {

const std::vector<BackendEntry>& renderBackends() {
  static const std::vector<BackendEntry> backends{
      {"embree", "dynbench's path tracer on Embree", &createEmbreeBackend},
      {"cycles", "Blender's Cycles (needs Debian's blender)", &createCyclesBackend},
  };
  return backends;
}

std::vector<std::string> backendNames() {
  std::vector<std::string> names;
  for (const auto& b : renderBackends()) names.emplace_back(b.name);
  return names;
}

Expected<const BackendEntry*> findBackend(const std::string& name) {
  for (const auto& b : renderBackends())
    if (name == b.name) return &b;
  return fail(ErrorCode::kUsage, "--engine '{}': expected one of {}", name, fmt::join(backendNames(), ", "));
}

}  // namespace dynbench::render
