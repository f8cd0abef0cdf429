#include "render/cpu_estimates.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <emmintrin.h>
#endif

#include "core/checksum.h"

namespace dynbench::render {
namespace {

#if defined(__x86_64__) || defined(__i386__)
// Feeds `sha` the estimates (RCPPS, or RSQRTPS with `squareRoot`) of every float whose bits are in
// [first, last), in order, as little-endian 32-bit words.
void hashEstimates(Sha256Stream& sha, std::uint32_t first, std::uint32_t last, bool squareRoot) {
  std::vector<std::uint32_t> out(1u << 16);
  for (std::uint32_t chunk = first; chunk < last; chunk += static_cast<std::uint32_t>(out.size())) {
    const std::uint32_t count = std::min<std::uint32_t>(static_cast<std::uint32_t>(out.size()), last - chunk);
    for (std::uint32_t i = 0; i < count; i += 4) {  // count is a multiple of 4: both ranges are of 2^16s
      const std::uint32_t b = chunk + i;
      const auto lane = [b](std::uint32_t k) { return static_cast<int>(b + k); };
      const __m128 x = _mm_castsi128_ps(_mm_setr_epi32(lane(0), lane(1), lane(2), lane(3)));
      _mm_storeu_ps(reinterpret_cast<float*>(out.data() + i), squareRoot ? _mm_rsqrt_ps(x) : _mm_rcp_ps(x));
    }
    sha.update(out.data(), count * sizeof(std::uint32_t));
  }
}
#endif

}  // namespace

const std::string& reciprocalEstimates() {
  static const std::string fingerprint = [] {
#if defined(__x86_64__) || defined(__i386__)
    Sha256Stream sha;
    hashEstimates(sha, 0x3f800000u, 0x40000000u, false);  // [1, 2)
    hashEstimates(sha, 0x3f800000u, 0x40800000u, true);   // [1, 4)
    return sha.hex();
#else
    return std::string();
#endif
  }();
  return fingerprint;
}

}  // namespace dynbench::render
