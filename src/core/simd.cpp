#include "core/simd.h"

#include <hwy/targets.h>

#include <mutex>

namespace dynbench::core {

void useMachineIndependentSimd() {
  static std::once_flag once;
  // Highway's x86 targets are bits below HWY_AVX2 for the wider ones (AVX3, AVX3_DL, reserved).
  std::call_once(once, [] { hwy::DisableTargets(HWY_AVX2 - 1); });
}

bool simdMatchesOtherMachines() {
  useMachineIndependentSimd();
  return (hwy::SupportedTargets() & HWY_AVX2) != 0;
}

}  // namespace dynbench::core
