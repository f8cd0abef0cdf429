// Engine agreement (run by hand; not part of the test suite):
//   build/release/bench/bench_agreement FRAMES_A FRAMES_B
// For every frame the two folders share, prints the mean luminance (cd/m2, Rec. 709 weights) of
// direct, indirect and their sum in each, and B / A. Used to compare `--engine embree` with
// `--engine cycles` renders of the same frames (docs/feature-buffers.md, "Agreement with Cycles").
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "core/math.h"
#include "frames/frame_io.h"

using namespace dynbench;

namespace {

struct Means {
  double direct = 0, indirect = 0;
};

Means meansOf(const frames::FeatureFrame& f) {
  Means m;
  const std::size_t n = f.pixelCount();
  for (std::size_t i = 0; i < n; ++i) {
    m.direct += luminance(glm::dvec3(f.direct[3 * i], f.direct[3 * i + 1], f.direct[3 * i + 2]));
    m.indirect += luminance(glm::dvec3(f.indirect[3 * i], f.indirect[3 * i + 1], f.indirect[3 * i + 2]));
  }
  m.direct /= static_cast<double>(n);
  m.indirect /= static_cast<double>(n);
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_agreement FRAMES_A FRAMES_B\n");
    return 2;
  }
  auto a = frames::listFrames(argv[1]), b = frames::listFrames(argv[2]);
  if (!a || !b) {
    std::fprintf(stderr, "%s\n", (!a ? a.error() : b.error()).message.c_str());
    return 1;
  }
  std::map<long, frames::FrameEntry> inB;
  for (const auto& e : *b) inB[e.frame] = e;
  fmt::print("{:>6} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>8} {:>8} {:>8}\n", "frame", "A direct", "A indirect", "A total", "B direct",
             "B indirect", "B total", "B/A dir", "B/A ind", "B/A tot");
  for (const auto& ea : *a) {
    const auto it = inB.find(ea.frame);
    if (it == inB.end()) continue;
    auto fa = frames::readFrame(ea), fb = frames::readFrame(it->second);
    if (!fa || !fb) {
      std::fprintf(stderr, "%s\n", (!fa ? fa.error() : fb.error()).message.c_str());
      return 1;
    }
    const Means ma = meansOf(*fa), mb = meansOf(*fb);
    fmt::print("{:>6} {:>12.2f} {:>12.2f} {:>12.2f} {:>12.2f} {:>12.2f} {:>12.2f} {:>8.4f} {:>8.4f} {:>8.4f}\n", ea.frame, ma.direct, ma.indirect,
               ma.direct + ma.indirect, mb.direct, mb.indirect, mb.direct + mb.indirect, mb.direct / ma.direct, mb.indirect / ma.indirect,
               (mb.direct + mb.indirect) / (ma.direct + ma.indirect));
  }
  return 0;
}
