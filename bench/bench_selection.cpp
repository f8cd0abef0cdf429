// References at a suite's budget with one light selection or another (run by hand; not part of the
// test suite; issue 68's comparison):
//   build/release/bench/bench_selection --frames A:B [--res WxH] [--spp N] [--max-spp N] [--tolerance T]
//                                       [--bounces N] [--max-pairs N] DATASET:SELECTION[@K] [DATASET:SELECTION[@K] ...]
// SELECTION is `tree` (the light tree's importance alone) or `learned` (render/light_visibility.h);
// K is RenderSettings::everyLightUpTo (every light in reach where at most K reach; 0: always
// sample lights_per_point, as before), by default render's.
// Defaults: v2's budget (320x180, 16 to 128 paths, tolerance 0.5, 2 bounces, pairs up to 64 a pixel). For each
// configuration, in one run: the converged reference of the frames as a suite renders it (seed 1,
// with its radiance-change pairs), then the same frames with seed 3 and no pairs (the suite's floor
// render), and prints seconds per frame of each, the share of pixels that stopped at the path cap,
// the mean paths per pixel, and the noise floor (evaluate::referenceNoiseFloor: mean ꟻLIP between
// the two, as suite.md's floor), and the Monte Carlo efficiency 1 / (floor^2 x seconds per frame of
// the reference) relative to the first configuration. Say which CPU the figures came from.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/machine.h"
#include "evaluate/evaluate.h"
#include "pipeline/stages.h"

namespace fs = std::filesystem;
using namespace dynbench;

namespace {

struct Configuration {
  fs::path dataset;
  bool learned = true;
  int everyLightUpTo = render::kEveryLightUpTo;
};

render::RenderSummary renderOrExit(const render::RenderJob& job) {
  std::error_code ec;
  fs::remove_all(job.output, ec);
  pipeline::RenderStage stage;
  stage.job = job;
  auto summary = pipeline::runRender(stage);
  if (!summary) {
    std::fprintf(stderr, "bench_selection: %s\n", summary.error().message.c_str());
    std::exit(1);
  }
  return *summary;
}

}  // namespace

