// Engine agreement (run by hand; not part of the test suite):
//   build/release/bench/bench_agreement FRAMES_A FRAMES_B [--png DIR]
// For every frame the two folders share, prints the mean luminance (cd/m2, Rec. 709 weights) of
// direct, indirect and their sum in each, and B / A. --png writes DIR/frame_NNNNN.png per frame:
// A's direct, B's direct, A's indirect, B's indirect side by side, each pair at the exposure that
// maps A's mean to middle grey (Reinhard's c / (1 + c), gamma 1/2.2), to see where they differ. Used to compare `--engine embree` with
// `--engine cycles` renders of the same frames (docs/feature-buffers.md, "Agreement with Cycles").
// Then, for two renders of one estimator's expectation (e.g. two light selections, issue 68), per
// frame and for direct and indirect: the mean over pixels of the luminance difference d = B - A,
// its standard error sqrt(sum d^2) / N (pixels are sampled independently, and where A and B have
// the same expectation E[d^2] is the variance of d), z = mean / standard error (|z| < 3: the same
// image within their noise), and the mean of |d| beside the mean luminance of A.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/image_io.h"
#include "core/math.h"
#include "frames/frame_io.h"

using namespace dynbench;

namespace {

struct Means {
  double direct = 0, indirect = 0;
};

// The difference test for one buffer (3 floats per pixel) of two frames of one size.
struct Difference {
  double mean = 0, standardError = 0, meanAbsolute = 0;
};
Difference differenceOf(const std::vector<float>& a, const std::vector<float>& b, std::size_t pixels) {
  double sum = 0, sumSquares = 0, sumAbsolute = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const double d = luminance(glm::dvec3(b[3 * i], b[3 * i + 1], b[3 * i + 2])) - luminance(glm::dvec3(a[3 * i], a[3 * i + 1], a[3 * i + 2]));
    sum += d;
    sumSquares += d * d;
    sumAbsolute += std::abs(d);
  }
  const double n = static_cast<double>(pixels);
  return {sum / n, std::sqrt(sumSquares) / n, sumAbsolute / n};
}

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

// Pastes `buffer` (3 floats per pixel) tone-mapped at `exposure` into panel `panel` of a strip.
void paste(FloatImage& strip, int panel, const frames::FeatureFrame& f, const std::vector<float>& buffer, double exposure) {
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double v = exposure * buffer[3 * (static_cast<std::size_t>(y) * f.width + x) + c];
        strip.pixels[3 * (static_cast<std::size_t>(y) * strip.width + panel * f.width + x) + c] =
            static_cast<float>(std::pow(v / (1.0 + v), 1.0 / 2.2));
      }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3 && !(argc == 5 && std::string(argv[3]) == "--png")) {
    std::fprintf(stderr, "usage: bench_agreement FRAMES_A FRAMES_B [--png DIR]\n");
    return 2;
  }
  const std::filesystem::path pngDir = argc == 5 ? argv[4] : "";
  if (!pngDir.empty()) std::filesystem::create_directories(pngDir);
  auto a = frames::listFrames(argv[1]), b = frames::listFrames(argv[2]);
  if (!a || !b) {
    std::fprintf(stderr, "%s\n", (!a ? a.error() : b.error()).message.c_str());
    return 1;
  }
  std::map<long, frames::FrameEntry> inB;
  for (const auto& e : *b) inB[e.frame] = e;
  std::vector<std::string> differences;
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
    if (fa->width == fb->width && fa->height == fb->height)
      for (const bool direct : {true, false}) {
        const Difference d = differenceOf(direct ? fa->direct : fa->indirect, direct ? fb->direct : fb->indirect, fa->pixelCount());
        differences.push_back(fmt::format("{:>6} {:>9} {:>12.4f} {:>12.4f} {:>8.2f} {:>12.4f} {:>12.4f}", ea.frame, direct ? "direct" : "indirect", d.mean,
                                          d.standardError, d.mean / std::max(d.standardError, 1e-300), d.meanAbsolute,
                                          direct ? ma.direct : ma.indirect));
      }
    if (!pngDir.empty() && fa->width == fb->width && fa->height == fb->height) {
      FloatImage strip{4 * fa->width, fa->height, 3, std::vector<float>(static_cast<std::size_t>(12) * fa->pixelCount()), {}};
      const double directExposure = 0.18 / std::max(1e-12, ma.direct), indirectExposure = 0.18 / std::max(1e-12, ma.indirect);
      paste(strip, 0, *fa, fa->direct, directExposure);
      paste(strip, 1, *fb, fb->direct, directExposure);
      paste(strip, 2, *fa, fa->indirect, indirectExposure);
      paste(strip, 3, *fb, fb->indirect, indirectExposure);
      if (auto w = writeImage(pngDir / fmt::format("frame_{:05d}.png", ea.frame), strip); !w) {
        std::fprintf(stderr, "%s\n", w.error().message.c_str());
        return 1;
      }
    }
  }
  if (!differences.empty()) {
    fmt::print("\n{:>6} {:>9} {:>12} {:>12} {:>8} {:>12} {:>12}\n", "frame", "buffer", "mean B-A", "std. error", "z", "mean |B-A|", "A mean");
    for (const auto& line : differences) fmt::print("{}\n", line);
  }
  return 0;
}
