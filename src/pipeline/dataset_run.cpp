#include "pipeline/dataset_run.h"

#include <algorithm>

#include <fmt/format.h>

#include "convert/convert.h"
#include "maplight/cache.h"
#include "core/files.h"

namespace dynbench::pipeline {

namespace fs = std::filesystem;

namespace {

// What makes a capture: the match options, compared as text with the record beside a capture.
// Raised whenever an adapter changes what it records (Cube 2: 2: the map's normals decoded as the
// signed bytes they are; 3: lights keep their identity across frames, camera cuts), so that
// captures an older adapter made are not reused.
constexpr int kCube2AdapterVersion = 3;
constexpr int kOpenArenaAdapterVersion = 1;

std::string captureRecord(const capture::Cube2Options& c) {
  return fmt::format("{{\"map\": \"{}\", \"mode\": \"{}\", \"bots\": {}, \"skill\": {}, \"follow\": \"{}\", \"seconds\": {}, \"seed\": {}, "
                     "\"adapter\": {}}}\n",
                     c.map, c.mode, c.bots, c.skill, c.follow, c.seconds, c.seed, kCube2AdapterVersion);
}

std::string captureRecord(const capture::OpenArenaOptions& c) {
  return fmt::format("{{\"engine\": \"openarena\", \"map\": \"{}\", \"bots\": {}, \"skill\": {}, \"follow\": \"{}\", \"seconds\": {}, "
                     "\"fps\": {}, \"seed\": {}, \"game_cpu\": \"{}\", \"adapter\": {}}}\n",
                     c.map, c.bots, c.skill, c.follow, c.seconds, c.fps, c.seed, capture::gameCpuName(c.gameCpu), kOpenArenaAdapterVersion);
}

// The capture (`capture` runs the engine) unless `record` says it exists with these options, then
// the dataset unless it is newer than the capture.
template <typename Options, typename Capture>
Expected<void> captureAndConvertWith(const Options& options, const fs::path& record, const fs::path& dataset, const RunLog& log,
                                     const Capture& capture) {
  const fs::path& folder = options.output;
  const std::string wanted = captureRecord(options);
  auto recorded = readWholeFile(record);
  std::error_code ec;
  if (!(fs::exists(folder / "Capture.txt", ec) && recorded && *recorded == wanted)) {
    if (fs::exists(folder, ec)) {
      log(fmt::format("capture: {} was made with other options, capturing again", folder.string()));
      fs::remove_all(folder, ec);
      if (ec) return fail(ErrorCode::kIo, "{}: cannot remove the old capture: {}", folder.string(), ec.message());
    }
    fs::create_directories(record.parent_path(), ec);
    log(fmt::format("capture: {} s of a {}-bot match on {} (seed {})", options.seconds, options.bots, options.map, options.seed));
    if (auto ok = capture(); !ok) return ok;
    if (auto ok = writeFileAtomic(record, wanted); !ok) return std::unexpected(ok.error());
  } else {
    log(fmt::format("the capture {} exists, reused", (folder / "Capture.txt").string()));
  }
  if (!isNewerThan(dataset, folder / "Capture.txt")) {
    log("convert: capture -> " + dataset.string());
    convert::ConvertOptions convertOptions;
    convertOptions.capture = folder;
    convertOptions.output = dataset;
    if (auto converted = convert::convertCapture(convertOptions); !converted) return std::unexpected(converted.error());
  } else {
    log("convert: " + dataset.string() + " is newer than the capture, reused");
  }
  return {};
}

}  // namespace

Expected<void> captureAndConvert(const capture::Cube2Options& options, const fs::path& record, const fs::path& dataset, const RunLog& log) {
  return captureAndConvertWith(options, record, dataset, log, [&]() -> Expected<void> {
    auto captured = capture::captureCube2(options);
    if (!captured) return std::unexpected(captured.error());
    log(fmt::format("  {} frames in {:.0f} s{}", captured->frames, captured->wallSeconds,
                    captured->clientStoppedAfterCapture ? " (the client did not exit after closing the capture; stopped)" : ""));
    return {};
  });
}

Expected<void> captureAndConvert(const capture::OpenArenaOptions& options, const fs::path& record, const fs::path& dataset, const RunLog& log) {
  return captureAndConvertWith(options, record, dataset, log, [&]() -> Expected<void> {
    capture::OpenArenaOptions withLights = options;
    if (auto ok = capture::checkOpenArenaOptions(options); !ok) return std::unexpected(ok.error());
    if (withLights.mapLights.empty()) {
      auto lights = maplight::cachedAdapterLights(options.data / "baseoa", options.map, maplight::defaultCacheFolder());
      if (!lights) return std::unexpected(lights.error());
      withLights.mapLights = *lights;
    }
    auto captured = capture::captureOpenArena(withLights);
    if (!captured) return std::unexpected(captured.error());
    log(fmt::format("  {} frames in {:.0f} s{}", captured->frames, captured->wallSeconds,
                    captured->framesOffClock > 0 ? fmt::format(" ({} frames off the fixed clock: need not be the seed's capture)", captured->framesOffClock)
                                                 : ""));
    return {};
  });
}

Expected<void> flyThroughUnlessNewer(const fs::path& bot, const fs::path& fly, const fs::path& csv, const camera::FlythroughOptions& options,
                                     const RunLog& log) {
  if (isNewerThan(fly, bot)) {
    log("fly-through: " + fly.string() + " is newer than its source, reused");
    return {};
  }
  log("fly-through: a smooth camera over the same match -> " + fly.string());
  auto flown = camera::makeFlythroughDataset(bot, fly, csv, options);
  if (!flown) return std::unexpected(flown.error());
  log("  " + camera::describe(*flown));
  return {};
}

std::string methodInput(const DatasetRunSettings& settings, const std::string& method) {
  const auto named = settings.methodInputs.find(method);
  return named != settings.methodInputs.end() ? named->second : std::string(evaluate::builtForInput(method));
}

bool needsStillInput(const DatasetRunSettings& settings) {
  return std::any_of(settings.methods.begin(), settings.methods.end(),
                     [&](const std::string& m) { return methodInput(settings, m) == evaluate::kStillInput; });
}

Expected<MethodsOnTheirInputs> evaluateOnTheirInputs(const fs::path& run, const DatasetRunSettings& o,
                                                     const std::vector<std::shared_ptr<evaluate::TemporalMethod>>& extra, bool writeFiles,
                                                     const std::vector<std::shared_ptr<evaluate::TemporalMethod>>& extraStill) {
  MethodsOnTheirInputs out;
  for (const bool still : {false, true}) {
    evaluate::EvaluateOptions evaluation;
    evaluation.frames = run / (still ? "input-still" : "input");
    evaluation.reference = run / "frames";
    // The jittered input's methods as listed; the still input's after its own `none` (each
    // method's ratio is to `none` on the input it had).
    evaluation.methods.clear();
    if (still) evaluation.methods.push_back("none");
    for (const std::string& m : o.methods) {
      const bool wantsStill = methodInput(o, m) == evaluate::kStillInput;
      if (wantsStill == still && !(still && m == "none")) evaluation.methods.push_back(m);
    }
    if (still && evaluation.methods.size() == 1 && extraStill.empty()) break;  // no method asked for it
    evaluation.callerMethods = still ? extraStill : extra;
    if (writeFiles) {
      const std::string suffix = still ? "-still" : "";
      evaluation.json = run / ("evaluate" + suffix + ".json");
      evaluation.csv = run / ("evaluate" + suffix + ".csv");
      evaluation.outDir = run / ("evaluate" + suffix);
    }
    auto evaluated = evaluate::runEvaluate(evaluation);
    if (!evaluated) return std::unexpected(evaluated.error());
    (still ? out.still : out.jittered) = std::move(evaluated->methods);
  }
  return out;
}

DatasetRenders datasetRenders(const fs::path& dataset, const fs::path& run, const DatasetRunSettings& o, long animationFrames) {
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
  render.job.settings.pairs = true;  // Table 6.7's radiance columns (discard's default test)
  render.job.settings.maxPairs = o.maxPairs;
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
  input.job.settings.pairs = false;
  input.job.settings.samplesPerPixel = o.inputSamplesPerPixel;
  input.job.settings.seed = o.seed + 1;
  input.job.settings.jitter = true;
  input.job.settings.pixelFilter = {render::PixelFilterType::kCentre, 0.0};
  DatasetRenders renders{render, input, std::nullopt, std::nullopt};
  if (needsStillInput(o)) {
    // The same input without the jitter: the pixel centres every frame, what accumulation and
    // SVGF are fed in their papers.
    RenderStage still = input;
    still.job.output = run / "input-still";
    still.job.settings.jitter = false;
    renders.stillInput = still;
  }
  if (o.floorFrames > 0) {
    // The same converged reference with another seed, on floorFrames frames spread over the window
    // (every step-th from its first): two independent estimates of the same image. No pairs:
    // only its radiance is compared.
    RenderStage floor = render;
    floor.job.output = run / "floor";
    floor.job.settings.seed = o.seed + 2;
    floor.job.settings.pairs = false;
    const long window = render.job.frames.last - render.job.frames.first + 1;
    const long count = std::min<long>(window, o.floorFrames);
    floor.job.frames.step = window / count;
    floor.job.frames.last = floor.job.frames.first + floor.job.frames.step * (count - 1);
    renders.floor = floor;
  }
  return renders;
}

Expected<StatsOutcome> measureStats(const fs::path& dataset, const fs::path& run, const DatasetRunSettings& o, bool files) {
  StatsStage stats;
  stats.inputs = {dataset};
  stats.fps = o.fps;
  if (files) {
    stats.json = run / "stats.json";
    stats.seriesDir = run;
  }
  return runStats(stats);
}

Expected<DatasetRunOutcome> measureDataset(const fs::path& dataset, const fs::path& run, const DatasetRunSettings& o, const RunLog& log) {
  auto stats = measureStats(dataset, run, o, true);
  if (!stats) return std::unexpected(stats.error());
  DatasetRunOutcome outcome;
  outcome.motion = stats->rows.front().motion;
  const long frames = static_cast<long>(stats->rows.front().properties.animationFrames);
  const auto [render, input, stillInput, floor] = datasetRenders(dataset, run, o, frames);
  outcome.firstFrame = render.job.frames.first, outcome.lastFrame = render.job.frames.last;
  auto rendered = runRender(render);
  if (!rendered) return std::unexpected(rendered.error());
  log(fmt::format("  rendered {} frames ({} already there) in {:.0f} s", rendered->rendered.size(), rendered->skipped.size(), rendered->seconds));
  outcome.framesRendered = rendered->rendered.size();

  DiscardStage discard;
  discard.frames = render.job.output;
  // discard's defaults: the per-tap geometry test (docs/metrics.md), radiance relative to the frame.
  discard.json = run / "discard.json";
  discard.csv = run / "discard.csv";
  discard.masks = run / "masks";
  auto discarded = runDiscard(discard);
  if (!discarded) return std::unexpected(discarded.error());
  const auto& mean = discarded->run.mean;
  outcome.discard = mean;
  log(fmt::format("  discard: frustum {:.2f} %, world position {:.2f} %, shading normal {:.2f} %, direct {:.2f} ± {:.2f} %, indirect {:.2f} ± {:.2f} %",
                  mean.frustum, mean.position, mean.normal, mean.direct, mean.directInterval ? mean.directInterval->halfWidth() : 0.0,
                  mean.indirect, mean.indirectInterval ? mean.indirectInterval->halfWidth() : 0.0));

  // Temporal methods: each run over the input window and scored against the converged frames above.
  for (const auto& stage : {std::optional(input), stillInput})
    if (stage) {
      auto renderedInput = runRender(*stage);
      if (!renderedInput) return std::unexpected(renderedInput.error());
      outcome.framesRendered += renderedInput->rendered.size();
    }
  auto evaluated = evaluateOnTheirInputs(run, o, {}, true);
  if (!evaluated) return std::unexpected(evaluated.error());
  for (const auto* group : {&evaluated->jittered, &evaluated->still})
    for (const auto& m : *group)
      log(fmt::format("  {} ({} spp {} input): FLIP {:.4f} ± {:.4f}, PSNR {:.2f} dB, history use {:.3f}", m.name, o.inputSamplesPerPixel,
                      group == &evaluated->still ? evaluate::kStillInput : evaluate::kJitteredInput, m.flip.mean, m.flip.standardError,
                      m.psnr.mean, m.historyUse.mean));
  outcome.methods = std::move(*evaluated);
  if (floor) {
    auto renderedFloor = runRender(*floor);
    if (!renderedFloor) return std::unexpected(renderedFloor.error());
    outcome.framesRendered += renderedFloor->rendered.size();
    auto noise = evaluate::referenceNoiseFloor(render.job.output, floor->job.output);
    if (!noise) return std::unexpected(noise.error());
    outcome.referenceFloor = *noise;
    // Beside the scores, for `report` (evaluate::readNoiseFloorJson).
    if (auto ok = evaluate::writeNoiseFloorJson(run / "floor.json", *noise, o.seed, o.seed + 2); !ok) return std::unexpected(ok.error());
    log(fmt::format("  the reference's noise floor (seed {} against {}, {} frames): ꟻLIP {:.4f}", o.seed + 2, o.seed, noise->count, noise->mean));
  }
  return outcome;
}


Expected<void> renderTask(const std::vector<DatasetJob>& datasets, int task, int perTask, const std::string& what, const RunLog& log) {
  std::vector<std::pair<RenderStage, long>> items;
  for (const DatasetJob& d : datasets) {
    auto stats = measureStats(d.dataset, d.run, d.settings, false);
    if (!stats) return std::unexpected(stats.error());
    const auto renders = datasetRenders(d.dataset, d.run, d.settings, static_cast<long>(stats->rows.front().properties.animationFrames));
    for (const RenderStage* stage : {&renders.reference, &renders.input, renders.stillInput ? &*renders.stillInput : nullptr,
                                     renders.floor ? &*renders.floor : nullptr})
      if (stage)
        for (long f = stage->job.frames.first; f <= stage->job.frames.last; f += stage->job.frames.step) items.emplace_back(*stage, f);
  }
  const std::size_t first = static_cast<std::size_t>(task) * static_cast<std::size_t>(perTask);
  const std::size_t last = std::min(items.size(), first + static_cast<std::size_t>(perTask));
  if (first >= items.size()) log(fmt::format("render task {}: nothing to render ({} has {} frame renders)", task, what, items.size()));
  for (std::size_t i = first; i < last;) {
    std::size_t j = i;
    while (j + 1 < last && items[j + 1].first.job.output == items[i].first.job.output) ++j;
    RenderStage chunk = items[i].first;
    chunk.job.stepFrom = chunk.job.frames.first;  // the whole range's stepping, so the whole job's bytes
    chunk.job.frames.first = items[i].second;
    chunk.job.frames.last = items[j].second;
    auto rendered = runRender(chunk);
    if (!rendered) return std::unexpected(rendered.error());
    log(fmt::format("render task {}: {} frames {}-{}: {} rendered, {} already complete", task, chunk.job.output.string(), chunk.job.frames.first,
                    chunk.job.frames.last, rendered->rendered.size(), rendered->skipped.size()));
    i = j + 1;
  }
  return {};
}

nlohmann::json datasetRunSettingsJson(const DatasetRunSettings& s, bool all) {
  nlohmann::json j = {{"width", s.width},   {"height", s.height},   {"frames", s.renderFrames},          {"spp", s.samplesPerPixel},
                      {"max_spp", s.maxSamplesPerPixel}, {"bounces", s.bounces}, {"input_spp", s.inputSamplesPerPixel}, {"tolerance", s.tolerance},
                      {"fps", s.fps}, {"floor_frames", s.floorFrames}};
  if (all) {
    j["max_pairs"] = s.maxPairs;
    j["methods"] = s.methods;
    j["seed"] = s.seed;
    j["threads"] = s.threads;
  }
  return j;
}

const std::vector<const char*>& datasetRunSettingsKeys(bool all) {
  static const std::vector<const char*> manifest = {"width", "height", "frames", "spp", "max_spp", "bounces", "input_spp", "tolerance", "fps",
                                                    "floor_frames"};
  static const std::vector<const char*> every = [] {
    auto keys = manifest;
    keys.insert(keys.end(), {"max_pairs", "methods", "seed", "threads"});
    return keys;
  }();
  return all ? every : manifest;
}

Expected<void> readDatasetRunSettings(const JsonSettingsReader& r, const std::string& prefix, DatasetRunSettings& s, bool all) {
  for (auto ok : {r.integer(prefix + "/width", s.width, 8, 7680), r.integer(prefix + "/height", s.height, 8, 4320),
                  r.integer(prefix + "/frames", s.renderFrames, 2, 100000), r.integer(prefix + "/spp", s.samplesPerPixel, 1, 1 << 20),
                  r.integer(prefix + "/max_spp", s.maxSamplesPerPixel, 1, 1 << 20), r.integer(prefix + "/bounces", s.bounces, 0, 64),
                  r.integer(prefix + "/input_spp", s.inputSamplesPerPixel, 1, 1 << 20), r.number(prefix + "/tolerance", s.tolerance, 1e-4, 10.0),
                  r.number(prefix + "/fps", s.fps, 1.0, 1000.0), r.integer(prefix + "/floor_frames", s.floorFrames, 0, 100000)})
    if (!ok) return ok;
  if (s.maxSamplesPerPixel < s.samplesPerPixel) return r.bad(prefix + "/max_spp", "at least " + prefix + "/spp");
  if (!all) return {};
  for (auto ok : {r.integer(prefix + "/max_pairs", s.maxPairs, 4, 1 << 20), r.integer(prefix + "/seed", s.seed, 0, 4294967295LL),
                  r.integer(prefix + "/threads", s.threads, 0, 4096)})
    if (!ok) return ok;
  if (r.has(prefix + "/methods")) {
    auto methods = r.strings(prefix + "/methods");
    if (!methods) return std::unexpected(methods.error());
    if (methods->empty()) return r.bad(prefix + "/methods", "a non-empty array of method names");
    s.methods = *methods;
  }
  return {};
}

}  // namespace dynbench::pipeline
