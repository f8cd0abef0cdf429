// What radiance-change pairs cost (run by hand; not part of the test suite):
//   build/release/bench/bench_pairs DATASET [--frames A:B] [--res WxH] [--fps N] [--max-spp N] [--max-pairs N] [--seed N]
// For each frame, in one run on the same tracer: the converged image as `render --converge` makes
// it (tolerance 0.25, up to --max-spp, default 4096: today's reference), then its radiance-change
// pairs (PathTracer::renderChanges, up to --max-pairs). Prints seconds per frame of each, their
// ratio, the pairs a pixel took and the pixels left undecided, and the machine's thread count.
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

#include <fmt/format.h>

#include "render/path_tracer.h"
#include "render/render_job.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"

using namespace dynbench;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_pairs DATASET [--frames A:B] [--res WxH] [--fps N] [--max-spp N] [--max-pairs N] [--seed N]\n");
    return 2;
  }
  render::RenderJob job;
  job.dataset = argv[1];
  job.settings.width = 160;
  job.settings.height = 90;
  job.settings.converge = true;
  job.settings.pairs = true;
  std::string frames = "40:43";
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--frames") frames = value;
    else if (key == "--res") std::sscanf(value.c_str(), "%dx%d", &job.settings.width, &job.settings.height);
    else if (key == "--fps") job.fps = std::stod(value);
    else if (key == "--max-spp") job.settings.maxSamplesPerPixel = std::stoi(value);
    else if (key == "--max-pairs") job.settings.maxPairs = std::stoi(value);
    else if (key == "--seed") job.settings.seed = static_cast<std::uint64_t>(std::stoull(value));
    else {
      std::fprintf(stderr, "bench_pairs: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  auto range = render::parseFrameRange(frames);
  if (!range) return std::fprintf(stderr, "%s\n", range.error().message.c_str()), 2;
  job.frames = *range;
  auto scene = scene::loadScene(job.dataset);
  if (!scene) return std::fprintf(stderr, "%s\n", scene.error().message.c_str()), 1;
  auto cameraNode = scene::selectCameraNode(*scene, std::nullopt);
  if (!cameraNode) return std::fprintf(stderr, "%s\n", cameraNode.error().message.c_str()), 1;
  std::vector<std::string> warnings;
  auto tracer = render::PathTracer::create(*scene, job.settings, warnings);
  if (!tracer) return std::fprintf(stderr, "%s\n", tracer.error().message.c_str()), 1;
  const scene::Evaluator evaluator(*scene);
  auto seconds = [](auto start) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  fmt::print("{} at {}x{}, {} threads; image: --converge --tolerance {} --max-spp {}; pairs: up to {}\n", job.dataset.string(),
             job.settings.width, job.settings.height, std::thread::hardware_concurrency(), job.settings.tolerance,
             job.settings.maxSamplesPerPixel, job.settings.maxPairs);
  fmt::print("{:>6} {:>10} {:>10} {:>8} {:>10} {:>10} {:>11}\n", "frame", "image s", "pairs s", "ratio", "mean spp", "mean pairs", "undecided");
  double imageTotal = 0, pairsTotal = 0;
  int count = 0;
  for (long f = job.frames.first; f <= job.frames.last; f += job.frames.step) {
    auto cameras = render::frameCameras(evaluator, *cameraNode, job, f);
    if (!cameras) return std::fprintf(stderr, "%s\n", cameras.error().message.c_str()), 1;
    if (auto ok = (*tracer)->setTime(cameras->time, cameras->previousTime); !ok) return std::fprintf(stderr, "%s\n", ok.error().message.c_str()), 1;
    auto start = std::chrono::steady_clock::now();
    render::FrameBuffers frame = (*tracer)->render(static_cast<std::uint64_t>(f), cameras->camera, cameras->previous);
    const double image = seconds(start);
    start = std::chrono::steady_clock::now();
    (*tracer)->renderChanges(static_cast<std::uint64_t>(f), cameras->camera, cameras->previous, frame);
    const double pairs = seconds(start);
    imageTotal += image;
    pairsTotal += pairs;
    ++count;
    fmt::print("{:>6} {:>10.2f} {:>10.2f} {:>8.3f} {:>10.1f} {:>10.1f} {:>10.2f}%\n", f, image, pairs, pairs / image, frame.sampling->meanSamples,
               frame.sampling->meanPairs, 100.0 * static_cast<double>(frame.sampling->undecidedPixels) / static_cast<double>(frame.pixelCount()));
  }
  if (count > 0)
    fmt::print("mean: image {:.2f} s a frame, pairs {:.2f} s a frame, pairs / image {:.3f}\n", imageTotal / count, pairsTotal / count,
               pairsTotal / imageTotal);
  return 0;
}