int main(int argc, char** argv) {
  render::RenderJob job;
  job.settings.width = 320;
  job.settings.height = 180;
  job.settings.samplesPerPixel = 16;
  job.settings.maxSamplesPerPixel = 128;
  job.settings.tolerance = 0.5;
  job.settings.bounces = 2;
  job.settings.converge = true;
  job.settings.maxPairs = 64;
  bool framesGiven = false;
  std::vector<Configuration> configurations;
  for (int i = 1; i < argc; ++i) {
    const bool hasValue = i + 1 < argc;
    if (!std::strcmp(argv[i], "--frames") && hasValue) framesGiven = std::sscanf(argv[++i], "%ld:%ld", &job.frames.first, &job.frames.last) == 2;
    else if (!std::strcmp(argv[i], "--res") && hasValue) std::sscanf(argv[++i], "%dx%d", &job.settings.width, &job.settings.height);
    else if (!std::strcmp(argv[i], "--spp") && hasValue) job.settings.samplesPerPixel = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--max-spp") && hasValue) job.settings.maxSamplesPerPixel = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--tolerance") && hasValue) job.settings.tolerance = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--bounces") && hasValue) job.settings.bounces = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--max-pairs") && hasValue) job.settings.maxPairs = std::atoi(argv[++i]);
    else {
      const std::string arg = argv[i];
      const auto colon = arg.rfind(':');
      std::string selection = colon == std::string::npos ? std::string() : arg.substr(colon + 1);
      int everyLightUpTo = render::kEveryLightUpTo;
      if (const auto at = selection.find('@'); at != std::string::npos) {
        char* end = nullptr;
        everyLightUpTo = static_cast<int>(std::strtol(selection.c_str() + at + 1, &end, 10));
        if (*end != '\0' || everyLightUpTo < 0) selection.clear();
        else selection.resize(at);
      }
      const auto learned = render::parseLightSelection(selection);
      if (!learned) {
        std::fprintf(stderr, "bench_selection: %s: expected DATASET:tree or DATASET:learned, optionally with @K (K >= 0)\n", arg.c_str());
        return 2;
      }
      configurations.push_back({arg.substr(0, colon), *learned, everyLightUpTo});
    }
  }
  if (!framesGiven || configurations.empty()) {
    std::fprintf(stderr, "usage: bench_selection --frames A:B [--res WxH] [--spp N] [--max-spp N] [--tolerance T] [--bounces N] [--max-pairs N] DATASET:SELECTION ...\n");
    return 2;
  }
  const core::MachineInfo machine = core::machineInfo();
  const long frames = job.frames.last - job.frames.first + 1;
  fmt::print("{}, {} threads; frames {}-{} at {}x{}, {} to {} paths, tolerance {}, {} bounces\n", machine.cpu, machine.threads, job.frames.first,
             job.frames.last, job.settings.width, job.settings.height, job.settings.samplesPerPixel, job.settings.maxSamplesPerPixel,
             job.settings.tolerance, job.settings.bounces);
  fmt::print("{:<44} {:>8} {:>9} {:>8} {:>7} {:>9} {:>8} {:>10}\n", "dataset:selection", "ref s/f", "floor s/f", "capped", "paths", "floor", "±", "efficiency");
  const fs::path work = fs::temp_directory_path() / "dynbench_bench_selection";
  double firstEfficiency = 0;
  for (std::size_t c = 0; c < configurations.size(); ++c) {
    render::RenderJob reference = job;
    reference.dataset = configurations[c].dataset;
    reference.settings.learnedLightSelection = configurations[c].learned;
    reference.settings.everyLightUpTo = configurations[c].everyLightUpTo;
    reference.settings.seed = 1;
    reference.settings.pairs = true;
    reference.output = work / fmt::format("{}_reference", c);
    render::RenderJob floor = reference;
    floor.settings.seed = 3;
    floor.settings.pairs = false;
    floor.output = work / fmt::format("{}_floor", c);
    const render::RenderSummary a = renderOrExit(reference), b = renderOrExit(floor);
    auto noise = evaluate::referenceNoiseFloor(reference.output, floor.output);
    if (!noise) {
      std::fprintf(stderr, "bench_selection: %s\n", noise.error().message.c_str());
      return 1;
    }
    const double perFrame = (a.seconds - a.loadSeconds) / static_cast<double>(frames);
    const double efficiency = 1.0 / (noise->mean * noise->mean * perFrame);
    if (c == 0) firstEfficiency = efficiency;
    const std::string name = fmt::format("{}:{}@{}", configurations[c].dataset.filename().string() == "bot.gltf"
                                                      ? configurations[c].dataset.parent_path().filename().string()
                                                      : configurations[c].dataset.filename().string(),
                                         render::lightSelectionName(configurations[c].learned), configurations[c].everyLightUpTo);
    fmt::print("{:<44} {:>8.2f} {:>9.2f} {:>7.1f}% {:>7.1f} {:>9.4f} {:>8.4f} {:>9.2f}x\n", name.size() > 44 ? name.substr(name.size() - 44) : name, perFrame,
               (b.seconds - b.loadSeconds) / static_cast<double>(frames), 100.0 * static_cast<double>(a.cappedPixels) / static_cast<double>(a.pixels),
               static_cast<double>(a.cameraSamples) / static_cast<double>(a.pixels), noise->mean, 1.96 * noise->standardError, efficiency / firstEfficiency);
  }
  fmt::print("floor: mean ꟻLIP of the reference against its seed-3 render, ± its 95 % half-width; efficiency 1 / (floor² · ref s/f), "
             "relative to the first line\n");
  return 0;
}
