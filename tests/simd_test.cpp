// The SIMD code paths are capped at AVX2 on every machine (core/simd.h): Highway's dispatch
// offers nothing wider once the cap is set, and this machine (every machine the project runs on
// has AVX2) runs the AVX2 paths, the ones every other such machine runs.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include "core/simd.h"

namespace dynbench::core {
namespace {

TEST(Simd, HighwayDispatchStopsAtAvx2) {
  useMachineIndependentSimd();
  const std::int64_t targets = hwy::SupportedTargets();
  EXPECT_EQ(targets & (HWY_AVX2 - 1), 0) << "a target wider than AVX2 is still offered: " << hwy::TargetName(targets & (HWY_AVX2 - 1));
  EXPECT_NE(targets & HWY_AVX2, 0) << "this machine has no AVX2: its renders differ from other machines' (docs/feature-buffers.md)";
  EXPECT_TRUE(simdMatchesOtherMachines());
  useMachineIndependentSimd();  // idempotent
  EXPECT_EQ(hwy::SupportedTargets(), targets);
}

}  // namespace
}  // namespace dynbench::core
