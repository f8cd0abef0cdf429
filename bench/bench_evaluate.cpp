// bench_evaluate [--res WxH] [--flip-tool PATH]: the time of each image metric and of each temporal
// method per frame (default 1920x1080, the size the ꟻLIP authors quote), on this machine's cores.
// With --flip-tool (the authors' C++ `flip`, built by hand from NVlabs/flip: it is not a
// dependency), times it on the same images in the same run and prints the ratio.
//
// The images are synthetic: a textured, lit pattern with HDR highlights and per-pixel noise, as a
// low-sample render is; the frames are a static camera over a plane (motion 0), so every method
// keeps its history and runs its full path.
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <thread>

#include <glm/gtc/matrix_transform.hpp>

#include "core/image_io.h"
#include "core/process.h"
#include "discard/discard.h"
#include "evaluate/compare.h"
#include "evaluate/image_metrics.h"
#include "evaluate/method.h"
#include "frames/frame_io.h"

using namespace dynbench;
using namespace dynbench::evaluate;
namespace fs = std::filesystem;

namespace {

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The median of three timed runs, in milliseconds.
template <typename F>
double timeMs(F&& f) {
  double t[3];
  for (double& v : t) {
    const auto start = std::chrono::steady_clock::now();
    f();
    v = 1000.0 * seconds(start);
  }
  std::sort(t, t + 3);
  return t[1];
}

frames::FeatureFrame syntheticFrame(int w, int h, long index, double noise) {
  frames::FeatureFrame f;
  f.frame = index;
  f.resize(w, h);
  frames::FrameCamera& c = f.camera;
  c.view = glm::lookAt(glm::dvec3(0.0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
  c.world = glm::inverse(c.view);
  c.projection = glm::perspective(glm::radians(60.0), static_cast<double>(w) / h, 0.1, 100.0);
  c.width = w, c.height = h;
  std::mt19937 rng(static_cast<std::uint32_t>(index));
  std::normal_distribution<double> n(0.0, 1.0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const glm::dvec3 d = reprojection::pixelDirection(c, x + 0.5, y + 0.5);
      const glm::dvec3 p = d * (5.0 / -d.z);
      const double texture = 0.5 + 0.4 * std::sin(0.05 * x) * std::cos(0.07 * y), light = (x / 64 + y / 64) % 5 == 0 ? 20.0 : 1.0;
      for (int k = 0; k < 3; ++k) {
        f.position[3 * i + k] = static_cast<float>(p[k]);
        f.normal[3 * i + k] = k == 2 ? 1.0f : 0.0f;
        f.albedo[3 * i + k] = static_cast<float>(texture);
        f.direct[3 * i + k] = static_cast<float>(std::max(0.0, texture * light * (1.0 + noise * n(rng))));
      }
      f.depth[i] = 5.0f, f.id[i] = 0.0f, f.hit[i] = 1.0f;
    }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  int w = 1920, h = 1080;
  std::string flipTool, windowDir;
  int windowFrames = 48;
  std::string onlyMethod;  // --method NAME: time that method alone (for perf)
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--res" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%dx%d", &w, &h) != 2) return std::fprintf(stderr, "bench_evaluate: --res WxH\n"), 2;
    } else if (a == "--flip-tool" && i + 1 < argc) {
      flipTool = argv[++i];
    } else if (a == "--method" && i + 1 < argc) {
      onlyMethod = argv[++i];
    } else if (a == "--write-window" && i + 1 < argc) {
      windowDir = argv[++i];
      if (i + 1 < argc && std::isdigit(static_cast<unsigned char>(argv[i + 1][0]))) windowFrames = std::atoi(argv[++i]);
    } else {
      return std::fprintf(stderr, "usage: bench_evaluate [--res WxH] [--flip-tool PATH] [--method NAME] [--write-window DIR [FRAMES]]\n"), 2;
    }
  }
  if (!windowDir.empty()) {
    // A window for timing `dynbench evaluate` by hand (old and new builds on the same files):
    // DIR/reference (noise-free) and DIR/input (noisy) synthetic frames 0..FRAMES-1.
    for (int k = 0; k < windowFrames; ++k)
      for (const auto& [folder, noise] : {std::pair{"reference", 0.0}, std::pair{"input", 0.5}}) {
        frames::FeatureFrame f = syntheticFrame(w, h, 100 + k, noise);
        f.frame = k, f.time = k / 24.0;
        if (auto ok = frames::writeFrame(fs::path(windowDir) / folder, f, {{"engine", "bench_evaluate synthetic"}, {"noise", noise}}); !ok)
          return std::fprintf(stderr, "bench_evaluate: %s\n", ok.error().message.c_str()), 1;
      }
    std::printf("wrote %d frames of %dx%d to %s/reference and %s/input\n", windowFrames, w, h, windowDir.c_str(), windowDir.c_str());
    return 0;
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  std::printf("bench_evaluate: %dx%d, %u cores; median of 3 runs, ms per frame (core-ms = ms x cores)\n\n", w, h, cores);

  const frames::FeatureFrame refFrame = syntheticFrame(w, h, 1, 0.0), testFrame = syntheticFrame(w, h, 2, 0.5);
  auto row = [&](const char* name, double ms) { std::printf("%-28s %10.1f %10.0f\n", name, ms, ms * cores); };
  if (onlyMethod.empty()) {
    const RgbImage ref = frameRadiance(refFrame), test = frameRadiance(testFrame);
    const double scale = displayScale(ref);
    const RgbImage refLdr = toDisplay(ref, scale), testLdr = toDisplay(test, scale);
    // LDR-ꟻLIP takes linear values in [0, 1]: the display images decoded from sRGB.
    auto linear = [](RgbImage img) {
      for (std::size_t p = 0; p < img.pixelCount(); ++p) {
        const glm::dvec3 c = flip::srgbToLinear(glm::dvec3(img.rgb[3 * p], img.rgb[3 * p + 1], img.rgb[3 * p + 2]));
        for (int k = 0; k < 3; ++k) img.rgb[3 * p + k] = static_cast<float>(c[k]);
      }
      return img;
    };
    const RgbImage refLinearLdr = linear(refLdr), testLinearLdr = linear(testLdr);
    const double ppd = flip::defaultPixelsPerDegree();
    const int exposures = flip::hdrExposureRange(ref).count;

    std::printf("%-28s %10s %10s\n", "metric", "ms", "core-ms");
    const double ldrMs = timeMs([&] { (void)flip::ldrFlip(refLinearLdr, testLinearLdr, ppd); });
    row("LDR-FLIP", ldrMs);
    const double hdrMs = timeMs([&] { (void)flip::hdrFlip(ref, test, ppd); });
    row(fmt::format("HDR-FLIP ({} exposures)", exposures).c_str(), hdrMs);
    row("display transform (x2)", timeMs([&] { (void)toDisplay(ref, scale), (void)toDisplay(test, scale); }));
    row("PSNR", timeMs([&] { (void)psnr(refLdr, testLdr); }));
    row("SSIM", timeMs([&] { (void)ssim(refLdr, testLdr); }));
    row("relMSE", timeMs([&] { (void)relMse(ref, test); }));
    row("SMAPE", timeMs([&] { (void)smape(ref, test); }));
    std::printf("\nauthors' published C++ tool (32 cores): LDR-FLIP 86 ms = %.0f core-ms, HDR-FLIP 1179 ms = %.0f core-ms\n", 86.0 * 32,
                1179.0 * 32);
    std::printf("dynbench / authors' published, per core: LDR %.2fx, HDR %.2fx\n", ldrMs * cores / (86.0 * 32), hdrMs * cores / (1179.0 * 32));

    if (!flipTool.empty()) {
      // The same images through the authors' tool, in this run: PNG for LDR, EXR for HDR.
      const fs::path dir = fs::temp_directory_path() / "bench_evaluate_flip";
      fs::create_directories(dir);
      auto save = [&](const fs::path& p, const RgbImage& img) {
        FloatImage f;
        f.width = img.width, f.height = img.height, f.channels = 3, f.pixels = img.rgb, f.channelNames = {"R", "G", "B"};
        if (auto ok = writeImage(p, f); !ok) std::fprintf(stderr, "%s\n", ok.error().message.c_str());
      };
      save(dir / "ref.png", refLdr), save(dir / "test.png", testLdr), save(dir / "ref.exr", ref), save(dir / "test.exr", test);
      for (const auto& [mode, ours, r, t] : {std::tuple{"LDR", ldrMs, "ref.png", "test.png"}, std::tuple{"HDR", hdrMs, "ref.exr", "test.exr"}}) {
        double evaluation = -1.0;
        std::string meanText;
        auto run = runProcess({.argv = {flipTool, "-r", (dir / r).string(), "-t", (dir / t).string(), "-d", dir.string()},
                               .environment = {},
                               .workingDirectory = dir,
                               .onLine = [&](std::string_view line) {
                                 if (auto at = line.find("Evaluation time: "); at != std::string_view::npos)
                                   evaluation = 1000.0 * std::stod(std::string(line.substr(at + 17)));
                                 if (auto at = line.find("Mean: "); at != std::string_view::npos) meanText = std::string(line.substr(at + 6));
                                 return true;
                               }});
        if (!run || evaluation < 0) {
          std::printf("%s: the authors' tool did not report an evaluation time\n", mode);
          continue;
        }
        // Our error map's mean in double, and summed pixel by pixel in 32-bit float as the authors'
        // pooling does (FLIPPooling::pooling<float>): the float sum's rounding is what separates
        // the two means in the 6th digit.
        // (The files as written, read back as `dynbench compare` reads them: 8-bit PNG, half EXR.)
        auto refFile = loadImage(dir / r), testFile = loadImage(dir / t);
        if (!refFile || !testFile) return std::fprintf(stderr, "bench_evaluate: cannot read back %s\n", r), 1;
        const std::vector<float> error = std::string(mode) == "LDR" ? flip::ldrFlip(refFile->linear, testFile->linear, ppd)
                                                                    : flip::hdrFlip(refFile->linear, testFile->linear, ppd).error;
        float floatSum = 0.0f;
        for (float e : error) floatSum += e;
        std::printf("%s-FLIP, authors' tool on this machine: %.1f ms (mean %s); dynbench / authors' = %.2fx; dynbench's mean %.6f (%.6f summed in float)\n",
                    mode, evaluation, meanText.c_str(), ours / evaluation, flip::pool(error).mean, floatSum / static_cast<float>(error.size()));
      }
    }

  }
  std::printf("\n%-28s %10s %10s\n", "method (per frame)", "ms", "core-ms");
  MethodContext context;
  context.sceneSize = discard::sceneSize(refFrame);
  // Steady state: the timed frames follow five frames of history (SVGF's variance then comes from
  // its temporal moments). SVGF also right after a cut, where the variance is estimated spatially.
  for (const char* name : {"none", "accumulate", "taa", "svgf"}) {
    if (!onlyMethod.empty() && onlyMethod != name) continue;
    auto method = createMethod(name, context);
    if (!method) return 1;
    for (long k = 0; k < 5; ++k) (void)(*method)->process(syntheticFrame(w, h, 3 + k, 0.5));
    const frames::FeatureFrame next = syntheticFrame(w, h, 8, 0.5);
    row(name, timeMs([&] { (void)(*method)->process(next); }));
    if (std::string(name) == "svgf") {
      double t[3];
      for (double& v : t) {
        (*method)->reset();
        (void)(*method)->process(next);
        const auto start = std::chrono::steady_clock::now();
        (void)(*method)->process(next);
        v = 1000.0 * seconds(start);
      }
      std::sort(t, t + 3);
      row("svgf, 2nd frame after a cut", t[1]);
    }
  }
  return 0;
}
