// The SIMD code paths are capped at AVX2 on every machine (core/simd.h): Highway's dispatch
// offers nothing wider once the cap is set, and this machine (every machine the project runs on
// has AVX2) runs the AVX2 paths, the ones every other such machine runs.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <xmmintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/checksum.h"
#include "core/machine.h"
#include "core/simd.h"
#include "render/cpu_estimates.h"

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
  std::string line, model, vendor, family, modelNumber, stepping;
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
    if (line.starts_with("cpu family") && family.empty()) family = value;
    if (key == "model" && !line.starts_with("model name") && modelNumber.empty()) modelNumber = value;
    if (key == "stepping" && stepping.empty()) stepping = value;
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
  ASSERT_FALSE(family.empty());
  EXPECT_EQ(m.family, std::stoi(family));
  EXPECT_EQ(m.model, std::stoi(modelNumber));
  EXPECT_EQ(m.stepping, std::stoi(stepping));
  EXPECT_TRUE(m.reciprocalEstimates.empty());  // render's to fill (render/cpu_estimates.h)
}

// The fingerprint of the CPU's reciprocal estimates (render/cpu_estimates.h) is the SHA-256 of RCPPS over [1, 2) and RSQRTPS
// over [1, 4), recomputed here one float at a time (RCPSS, RSQRTSS) into one buffer; each estimate
// is within the SDM's bound (relative error at most 1.5 x 2^-12); and the assumption that lets
// those inputs stand for all holds on this CPU: the estimate of x 2^k is that of x scaled.
TEST(Machine, ReciprocalEstimatesFingerprintTheCpusTables) {
  const auto rcp = [](float x) { return _mm_cvtss_f32(_mm_rcp_ss(_mm_set_ss(x))); };
  const auto rsqrt = [](float x) { return _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x))); };
  const auto fromBits = [](std::uint32_t bits) { return std::bit_cast<float>(bits); };
  std::string bytes;
  bytes.reserve((0x800000u + 0x1000000u) * 4);
  double worst = 0;
  std::size_t unscaled = 0;
  for (int squareRoot = 0; squareRoot < 2; ++squareRoot) {
    const std::uint32_t last = squareRoot ? 0x40800000u : 0x40000000u;
    for (std::uint32_t bits = 0x3f800000u; bits < last; ++bits) {
      const float x = fromBits(bits), e = squareRoot ? rsqrt(x) : rcp(x);
      const std::uint32_t out = std::bit_cast<std::uint32_t>(e);
      bytes.append(reinterpret_cast<const char*>(&out), 4);
      worst = std::max(worst, std::abs(squareRoot ? double(e) * std::sqrt(double(x)) - 1.0 : double(e) * x - 1.0));
      if (bits % 4099 != 0) continue;  // the scaling, on a sample of 2,000-odd inputs
      for (const int k : {-20, -3, 4, 30}) {
        const float scaled = std::ldexp(x, squareRoot ? 2 * k : k);
        const float expected = std::ldexp(e, -k);
        unscaled += (squareRoot ? rsqrt(scaled) : rcp(scaled)) != expected;
      }
    }
  }
  EXPECT_EQ(render::reciprocalEstimates(), sha256Text(bytes));
  EXPECT_EQ(render::reciprocalEstimates().size(), 64u);
  EXPECT_LE(worst, 1.5 * std::ldexp(1.0, -12));
  EXPECT_GT(worst, 0.0);  // estimates, not exact results
  EXPECT_EQ(unscaled, 0u);
}

}  // namespace
}  // namespace dynbench::core
