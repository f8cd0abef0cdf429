#pragma once
// Loops the metrics spend their time in, compiled for baseline x86-64 and also for x86-64-v3
// (AVX2, FMA) and v4 (AVX-512), one picked when the program loads (GCC's function multiversioning,
// in vector_loops.cpp): the build targets baseline x86-64, whose SSE2 does two doubles or four
// floats an instruction and has no fused multiply-add.
namespace dynbench::evaluate {

// dst[x] += weight x src[x] for x in [0, n): one tap of a separable filter over a row.
void addScaled(float* dst, const float* src, float weight, int n);
void addScaled(double* dst, const double* src, double weight, int n);

}  // namespace dynbench::evaluate
