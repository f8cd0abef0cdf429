// The SIMD code paths are capped at AVX2 on every machine (core/simd.h): Highway's dispatch
// offers nothing wider once the cap is set, and this machine (every machine the project runs on
// has AVX2) runs the AVX2 paths, the ones every other such machine runs.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/machine.h"
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

// The machine a suite record names (core/machine.h): its ISA level agrees with the kernel's own list
// of the CPU's features (/proc/cpuinfo "flags", read here independently of the compiler's
// __builtin_cpu_supports that machineInfo asks), and its CPU and vendor are /proc/cpuinfo's.
TEST(Machine, IsaLevelAgreesWithTheKernelsFlags) {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model, vendor;
  std::set<std::string> flags;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, line.find_first_of(" \t:"));
    const std::string value = colon + 2 <= line.size() ? line.substr(colon + 2) : "";
    if (key == "flags" && flags.empty()) {
      std::istringstream words(value);
      for (std::string w; words >> w;) flags.insert(w);
    }
    if (key == "model" && line.starts_with("model name") && model.empty()) model = value;
    if (key == "vendor_id" && vendor.empty()) vendor = value;
  }
  ASSERT_FALSE(flags.empty()) << "/proc/cpuinfo has no flags";
  const auto all = [&](std::initializer_list<const char*> names) {
    for (const char* n : names)
      if (!flags.count(n)) return false;
    return true;
  };
  const bool v2 = all({"sse4_2", "popcnt"}), v3 = v2 && all({"avx2", "fma", "bmi2"}),
             v4 = v3 && all({"avx512f", "avx512bw", "avx512cd", "avx512dq", "avx512vl"});
  const MachineInfo m = machineInfo();
  EXPECT_EQ(m.isa, v4 ? "x86-64-v4" : v3 ? "x86-64-v3" : v2 ? "x86-64-v2" : "x86-64");
  EXPECT_EQ(m.cpu, model);
  EXPECT_EQ(m.vendor, vendor);
  EXPECT_GE(m.threads, 1);
}

}  // namespace
}  // namespace dynbench::core
