#pragma once
// Runs a command as another machine would (issue 45): while an OtherMachine lives, the process
// environment (which the dynbench commands and the games they start inherit) says the machine has
// a working audio device (SDL's dummy driver), llvmpipe without AVX-512 on one thread, glibc
// without its AVX2, FMA and AVX-512 code paths, and Embree's SSE4.2 kernels (DYNBENCH_EMBREE_CONFIG,
// render/raytracing_scene.cpp). A capture, a dataset and a fly-through must come out byte for byte
// the same.
#include <cstdlib>
#include <utility>
#include <vector>

namespace dynbench::test {

class OtherMachine {
 public:
  OtherMachine() {
    for (const auto& [name, value] : kVariables) ::setenv(name, value, 1);
  }
  ~OtherMachine() {
    for (const auto& [name, value] : kVariables) ::unsetenv(name);
  }
  OtherMachine(const OtherMachine&) = delete;
  OtherMachine& operator=(const OtherMachine&) = delete;

 private:
  static inline const std::vector<std::pair<const char*, const char*>> kVariables = {
      {"SDL_AUDIODRIVER", "dummy"},
      {"GALLIUM_OVERRIDE_CPU_CAPS", "avx"},
      {"LP_NUM_THREADS", "1"},
      {"DYNBENCH_EMBREE_CONFIG", "max_isa=sse4.2"},
      {"GLIBC_TUNABLES", "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F,-AVX512VL,-AVX512BW,-AVX512DQ"}};
};

}  // namespace dynbench::test
