#pragma once
// What Embree's rays take from the CPU beyond IEEE arithmetic. x86 leaves the results of RCPPS and
// RSQRTPS to each CPU (the SDM bounds only their relative error, 1.5 x 2^-12); Intel's and AMD's
// differ, and Embree refines them by one Newton step in its traversal and triangle tests, so a CPU
// that estimates otherwise can move a rare hit by an ulp and a pixel with it. Every other SIMD path
// is capped at AVX2 (core/simd.h), so two machines whose estimates agree trace the same bits.
// Here, not in core: core and the map-light fit must hold no such instruction
// (TriangleBvh.TheFitsCodeHasNoInstructionAVendorDecides).
#include <string>

namespace dynbench::render {

// SHA-256 of this CPU's estimates: RCPPS of every float in [1, 2) and RSQRTPS of every float in
// [1, 4), their bits in order ("" on a CPU without them). An estimate of x 2^k is taken to be that
// of x scaled (the tables are indexed by the mantissa, the square root's also by the exponent's
// parity; Machine.ReciprocalEstimatesFingerprintTheCpusTables checks it on a sample), so these 25
// million inputs stand for all. Computed once per process (about 0.1 s).
const std::string& reciprocalEstimates();

}  // namespace dynbench::render
