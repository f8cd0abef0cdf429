#include "evaluate/vector_loops.h"

namespace dynbench::evaluate {

#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
#define DYNBENCH_VECTOR_CLONES [[gnu::target_clones("default", "arch=x86-64-v3")]]
#else
#define DYNBENCH_VECTOR_CLONES
#endif

DYNBENCH_VECTOR_CLONES void addScaled(float* dst, const float* src, float weight, int n) {
  for (int x = 0; x < n; ++x) dst[x] += weight * src[x];
}

DYNBENCH_VECTOR_CLONES void addScaled(double* dst, const double* src, double weight, int n) {
  for (int x = 0; x < n; ++x) dst[x] += weight * src[x];
}

}  // namespace dynbench::evaluate
