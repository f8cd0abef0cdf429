#include "render/cpu_estimates.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
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
    for (std::uint32_t i = 0; i < count; i += 4) {
      alignas(16) std::uint32_t bits[4] = {chunk + i, chunk + i + 1, chunk + i + 2, chunk + i + 3};
      const __m128 x = _mm_load_ps(reinterpret_cast<const float*>(bits));
      _mm_store_ps(reinterpret_cast<float*>(bits), squareRoot ? _mm_rsqrt_ps(x) : _mm_rcp_ps(x));
      std::memcpy(out.data() + i, bits, sizeof bits);
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
