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

Expected<const BackendEntry*> findBackend(const std::string& name) {
  std::string names;
  for (const auto& b : renderBackends()) {
    if (name == b.name) return &b;
    names += fmt::format("{}{}", names.empty() ? "" : ", ", b.name);
  }
  return fail(ErrorCode::kUsage, "--engine '{}': expected one of {}", name, names);
}

}  // namespace dynbench::render
