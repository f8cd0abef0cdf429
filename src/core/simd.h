#pragma once
// The same SIMD code paths on every machine dynbench runs on (x86-64 with AVX2: the brief's
// machines have AVX2, some also AVX-512). Embree, Highway and GCC's function clones each pick
// their kernels for the CPU at run time; on an AVX-512 machine they picked AVX-512 ones, whose
// ray-triangle tests round hit distances differently: half the pixels of a 160x90 render of
// oa_dm1 differed between Embree's AVX-512 and AVX2 kernels (depth, position, radiance), so every
// render-derived number (Table 6.7's radiance columns, method scores) was a property of the
// machine. Capped at AVX2 (with FMA), every such machine runs the same instructions. A machine
// without AVX2 falls back to SSE4.2 kernels and gets other bytes (docs/feature-buffers.md).

namespace dynbench::core {

// Embree's device configuration (rtcNewDevice(3)) for every scene rays are traced in, unless
// DYNBENCH_EMBREE_CONFIG gives another.
inline constexpr const char* kEmbreeDeviceConfig = "max_isa=avx2";

// Caps Highway's run-time dispatch at AVX2 (hwy::DisableTargets of every wider x86 target). Call
// before the first HWY_DYNAMIC_DISPATCH of a code path; cheap and idempotent.
void useMachineIndependentSimd();

// Whether this machine runs the AVX2 code paths (it has AVX2 and FMA), i.e. the bytes every
// other such machine makes.
bool simdMatchesOtherMachines();

}  // namespace dynbench::core
