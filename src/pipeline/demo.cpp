#include "pipeline/demo.h"

#include <cmath>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "convert/convert.h"
#include "convert/merge_camera.h"
#include "core/files.h"
#include "core/math.h"
#include "evaluate/evaluate.h"
#include "pipeline/stages.h"
#include "scene/evaluate.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace dynbench::demo {

using namespace dynbench::pipeline;
namespace {

namespace fs = std::filesystem;

// Catmull-Rom through p1..p2 with neighbours p0, p3, at s in [0, 1].
glm::dvec3 catmullRom(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return 0.5 * ((2.0 * p1) + (-p0 + p2) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s2 + (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * s3);
}

// What makes a capture: the match options. Compared as text with the record beside a capture.
// Raised whenever the Cube 2 adapter changes what it records (2: the map's normals decoded as the
// signed bytes they are), so that captures an older adapter made are not reused.
constexpr int kCaptureAdapterVersion = 2;

std::string captureKey(const DemoOptions& o) {
  return fmt::format("{{\"map\": \"{}\", \"bots\": {}, \"seconds\": {}, \"seed\": {}, \"adapter\": {}}}\n", o.map, o.bots, o.seconds,
                     o.seed, kCaptureAdapterVersion);
}

// stats, render, discard for one dataset into RUN.
Expected<void> measureDataset(const fs::path& dataset, const fs::path& run, const DemoOptions& o, const DemoLog& log) {
  StatsStage stats;
  stats.inputs = {dataset};
  stats.fps = o.fps;
  stats.json = run / "stats.json";
  stats.seriesDir = run;
  auto measured = runStats(stats);
  if (!measured) return std::unexpected(measured.error());

  RenderStage render;
  render.job.dataset = dataset;
  render.job.output = run / "frames";
  render.job.fps = o.fps;
  render.job.settings.width = o.width;
  render.job.settings.height = o.height;
  render.job.settings.samplesPerPixel = o.samplesPerPixel;
  render.job.settings.bounces = o.bounces;
  render.job.settings.seed = o.seed;
  render.job.settings.converge = true;
  render.job.settings.tolerance = o.tolerance;
  render.job.settings.maxSamplesPerPixel = o.maxSamplesPerPixel;
  {
    // The window: renderFrames consecutive frames around the middle of the dataset (its frame
    // count at o.fps, as stats just measured it).
    const long count = static_cast<long>(measured->rows.front().properties.animationFrames);
    const long window = std::min<long>(count, std::max(2, o.renderFrames));
    render.job.frames.first = (count - window) / 2;
    render.job.frames.last = render.job.frames.first + window - 1;
  }
  auto rendered = runRender(render);
  if (!rendered) return std::unexpected(rendered.error());
  log(fmt::format("  rendered {} frames ({} already there) in {:.0f} s", rendered->rendered.size(), rendered->skipped.size(), rendered->seconds));

  DiscardStage discard;
  discard.frames = render.job.output;
  discard.thresholds.relativePosition = true;
  discard.thresholds.position = 0.01;  // 1% of the scene's size
  discard.json = run / "discard.json";
  discard.csv = run / "discard.csv";
  discard.masks = run / "masks";
  auto discarded = runDiscard(discard);
  if (!discarded) return std::unexpected(discarded.error());
  const auto& mean = discarded->run.mean;
  log(fmt::format("  discard: frustum {:.2f} %, world position {:.2f} %, shading normal {:.2f} %, direct {:.2f} ± {:.2f} %, indirect {:.2f} ± {:.2f} %",
                  mean.frustum, mean.position, mean.normal, mean.direct, mean.directInterval ? mean.directInterval->halfWidth() : 0.0,
                  mean.indirect, mean.indirectInterval ? mean.indirectInterval->halfWidth() : 0.0));

  // Temporal methods: the same window rendered as a real-time renderer would (a few samples per
  // pixel, another seed so its noise is independent of the reference's), each method run over it
  // and scored against the converged frames above.
  RenderStage input = render;
  input.job.output = run / "input";
  input.job.settings.converge = false;
  input.job.settings.samplesPerPixel = o.inputSamplesPerPixel;
  input.job.settings.seed = o.seed + 1;
  auto renderedInput = runRender(input);
  if (!renderedInput) return std::unexpected(renderedInput.error());
  evaluate::EvaluateOptions evaluation;
  evaluation.frames = input.job.output;
  evaluation.reference = render.job.output;
  evaluation.methods = o.methods;
  evaluation.json = run / "evaluate.json";
  evaluation.csv = run / "evaluate.csv";
  evaluation.outDir = run / "evaluate";
  auto evaluated = evaluate::runEvaluate(evaluation);
  if (!evaluated) return std::unexpected(evaluated.error());
  for (const auto& m : evaluated->methods)
    log(fmt::format("  {} ({} spp input): FLIP {:.4f} ± {:.4f}, PSNR {:.2f} dB, history use {:.3f}", m.name, o.inputSamplesPerPixel, m.flip.mean,
                    m.flip.standardError, m.psnr.mean, m.historyUse.mean));
  return {};
}

}  // namespace

Expected<void> writeFlythroughCsv(const fs::path& dataset, const fs::path& csv, int keys, double rate) {
  auto scene = scene::loadScene(dataset);
  if (!scene) return std::unexpected(scene.error());
  auto cameraNode = scene::selectCameraNode(*scene, std::nullopt);
  if (!cameraNode) return std::unexpected(cameraNode.error());
  const auto range = scene->timeRange();
  if (!(range.end > range.start)) return fail(ErrorCode::kInvalidData, "{}: no animation to fly along", dataset.string());
  keys = std::max(keys, 2);
  const scene::Evaluator evaluator(*scene);
  std::vector<glm::dvec3> points;
  for (int k = 0; k < keys; ++k) {
    const double t = range.start + (range.end - range.start) * k / (keys - 1);
    points.emplace_back(evaluator.worldMatrix(*cameraNode, t)[3]);
  }
  auto position = [&](double u) {  // u in [0, keys - 1]
    const int i = std::clamp(static_cast<int>(std::floor(u)), 0, keys - 2);
    const double s = u - i;
    const auto& p0 = points[static_cast<std::size_t>(std::max(i - 1, 0))];
    const auto& p3 = points[static_cast<std::size_t>(std::min(i + 2, keys - 1))];
    return catmullRom(p0, points[static_cast<std::size_t>(i)], points[static_cast<std::size_t>(i + 1)], p3, s);
  };
  std::string out = "time,x,y,z,qx,qy,qz,qw\n";
  const int samples = std::max(2, static_cast<int>(std::ceil((range.end - range.start) * rate)) + 1);
  double yaw = 0.0;
  for (int n = 0; n < samples; ++n) {
    const double t = (range.end - range.start) * n / (samples - 1);  // evenly spaced, ending at the last key
    const double u = t / (range.end - range.start) * (keys - 1);
    const glm::dvec3 p = position(u);
    // Look along the path, level, turning at most kMaxTurn degrees per second towards the
    // horizontal tangent: a fly-through pans, it does not snap (ORCA's cameras turn slowly).
    constexpr double kMaxTurn = 30.0;
    const glm::dvec3 ahead = position(std::min(u + 0.05, static_cast<double>(keys - 1))) - position(std::max(u - 0.05, 0.0));
    if (ahead.x * ahead.x + ahead.z * ahead.z > 1e-12) {
      const double target = std::atan2(-ahead.x, -ahead.z);
      if (n == 0) yaw = target;
      const double step = kMaxTurn * kPi / 180.0 * (range.end - range.start) / (samples - 1);  // per actual sample spacing
      yaw += std::clamp(std::remainder(target - yaw, 2.0 * kPi), -step, step);
    }
    const glm::dquat q = glm::angleAxis(yaw, glm::dvec3(0, 1, 0));
    out += fmt::format("{},{},{},{},{},{},{},{}\n", t, p.x, p.y, p.z, q.x, q.y, q.z, q.w);
  }
  return writeFileAtomic(csv, out);
}

Expected<fs::path> runDemo(const DemoOptions& o, const DemoLog& log) {
  const fs::path capture = o.output / "capture";
  const fs::path datasets = o.output / "datasets";
  const fs::path bot = datasets / (o.map + "_bot.gltf"), fly = datasets / (o.map + "_flythrough.gltf");
  std::error_code ec;

  // The capture is reused only when it was made with the same match options (recorded beside it);
  // anything else is captured again, and every later stage follows from the newer capture.
  const fs::path key = capture / "dynbench-demo-capture.json";
  const std::string wanted = captureKey(o);
  auto recorded = readWholeFile(key);
  const bool reusable = fs::exists(capture / "Capture.txt", ec) && recorded && *recorded == wanted;
  if (!reusable) {
    if (fs::exists(capture, ec)) {
      log(fmt::format("capture: {} was made with other options, capturing again", capture.string()));
      fs::remove_all(capture, ec);
      if (ec) return fail(ErrorCode::kIo, "{}: cannot remove the old capture: {}", capture.string(), ec.message());
    }
    log(fmt::format("capture: {} s of a {}-bot match on {} (seed {})", o.seconds, o.bots, o.map, o.seed));
    capture::Cube2Options c;
    c.output = capture;
    c.map = o.map;
    c.bots = o.bots;
    c.seconds = o.seconds;
    c.seed = o.seed;
    auto captured = capture::captureCube2(c);
    if (!captured) return std::unexpected(captured.error());
    log(fmt::format("  {} frames in {:.0f} s", captured->frames, captured->wallSeconds));
    if (auto ok = writeFileAtomic(key, wanted); !ok) return std::unexpected(ok.error());
  } else {
    log(fmt::format("capture: {} exists, reused", (capture / "Capture.txt").string()));
  }
  // A rerun keeps what is up to date, so the frames rendered from it stay valid too.
  auto newer = [&](const fs::path& a, const fs::path& b) {
    std::error_code e1, e2;
    const auto ta = fs::last_write_time(a, e1), tb = fs::last_write_time(b, e2);
    return !e1 && !e2 && ta > tb;
  };
  if (!newer(bot, capture / "Capture.txt")) {
    log("convert: capture -> " + bot.string());
    convert::ConvertOptions convertOptions;
    convertOptions.capture = capture;
    convertOptions.output = bot;
    auto converted = convert::convertCapture(convertOptions);
    if (!converted) return std::unexpected(converted.error());
  } else {
    log("convert: " + bot.string() + " is newer than the capture, reused");
  }
  if (!newer(fly, bot)) {
    log("fly-through: a smooth camera over the same match -> " + fly.string());
    const fs::path csv = datasets / "flythrough.csv";
    if (auto ok = writeFlythroughCsv(bot, csv, o.flythroughKeys, 60.0); !ok) return std::unexpected(ok.error());
    convert::MergeCameraOptions merge;
    merge.dataset = bot;
    merge.run = csv;
    merge.output = fly;
    if (auto merged = convert::mergeCamera(merge); !merged) return std::unexpected(merged.error());
  } else {
    log("fly-through: " + fly.string() + " is newer than its source, reused");
  }

  std::vector<fs::path> runs;
  for (const auto& [name, dataset] : {std::pair{"first-person bot", bot}, std::pair{"fly-through", fly}}) {
    const fs::path run = o.output / "runs" / dataset.stem();
    log(fmt::format("{}: stats, render ({}x{}, {} frames, converged to tolerance {} with {}-{} spp, {} bounces, {} fps), discard -> {}", name,
                    o.width, o.height, o.renderFrames, o.tolerance, o.samplesPerPixel, o.maxSamplesPerPixel, o.bounces, o.fps, run.string()));
    if (auto ok = measureDataset(dataset, run, o, log); !ok) return std::unexpected(ok.error());
    runs.push_back(run);
  }
  report::ReportOptions r;
  r.runs = runs;
  r.output = o.output / "report.html";
  r.title = fmt::format("dynbench demo: {} with {} bots, first-person bot vs fly-through", o.map, o.bots);
  auto files = runReport(r);
  if (!files) return std::unexpected(files.error());
  return files->html;
}

}  // namespace dynbench::demo
