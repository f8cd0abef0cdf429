#include "pipeline/demo.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "convert/convert.h"
#include "convert/merge_camera.h"
#include "core/files.h"
#include "core/math.h"
#include "evaluate/evaluate.h"
#include "pipeline/stages.h"
#include "render/raytracing_scene.h"
#include "scene/evaluate.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace dynbench::demo {

using namespace dynbench::pipeline;
namespace {

namespace fs = std::filesystem;

// What makes a capture: the match options. Compared as text with the record beside a capture.
// Raised whenever the Cube 2 adapter changes what it records (2: the map's normals decoded as the
// signed bytes they are; 3: lights keep their identity across frames, camera cuts), so that
// captures an older adapter made are not reused.
constexpr int kCaptureAdapterVersion = 3;

std::string captureKey(const DemoOptions& o) {
  return fmt::format("{{\"map\": \"{}\", \"bots\": {}, \"seconds\": {}, \"seed\": {}, \"adapter\": {}}}\n", o.map, o.bots, o.seconds,
                     o.seed, kCaptureAdapterVersion);
}

// The two renders of a dataset: converged reference frames (RUN/frames) and the temporal methods'
// input (RUN/input), of the same window of frames around the middle of the dataset.
struct DatasetRenders {
  RenderStage reference, input;
};
DatasetRenders datasetRenders(const fs::path& dataset, const fs::path& run, const DemoOptions& o, long animationFrames) {
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
  render.job.threads = o.threads;
  {
    // The window: renderFrames consecutive frames around the middle of the dataset (its frame
    // count at o.fps, as stats measures it).
    const long window = std::min<long>(animationFrames, std::max(2, o.renderFrames));
    render.job.frames.first = (animationFrames - window) / 2;
    render.job.frames.last = render.job.frames.first + window - 1;
  }
  // The temporal methods' input: the same window rendered as a real-time renderer would: a few
  // paths per pixel from its G-buffer's hit (the pixel centre, no filter), the projection jittered
  // from frame to frame (the Halton sequence TAA needs to turn aliasing into anti-aliasing), and
  // another seed so its noise is independent of the reference's. The reference is the converged
  // radiance through the pixel filter: what a method should reconstruct.
  RenderStage input = render;
  input.job.output = run / "input";
  input.job.settings.converge = false;
  input.job.settings.samplesPerPixel = o.inputSamplesPerPixel;
  input.job.settings.seed = o.seed + 1;
  input.job.settings.jitter = true;
  input.job.settings.pixelFilter = {render::PixelFilterType::kCentre, 0.0};
  return {render, input};
}

// The dataset's frame count at o.fps (Table 6.1's), from stats; with `json`, its stats files too.
Expected<long> measureStats(const fs::path& dataset, const fs::path& run, const DemoOptions& o, bool files) {
  StatsStage stats;
  stats.inputs = {dataset};
  stats.fps = o.fps;
  if (files) {
    stats.json = run / "stats.json";
    stats.seriesDir = run;
  }
  auto measured = runStats(stats);
  if (!measured) return std::unexpected(measured.error());
  return static_cast<long>(measured->rows.front().properties.animationFrames);
}

// stats, render, discard for one dataset into RUN.
Expected<void> measureDataset(const fs::path& dataset, const fs::path& run, const DemoOptions& o, const DemoLog& log) {
  auto frames = measureStats(dataset, run, o, true);
  if (!frames) return std::unexpected(frames.error());
  const auto [render, input] = datasetRenders(dataset, run, o, *frames);
  auto rendered = runRender(render);
  if (!rendered) return std::unexpected(rendered.error());
  log(fmt::format("  rendered {} frames ({} already there) in {:.0f} s", rendered->rendered.size(), rendered->skipped.size(), rendered->seconds));

  DiscardStage discard;
  discard.frames = render.job.output;
  // discard's defaults: the per-tap geometry test (docs/metrics.md), radiance relative to the frame.
  discard.json = run / "discard.json";
  discard.csv = run / "discard.csv";
  discard.masks = run / "masks";
  auto discarded = runDiscard(discard);
  if (!discarded) return std::unexpected(discarded.error());
  const auto& mean = discarded->run.mean;
  log(fmt::format("  discard: frustum {:.2f} %, world position {:.2f} %, shading normal {:.2f} %, direct {:.2f} ± {:.2f} %, indirect {:.2f} ± {:.2f} %",
                  mean.frustum, mean.position, mean.normal, mean.direct, mean.directInterval ? mean.directInterval->halfWidth() : 0.0,
                  mean.indirect, mean.indirectInterval ? mean.indirectInterval->halfWidth() : 0.0));

  // Temporal methods: each run over the input window and scored against the converged frames above.
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

namespace {

// Linear interpolation along a polyline by arc length s (clamped to its ends).
struct Polyline {
  std::vector<glm::dvec3> points;
  std::vector<double> arc;  // cumulative length at each point
  explicit Polyline(std::vector<glm::dvec3> p) : points(std::move(p)) {
    arc.assign(points.size(), 0.0);
    for (std::size_t k = 1; k < points.size(); ++k) arc[k] = arc[k - 1] + glm::length(points[k] - points[k - 1]);
  }
  double length() const { return arc.empty() ? 0.0 : arc.back(); }
  glm::dvec3 at(double s) const {
    if (points.size() == 1 || s <= 0) return points.front();
    if (s >= length()) return points.back();
    const auto k = static_cast<std::size_t>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin()) - 1;
    const double span = arc[k + 1] - arc[k];
    return span > 0 ? glm::mix(points[k], points[k + 1], (s - arc[k]) / span) : points[k];
  }
};

// Moving average over +-half samples. kKeepEnds: the window shrinks symmetrically at the ends, so
// the first and last values stay where they are (a path keeps its ends); kHoldEnds: the values
// beyond the ends are the end values held, so the ends are as smooth as the middle (a heading).
enum class Ends { kKeep, kHold };
template <typename T>
std::vector<T> movingAverage(const std::vector<T>& v, std::size_t half, Ends ends) {
  const std::size_t n = v.size();
  // Prefix sums over v padded with `half` held values on each side.
  std::vector<T> prefix(n + 2 * half + 1, T(0));
  for (std::size_t k = 0; k < n + 2 * half; ++k) prefix[k + 1] = prefix[k] + v[std::clamp(k, half, half + n - 1) - half];
  std::vector<T> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t h = ends == Ends::kKeep ? std::min({half, k, n - 1 - k}) : half;
    out[k] = (prefix[k + half + h + 1] - prefix[k + half - h]) / static_cast<double>(2 * h + 1);
  }
  return out;
}

}  // namespace

