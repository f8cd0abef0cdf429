// Converged rendering benchmark (run by hand; not part of the test suite):
//   build/release/bench/bench_converge DATASET [--frames A:B] [--res WxH] [--tolerance T] [--max-spp N]
// In one run: renders the frames with `--converge` for seeds 1 and 2 and measures how far apart
// their discard means are (direct and indirect, expected test); then renders at fixed spp 16, 32,
// 64, ... (seeds 1 and 2) until both columns agree at least as well, and prints the two times and
// their ratio; fixed spp counts as reached when its seeds agree as well and its means are within
// max(that agreement, 0.5) points of the converged means. Also prints the light hierarchy's cost:
// punctual lights evaluated per shading point against the frame's punctual lights (what
// evaluating every light would cost).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "core/files.h"
#include "pipeline/stages.h"
#include "render/render_job.h"

namespace fs = std::filesystem;
using namespace dynbench;

namespace {

struct Outcome {
  double seconds = 0, direct = 0, indirect = 0, meanSpp = 0;
  render::RenderStatistics light;
  std::size_t frames = 0;
};

Outcome renderAndDiscard(const render::RenderJob& base, const fs::path& out) {
  Outcome o;
  render::RenderJob job = base;
  job.output = out;
  std::error_code ec;
  fs::remove_all(out, ec);
  auto summary = pipeline::runRender({job});
  if (!summary) {
    std::fprintf(stderr, "%s\n", summary.error().message.c_str());
    std::exit(1);
  }
  pipeline::DiscardStage discard;
  discard.frames = out;
  discard.thresholds.geometryTest = discard::Thresholds::GeometryTest::kBilinear;  // the figures' form (docs/metrics.md)
  discard.thresholds.relativePosition = true;
  discard.thresholds.position = discard::kBilinearPositionThreshold;
  auto d = pipeline::runDiscard(discard);
  if (!d) {
    std::fprintf(stderr, "%s\n", d.error().message.c_str());
    std::exit(1);
  }
  o.seconds = summary->seconds;
  o.direct = d->run.mean.direct;
  o.indirect = d->run.mean.indirect;
  o.meanSpp = static_cast<double>(summary->cameraSamples) / std::max<double>(1.0, static_cast<double>(summary->pixels));
  o.light = summary->light;
  o.frames = summary->rendered.size();
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_converge DATASET [--frames A:B] [--res WxH] [--tolerance T] [--max-spp N]\n");
    return 2;
  }
  render::RenderJob job;
  job.dataset = argv[1];
  job.settings.width = 64;
  job.settings.height = 36;
  job.settings.bounces = 2;
  job.frames = {40, 47, 1};
  double tolerance = 0.25;
  int maxSpp = 4096;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--frames")) std::sscanf(argv[i + 1], "%ld:%ld", &job.frames.first, &job.frames.last);
    else if (!std::strcmp(argv[i], "--res")) std::sscanf(argv[i + 1], "%dx%d", &job.settings.width, &job.settings.height);
    else if (!std::strcmp(argv[i], "--tolerance")) tolerance = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--max-spp")) maxSpp = std::atoi(argv[i + 1]);
  }
  const fs::path work = fs::temp_directory_path() / "dynbench_bench_converge";
  fmt::print("{} frames {}-{} at {}x{}, 2 bounces; discard --relative-position, expected test\n", job.dataset.string(), job.frames.first,
             job.frames.last, job.settings.width, job.settings.height);

  render::RenderJob adaptive = job;
  adaptive.settings.converge = true;
  adaptive.settings.tolerance = tolerance;
  adaptive.settings.maxSamplesPerPixel = maxSpp;
  Outcome a[2];
  for (int s = 0; s < 2; ++s) {
    adaptive.settings.seed = static_cast<std::uint64_t>(s + 1);
    a[s] = renderAndDiscard(adaptive, work / fmt::format("converge_{}", s));
  }
  const double agreeDirect = std::abs(a[0].direct - a[1].direct), agreeIndirect = std::abs(a[0].indirect - a[1].indirect);
  const double adaptiveSeconds = a[0].seconds + a[1].seconds;
  fmt::print("converge (tolerance {}, max {} spp): {:.1f} s for two seeds, {:.0f} spp on average; direct {:.3f} / {:.3f}, indirect "
             "{:.3f} / {:.3f}; seeds differ by {:.3f} (direct) and {:.3f} (indirect) points\n",
             tolerance, maxSpp, adaptiveSeconds, a[0].meanSpp, a[0].direct, a[1].direct, a[0].indirect, a[1].indirect, agreeDirect, agreeIndirect);

  double fixedSeconds = 0;
  int reached = 0, firstAgreement = 0;
  for (int spp = 16; spp <= maxSpp; spp *= 2) {
    render::RenderJob fixed = job;
    fixed.settings.samplesPerPixel = spp;
    Outcome f[2];
    for (int s = 0; s < 2; ++s) {
      fixed.settings.seed = static_cast<std::uint64_t>(s + 1);
      f[s] = renderAndDiscard(fixed, work / fmt::format("fixed_{}_{}", spp, s));
    }
    const double dd = std::abs(f[0].direct - f[1].direct), di = std::abs(f[0].indirect - f[1].indirect);
    fmt::print("fixed {:>5} spp: {:.1f} s for two seeds; direct {:.3f} / {:.3f}, indirect {:.3f} / {:.3f} (differ by {:.3f}, {:.3f})\n", spp,
               f[0].seconds + f[1].seconds, f[0].direct, f[1].direct, f[0].indirect, f[1].indirect, dd, di);
    // The same agreement between seeds, and the same answer: fixed-spp means drift with the sample
    // count (noise moves the radiance columns), so agreeing seeds alone are not converged.
    const double meanD = 0.5 * (a[0].direct + a[1].direct), meanI = 0.5 * (a[0].indirect + a[1].indirect);
    const bool sameAnswer = std::abs(0.5 * (f[0].direct + f[1].direct) - meanD) <= std::max(agreeDirect, 0.5) &&
                            std::abs(0.5 * (f[0].indirect + f[1].indirect) - meanI) <= std::max(agreeIndirect, 0.5);
    if (dd <= agreeDirect && di <= agreeIndirect && firstAgreement == 0) firstAgreement = spp;
    if (dd <= agreeDirect && di <= agreeIndirect && sameAnswer) {
      fixedSeconds = f[0].seconds + f[1].seconds;
      reached = spp;
      break;
    }
  }
  if (firstAgreement) fmt::print("seeds first agree as well at fixed {} spp (means not yet at the converged ones)\n", firstAgreement);
  if (reached)
    fmt::print("same agreement and means within max(that, 0.5) points of the converged ones at fixed {} spp: {:.1f} s; converge is {:.2f}x cheaper\n", reached, fixedSeconds, fixedSeconds / adaptiveSeconds);
  else
    fmt::print("fixed spp up to {} did not reach the converged agreement\n", maxSpp);

  const auto& l = a[0].light;
  if (l.shadingPoints > 0 && a[0].frames > 0)
    fmt::print("light hierarchy: {:.2f} punctual lights evaluated per shading point; evaluating every light: {:.1f} per point "
               "({:.0f}x the shadow rays)\n",
               static_cast<double>(l.punctualEvaluated) / static_cast<double>(l.shadingPoints),
               static_cast<double>(l.punctualInFrame) / static_cast<double>(a[0].frames),
               static_cast<double>(l.punctualInFrame) / static_cast<double>(a[0].frames) /
                   std::max(1e-9, static_cast<double>(l.punctualEvaluated) / static_cast<double>(l.shadingPoints)));
  return 0;
}
