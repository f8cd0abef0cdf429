#include "suite/demo.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "capture/cube2.h"
#include "capture/openarena.h"
#include "core/files.h"
#include "core/math.h"
#include "evaluate/evaluate.h"
#include "pipeline/dataset_run.h"
#include "pipeline/stages.h"

namespace dynbench::demo {

using namespace dynbench::pipeline;
namespace fs = std::filesystem;

std::string demoMap(const DemoOptions& o) {
  if (!o.map.empty()) return o.map;
  return o.engine == "openarena" ? capture::OpenArenaOptions{}.map : capture::Cube2Options{}.map;
}

Expected<fs::path> runDemo(const DemoOptions& o, const DemoLog& log) {
  const fs::path capture = o.output / "capture";
  const fs::path datasets = o.output / "datasets";
  const bool openArena = o.engine == "openarena";
  if (!openArena && o.engine != "cube2") return fail(ErrorCode::kUsage, "--engine '{}': expected cube2 or openarena", o.engine);
  const std::string map = demoMap(o);
  const fs::path bot = datasets / (map + "_bot.gltf"), fly = datasets / (map + "_flythrough.gltf");
  // The capture is reused only when it was made with the same match options (recorded beside it);
  // anything else is captured again, and every later stage follows from the newer capture, so the
  // frames rendered from it stay valid too.
  const fs::path record = capture / "dynbench-demo-capture.json";
  if (openArena) {
    capture::OpenArenaOptions c;
    c.output = capture, c.map = map, c.bots = o.bots, c.seconds = o.seconds, c.seed = o.seed;
    c.gameCpu = o.gameCpu;
    if (auto ok = captureAndConvert(c, record, bot, log); !ok) return std::unexpected(ok.error());
  } else {
    capture::Cube2Options c;
    c.output = capture, c.map = map, c.bots = o.bots, c.seconds = o.seconds, c.seed = o.seed;
    if (auto ok = captureAndConvert(c, record, bot, log); !ok) return std::unexpected(ok.error());
  }
  if (auto ok = flyThroughUnlessNewer(bot, fly, datasets / "flythrough.csv", {}, log); !ok) return std::unexpected(ok.error());

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
  r.title = fmt::format("dynbench demo: {} with {} bots ({}), first-person bot vs fly-through", map, o.bots, openArena ? "OpenArena" : "Cube 2");
  auto files = runReport(r);
  if (!files) return std::unexpected(files.error());
  log(fmt::format("report: {:.2f} MB, self-contained ({} images, {} videos inline)", files->htmlBytes / 1e6, files->images, files->videos));
  return files->html;
}

nlohmann::json demoJobJson(const DemoOptions& o) {
  nlohmann::json j = pipeline::datasetRunSettingsJson(o, true);
  j["dynbench_demo"] = kDemoJobVersion;
  j["output"] = o.output.string();
  j["engine"] = o.engine;
  j["map"] = o.map;
  j["bots"] = o.bots;
  j["seconds"] = o.seconds;
  j["game_cpu"] = capture::gameCpuName(o.gameCpu);
  return j;
}

Expected<DemoOptions> parseDemoJob(const nlohmann::json& document, const fs::path& source) {
  const JsonSettingsReader r(document, source);
  std::vector<const char*> keys = {"dynbench_demo", "output", "engine", "map", "bots", "seconds", "game_cpu"};
  for (const char* k : pipeline::datasetRunSettingsKeys(true)) keys.push_back(k);
  if (auto ok = r.jobDocument("the demo job", keys, "dynbench_demo", kDemoJobVersion); !ok) return std::unexpected(ok.error());
  DemoOptions o;
  std::string output = o.output.string(), gameCpu{capture::gameCpuName(o.gameCpu)};
  for (auto ok : {r.string("/output", output), r.string("/engine", o.engine), r.string("/map", o.map),
                  r.integer("/bots", o.bots, capture::kBotsRange.first, capture::kBotsRange.second), r.number("/seconds", o.seconds, 0.0, 1e6, true),
                  r.string("/game_cpu", gameCpu)})
    if (!ok) return std::unexpected(ok.error());
  if (o.engine != "cube2" && o.engine != "openarena") return r.bad("/engine", fmt::format("\"cube2\" or \"openarena\", found \"{}\"", o.engine));
  auto cpu = capture::parseGameCpu(gameCpu);
  if (!cpu) return r.bad("/game_cpu", fmt::format("{}, found \"{}\"", capture::gameCpuChoices(), gameCpu));
  o.gameCpu = *cpu;
  o.output = output;
  if (auto ok = pipeline::readDatasetRunSettings(r, "", o, true); !ok) return std::unexpected(ok.error());
  return o;
}

Expected<DemoOptions> readDemoJob(const fs::path& path) { return readJsonDocument(path, parseDemoJob); }

Expected<cluster::ChainOutcome> demoChain(const DemoOptions& demoIn, const cluster::Options& options,
                                                  const std::function<void(const cluster::ChainStatus&)>& progress) {
  DemoOptions demo = demoIn;
  demo.output = fs::absolute(demo.output).lexically_normal();
  cluster::ChainSpec spec;
  spec.name = "demo";
  spec.output = demo.output;
  // Every job runs the one job file.
  const fs::path jobFile = demo.output / "slurm" / "demo-job.json";
  std::error_code ec;
  fs::create_directories(jobFile.parent_path(), ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create the jobs' folder: {}", jobFile.parent_path().string(), ec.message());
  if (auto ok = writeFileAtomic(jobFile, jsonFileText(demoJobJson(demo))); !ok) return std::unexpected(ok.error());
  spec.arguments = {"--job", jobFile.string()};
  spec.frameRenders = demoFrameRenders(demo);
  spec.datasetsWhat = "capture, convert and the fly-through";
  spec.finalWhat = "the whole demo, reusing the datasets and frames: stats, discard, evaluate, report";
  spec.datasetsDone = demo.output / "datasets" / (demoMap(demo) + "_flythrough.gltf");
  spec.finalFile = demo.output / "report.html";
  return cluster::chainOfJobs(spec, options, progress);
}

}  // namespace dynbench::demo