Expected<FlythroughReport> writeFlythroughCsv(const fs::path& dataset, const fs::path& csv, const FlythroughOptions& o) {
  auto scene = scene::loadScene(dataset);
  if (!scene) return std::unexpected(scene.error());
  auto cameraNode = scene::selectCameraNode(*scene, std::nullopt);
  if (!cameraNode) return std::unexpected(cameraNode.error());
  if (*cameraNode < 0) return fail(ErrorCode::kInvalidData, "{}: no camera to fly along", dataset.string());
  const auto range = scene->timeRange();
  const double duration = range.end - range.start;
  if (!(duration > 0)) return fail(ErrorCode::kInvalidData, "{}: no animation to fly along", dataset.string());
  const auto& node = scene->nodes[static_cast<std::size_t>(*cameraNode)];
  const scene::Evaluator evaluator(*scene);
  const std::size_t samples = std::max<std::size_t>(2, static_cast<std::size_t>(std::ceil(duration * o.rate)) + 1);
  auto poseTime = [&](std::size_t n) { return duration * static_cast<double>(n) / static_cast<double>(samples - 1); };  // from the start
  auto timeAt = [&](std::size_t n) { return range.start + poseTime(n); };

  // The bot's longest stretch (by distance) between camera cuts.
  FlythroughReport report;
  std::vector<glm::dvec3> best, current;
  std::size_t currentStart = 0;
  auto closeStretch = [&](std::size_t end) {
    const double length = Polyline(current).length();
    if (length > report.stretchLength || best.empty()) {
      best = current;
      report.stretchLength = length;
      report.stretchStart = timeAt(currentStart);
      report.stretchEnd = timeAt(end);
    }
  };
  for (std::size_t n = 0; n < samples; ++n) {
    if (n > 0 && scene::cameraCutBetween(node, timeAt(n - 1), timeAt(n))) {
      closeStretch(n - 1);
      current.clear();
      currentStart = n;
    }
    current.emplace_back(evaluator.worldMatrix(*cameraNode, timeAt(n))[3]);
  }
  closeStretch(samples - 1);
  const Polyline stretch(best);
  const double unitSpeed = o.speed / o.metresPerUnit;

  // The stretch resampled every scene unit, then smoothed as widely as keeps the path out of walls.
  std::vector<glm::dvec3> even;
  for (double s = 0; s < stretch.length(); s += 1.0) even.push_back(stretch.at(s));
  even.push_back(stretch.at(stretch.length()));  // the stretch's own end
  if (even.size() < 2) even.push_back(even.back());
  auto walls = render::StaticGeometry::create(*scene);  // built once for every width tried
  if (!walls) return std::unexpected(walls.error());
  std::optional<Polyline> path;
  std::vector<glm::dvec3> positions(samples);
  for (double width : {64.0, 32.0, 16.0, 8.0, 4.0, 0.0}) {
    Polyline candidate(movingAverage(even, static_cast<std::size_t>(width / 2), Ends::kKeep));
    report.length = std::min(candidate.length(), unitSpeed * duration);  // smoothing shortens the path
    for (std::size_t n = 0; n < samples; ++n) positions[n] = candidate.at(report.length * poseTime(n) / duration);
    // The chords the renderer's frames make (dataset frame rate) as well as the poses' own.
    std::vector<glm::dvec3> frames;
    for (double t = 0; t <= duration + 1e-9; t += 1.0 / o.frameRate) frames.push_back(candidate.at(report.length * t / duration));
    const auto crossPoses = walls->segmentsThrough(positions), crossFrames = walls->segmentsThrough(frames);
    report.smoothing = width;
    path.emplace(std::move(candidate));
    if (crossPoses.empty() && crossFrames.empty()) break;
    if (width == 0.0)
      return fail(ErrorCode::kInvalidData, "{}: the bot's own path crosses static geometry ({} segments); no fly-through made", dataset.string(),
                  crossPoses.size() + crossFrames.size());
  }

  // Heading: towards the path lookAhead further on, level but for half the path's slope (at most
  // 10 degrees); yaw and pitch then averaged over a window that widens until their per-frame
  // changes at frameRate are within the ORCA bounds.
  const double ahead = o.lookAhead / o.metresPerUnit;
  std::vector<double> rawYaw(samples), rawPitch(samples);
  for (std::size_t n = 0; n < samples; ++n) {
    const double s = report.length * poseTime(n) / duration;
    glm::dvec3 d = path->at(s + ahead) - path->at(s);
    if (glm::length(glm::dvec2(d.x, d.z)) < 1e-6) d = path->at(s) - path->at(std::max(0.0, s - ahead));
    const double horizontal = glm::length(glm::dvec2(d.x, d.z));
    double yaw = horizontal > 1e-6 ? std::atan2(-d.x, -d.z) : (n > 0 ? rawYaw[n - 1] : 0.0);
    if (n > 0) yaw = rawYaw[n - 1] + std::remainder(yaw - rawYaw[n - 1], 2.0 * kPi);  // unwrapped
    rawYaw[n] = yaw;
    rawPitch[n] = std::clamp(0.5 * std::atan2(d.y, std::max(horizontal, 1e-6)), -radians(10.0), radians(10.0));
  }
  std::vector<double> yaw, pitch;
  // Mean and variance of |change| per frame at frameRate, the poses interpolated linearly.
  auto perFrame = [&](const std::vector<double>& angle) {
    std::vector<double> changes;
    auto at = [&](double t) {
      const double u = std::clamp(t / duration, 0.0, 1.0) * static_cast<double>(samples - 1);
      const auto k = std::min(static_cast<std::size_t>(u), samples - 2);
      return angle[k] + (u - static_cast<double>(k)) * (angle[k + 1] - angle[k]);
    };
    for (double t = 1.0 / o.frameRate; t <= duration + 1e-9; t += 1.0 / o.frameRate)
      changes.push_back(std::abs(degrees(at(t) - at(t - 1.0 / o.frameRate))));
    double mean = 0, variance = 0;
    for (double c : changes) mean += c / static_cast<double>(changes.size());
    for (double c : changes) variance += (c - mean) * (c - mean) / static_cast<double>(changes.size());
    return std::pair{mean, variance};
  };
  // Yaw and pitch each get the narrowest window (in steps of 10 %) that meets their bounds, so they
  // keep as much of the path's motion as ORCA's cameras have.
  auto smooth = [&](const std::vector<double>& raw, double maxMean, double maxVariance, std::vector<double>& out, double& window, double& mean,
                    double& variance) {
    for (window = 1.0;; window *= 1.1) {
      out = movingAverage(raw, static_cast<std::size_t>(0.5 * window * o.rate), Ends::kHold);
      std::tie(mean, variance) = perFrame(out);
      if ((mean <= maxMean && variance <= maxVariance) || window > duration) return;
    }
  };
  smooth(rawYaw, o.maxYawMean, o.maxYawVariance, yaw, report.headingWindow, report.yawMean, report.yawVariance);
  smooth(rawPitch, o.maxPitchMean, o.maxPitchVariance, pitch, report.pitchWindow, report.pitchMean, report.pitchVariance);
  std::string out = "time,x,y,z,qx,qy,qz,qw\n";
  for (std::size_t n = 0; n < samples; ++n) {
    const glm::dquat q = glm::angleAxis(yaw[n], glm::dvec3(0, 1, 0)) * glm::angleAxis(pitch[n], glm::dvec3(1, 0, 0));
    const glm::dvec3& p = positions[n];
    out += fmt::format("{},{},{},{},{},{},{},{}\n", poseTime(n), p.x, p.y, p.z, q.x, q.y, q.z, q.w);
  }
  report.poses = samples;
  report.speed = report.length / duration;
  if (auto ok = writeFileAtomic(csv, out); !ok) return std::unexpected(ok.error());
  return report;
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
    log(fmt::format("  {} frames in {:.0f} s{}", captured->frames, captured->wallSeconds,
                    captured->clientStoppedAfterCapture ? " (the client did not exit after closing the capture; stopped)" : ""));
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
    auto flown = writeFlythroughCsv(bot, csv);
    if (!flown) return std::unexpected(flown.error());
    log(fmt::format("  along the bot's path from {:.2f} s to {:.2f} s (no cut between), {:.0f} of its {:.0f} units at {:.2f} units/s, "
                    "smoothed over {:.0f} units, heading over {:.2f} s, pitch over {:.2f} s: yaw {:.3f} (variance {:.3f}), pitch {:.3f} ({:.4f}) degrees per frame",
                    flown->stretchStart, flown->stretchEnd, flown->length, flown->stretchLength, flown->speed,
                    flown->smoothing, flown->headingWindow, flown->pitchWindow, flown->yawMean, flown->yawVariance, flown->pitchMean, flown->pitchVariance));
    convert::MergeCameraOptions merge;
    merge.dataset = bot;
    merge.run = csv;
    merge.output = fly;
    if (auto merged = convert::mergeCamera(merge); !merged) return std::unexpected(merged.error());
  } else {
    log("fly-through: " + fly.string() + " is newer than its source, reused");
  }

  if (o.part == DemoPart::kDatasets) return fly;

  if (o.part == DemoPart::kRenderTask) {
    // Item i of the demo's renders (dataset, then reference before input, then frame), and task k
    // renders items k*F .. k*F+F-1, grouped by render into frame ranges.
    std::vector<std::pair<RenderStage, long>> items;
    for (const fs::path& dataset : {bot, fly}) {
      const fs::path run = o.output / "runs" / dataset.stem();
      auto frames = measureStats(dataset, run, o, false);
      if (!frames) return std::unexpected(frames.error());
      const auto renders = datasetRenders(dataset, run, o, *frames);
      for (const RenderStage* stage : {&renders.reference, &renders.input})
        for (long f = stage->job.frames.first; f <= stage->job.frames.last; ++f) items.emplace_back(*stage, f);
    }
    const std::size_t first = static_cast<std::size_t>(o.renderTask) * static_cast<std::size_t>(o.framesPerTask);
    const std::size_t last = std::min(items.size(), first + static_cast<std::size_t>(o.framesPerTask));
    if (first >= items.size()) log(fmt::format("render task {}: nothing to render (the demo has {} frame renders)", o.renderTask, items.size()));
    for (std::size_t i = first; i < last;) {
      std::size_t j = i;
      while (j + 1 < last && items[j + 1].first.job.output == items[i].first.job.output) ++j;
      RenderStage chunk = items[i].first;
      chunk.job.frames.first = items[i].second;
      chunk.job.frames.last = items[j].second;
      auto rendered = runRender(chunk);
      if (!rendered) return std::unexpected(rendered.error());
      log(fmt::format("render task {}: {} frames {}-{}: {} rendered, {} already complete", o.renderTask, chunk.job.output.string(),
                      chunk.job.frames.first, chunk.job.frames.last, rendered->rendered.size(), rendered->skipped.size()));
      i = j + 1;
    }
    return o.output;
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
  log(fmt::format("report: {:.2f} MB, self-contained ({} images, {} videos inline)", files->htmlBytes / 1e6, files->images, files->videos));
  return files->html;
}

}  // namespace dynbench::demo
