#include "pipeline/demo.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "convert/convert.h"
#include "core/files.h"
#include "core/math.h"
#include "evaluate/evaluate.h"
#include "pipeline/dataset_run.h"
#include "pipeline/flythrough.h"
#include "pipeline/stages.h"

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

}  // namespace

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
    auto flown = flythrough::makeFlythroughDataset(bot, fly, datasets / "flythrough.csv");
    if (!flown) return std::unexpected(flown.error());
    log("  " + flythrough::describe(*flown));
  } else {
    log("fly-through: " + fly.string() + " is newer than its source, reused");
  }

  if (o.part == DemoPart::kDatasets) return fly;

  if (o.part == DemoPart::kRenderTask) {
    std::vector<DatasetJob> datasets;
    for (const fs::path& dataset : {bot, fly}) datasets.push_back({dataset, o.output / "runs" / dataset.stem(), o});
    if (auto ok = renderTask(datasets, o.renderTask, o.framesPerTask, "the demo", log); !ok) return std::unexpected(ok.error());
    return o.output;
  }

  std::vector<fs::path> runs;
  for (const auto& [name, dataset] : {std::pair{"first-person bot", bot}, std::pair{"fly-through", fly}}) {
    const fs::path run = o.output / "runs" / dataset.stem();
    log(fmt::format("{}: stats, render ({}x{}, {} frames, converged to tolerance {} with {}-{} spp, {} bounces, {} fps), discard -> {}", name,
                    o.width, o.height, o.renderFrames, o.tolerance, o.samplesPerPixel, o.maxSamplesPerPixel, o.bounces, o.fps, run.string()));
    if (auto ok = measureDataset(dataset, run, static_cast<const DatasetRunSettings&>(o), log); !ok) return std::unexpected(ok.error());
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
