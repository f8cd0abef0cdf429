#include "suite/suite.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "capture/openarena.h"
#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "dynbench/version.h"
#include "camera/flythrough.h"
#include "camera/slowed.h"
#include "report/plots.h"
#include "report/stats_output.h"
#include "scene/load.h"
#include "scene/dataset_digest.h"

#include "suite/suite_markdown.h"

namespace dynbench::suite {

namespace fs = std::filesystem;
using pipeline::DatasetRunSettings;

namespace {

// Where a dataset's capture and converted datasets live: one folder per capture, shared by the
// datasets that differ only in camera.
struct CapturePlan {
  std::string key;  // the folder name, from the capture options
  bool openArena = false;
  capture::Cube2Options options;          // engine cube2
  capture::OpenArenaOptions openArenaOptions;  // engine openarena
};
Expected<CapturePlan> capturePlan(const DatasetSpec& d, const fs::path& root) {
  CapturePlan plan;
  if (d.engine == "openarena") {
    plan.openArena = true;
    capture::OpenArenaOptions& c = plan.openArenaOptions;
    if (!d.map.empty()) c.map = d.map;
    if (d.bots > 0) c.bots = d.bots;
    c.seed = d.seed;
    c.seconds = d.seconds;
    c.gameCpu = d.gameCpu;
    // host-CPU captures apart from emulated ones: they are other matches
    plan.key = fmt::format("openarena-custom-{}-{}bots-seed{}-{}s{}", c.map, c.bots, c.seed, c.seconds, d.gameCpu == capture::GameCpu::kHost ? "-host" : "");
    c.output = root / "captures" / plan.key / "capture";
    return plan;
  }
  capture::Cube2Options& c = plan.options;
  std::vector<std::string> keep;
  if (!d.map.empty()) c.map = d.map, keep.push_back("map");
  if (d.bots > 0) c.bots = d.bots, keep.push_back("bots");
  if (!d.preset.empty())
    if (auto ok = capture::applyCube2Preset(d.preset, c, keep); !ok) return std::unexpected(ok.error());
  c.seed = d.seed;
  c.seconds = d.seconds;
  plan.key = fmt::format("{}-{}-{}-{}bots-seed{}-{}s", d.engine, d.preset.empty() ? "custom" : d.preset, c.map, c.bots, c.seed, c.seconds);
  c.output = root / "captures" / plan.key / "capture";
  return plan;
}

// Where a spec's dataset lives: its capture's folder, bot.gltf, slowed.gltf or flythrough.gltf.
Expected<fs::path> datasetPath(const DatasetSpec& d, const fs::path& root) {
  auto plan = capturePlan(d, root);
  if (!plan) return std::unexpected(plan.error());
  return root / "captures" / plan->key / (d.camera + ".gltf");
}

// The dataset (bot or fly-through) for one spec, captured, converted and flown as needed.
Expected<fs::path> prepareDataset(const DatasetSpec& d, const fs::path& root, double fps, const pipeline::RunLog& log) {
  auto plan = capturePlan(d, root);
  if (!plan) return std::unexpected(plan.error());
  const fs::path folder = root / "captures" / plan->key, bot = folder / "bot.gltf";
  auto indented = [&](const std::string& line) { log("  " + line); };
  auto made = plan->openArena ? pipeline::captureAndConvert(plan->openArenaOptions, folder / "capture-options.json", bot, indented)
                              : pipeline::captureAndConvert(plan->options, folder / "capture-options.json", bot, indented);
  if (!made) return std::unexpected(made.error());
  if (d.camera == "bot") return bot;
  if (d.camera == "slowed") {
    const fs::path slowed = folder / "slowed.gltf";
    if (isNewerThan(slowed, bot)) {
      indented("slowed turns: " + slowed.string() + " is newer than its source, reused");
      return slowed;
    }
    indented("slowed turns: the bot's camera, its turns slowed -> " + slowed.string());
    auto made = camera::makeSlowedTurnsDataset(bot, slowed, folder / "slowed.csv");
    if (!made) return std::unexpected(made.error());
    indented("  " + camera::describe(*made));
    return slowed;
  }
  camera::FlythroughOptions o;
  o.frameRate = fps;  // the rate the suite renders and measures at
  const fs::path fly = folder / "flythrough.gltf";
  if (auto ok = pipeline::flyThroughUnlessNewer(bot, fly, folder / "flythrough.csv", o, indented); !ok) return std::unexpected(ok.error());
  return fly;
}

// The capture's and the dataset's digests of one prepared dataset, checked against the manifest's
// pins (dataset `index`); a mismatch names the dataset and the stage that made something else.
// `captureDigests` keeps each capture folder's digest: a bot dataset and its fly-through share one.
struct Digests {
  std::string capture, dataset;
};
Expected<Digests> checkPins(const Manifest& manifest, std::size_t index, const fs::path& dataset, const fs::path& root,
                            std::map<fs::path, std::string>& captureDigests) {
  const DatasetSpec& d = manifest.datasets[index];
  auto plan = capturePlan(d, root);
  if (!plan) return std::unexpected(plan.error());
  const fs::path captureFolder = plan->openArena ? plan->openArenaOptions.output : plan->options.output;
  auto known = captureDigests.find(captureFolder);
  if (known == captureDigests.end()) {
    auto digest = captureDigest(captureFolder);
    if (!digest) return std::unexpected(digest.error());
    known = captureDigests.emplace(captureFolder, *digest).first;
  }
  const std::string& capture = known->second;
  auto made = scene::datasetDigest(dataset);
  if (!made) return std::unexpected(made.error());
  const std::string manifestName = manifest.path.string();
  if (!d.captureSha256.empty() && capture != d.captureSha256)
    return fail(ErrorCode::kInvalidData,
                "{}: /datasets/{}/sha256/capture: dataset '{}': the capture stage made {} with SHA-256 {}, not the pinned {} (another "
                "game, game data or capture adapter than the manifest's, or a capture that does not reproduce; docs/suite.md)",
                manifestName, index, d.name, captureFolder.string(), capture, d.captureSha256);
  if (!d.datasetSha256.empty() && *made != d.datasetSha256)
    return fail(ErrorCode::kInvalidData,
                "{}: /datasets/{}/sha256/dataset: dataset '{}': the {} stage made {} with SHA-256 {}, not the pinned {} (the capture "
                "{}; docs/suite.md)",
                manifestName, index, d.name, d.camera == "bot" ? "convert" : d.camera == "slowed" ? "convert or slowed-turns" : "convert or fly-through", dataset.string(), *made,
                d.datasetSha256, d.captureSha256.empty() ? "is not pinned" : "matches its pin: convert or flythrough made another dataset");
  return Digests{capture, *made};
}

// Every dataset of the suite captured, converted and flown through as needed, and its pins
// checked: all of them before anything is rendered.
Expected<std::vector<std::pair<fs::path, Digests>>> prepareDatasets(const Manifest& manifest, const fs::path& root, double fps,
                                                                   const pipeline::RunLog& log) {
  std::vector<std::pair<fs::path, Digests>> prepared;
  std::map<fs::path, std::string> captureDigests;
  for (std::size_t i = 0; i < manifest.datasets.size(); ++i) {
    log(fmt::format("[{}/{}] {}: dataset", i + 1, manifest.datasets.size(), manifest.datasets[i].name));
    auto dataset = prepareDataset(manifest.datasets[i], root, fps, log);
    if (!dataset) return std::unexpected(dataset.error());
    auto digests = checkPins(manifest, i, *dataset, root, captureDigests);
    if (!digests) return std::unexpected(digests.error());
    const DatasetSpec& d = manifest.datasets[i];
    log(fmt::format("  sha256: capture {}{}, dataset {}{}", digests->capture, d.captureSha256.empty() ? "" : " (as pinned)", digests->dataset,
                    d.datasetSha256.empty() ? "" : " (as pinned)"));
    prepared.emplace_back(*dataset, *digests);
  }
  return prepared;
}

}  // namespace

std::vector<fs::path> recordedFiles(const fs::path& root, const fs::path& dataset, const fs::path& run) {
  std::vector<fs::path> files{fs::relative(dataset, root), fs::relative(fs::path(dataset).replace_extension(".bin"), root)};
  for (const char* folder : {"frames", "input", "input-still", "floor"}) {
    std::vector<fs::path> frames;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(run / folder, ec))
      if (entry.is_regular_file() && (entry.path().extension() == ".exr" || entry.path().extension() == ".json"))
        frames.push_back(fs::relative(entry.path(), root));
    std::sort(frames.begin(), frames.end());
    files.insert(files.end(), frames.begin(), frames.end());
  }
  return files;
}

int suiteFrameRenders(const Manifest& manifest) {
  return static_cast<int>(manifest.datasets.size()) * pipeline::datasetFrameRenders(manifest.run);
}

Expected<SuiteOutcome> runSuite(const SuiteOptions& options, const pipeline::RunLog& log) {
  auto manifest = readManifest(options.manifest);
  if (!manifest) return std::unexpected(manifest.error());
  const fs::path root = options.output;
  std::error_code ec;
  fs::create_directories(root, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create folder: {}", root.string(), ec.message());
  DatasetRunSettings settings = manifest->run;
  settings.threads = options.threads;
  SuiteOutcome outcome;
  if (options.part == SuitePart::kDatasets) {
    if (auto prepared = prepareDatasets(*manifest, root, settings.fps, log); !prepared) return std::unexpected(prepared.error());
    return outcome;
  }
  if (options.part == SuitePart::kRenderTask) {
    std::vector<pipeline::DatasetJob> jobs;
    for (const DatasetSpec& spec : manifest->datasets) {
      auto dataset = datasetPath(spec, root);
      if (!dataset) return std::unexpected(dataset.error());
      DatasetRunSettings s = settings;
      s.seed = spec.seed;
      jobs.push_back({*dataset, root / "runs" / spec.name, s});
    }
    if (auto ok = pipeline::renderTask(jobs, options.renderTask, options.framesPerTask, "the suite", log); !ok) return std::unexpected(ok.error());
    return outcome;
  }
  nlohmann::json doc = {{"dynbench_suite_results", kResultsVersion},
                        {"tool_version", kVersion},
                        {"manifest", manifest->document},
                        {"ranking_error", "flip_ratio_to_none (flip for none)"},
                        {"method_inputs", manifest->run.methodInputs},
                        {"datasets", nlohmann::json::array()},
                        {"files", nlohmann::json::object()}};
  auto prepared = prepareDatasets(*manifest, root, settings.fps, log);
  if (!prepared) return std::unexpected(prepared.error());
  // Progress: datasets done, and the time left at the mean time of the datasets this run rendered
  // (a resumed run re-reads finished datasets in seconds; they would make the estimate a guess).
  const auto start = std::chrono::steady_clock::now();
  double renderingSeconds = 0.0;
  std::size_t renderedDatasets = 0;
  for (std::size_t i = 0; i < manifest->datasets.size(); ++i) {
    const DatasetSpec& spec = manifest->datasets[i];
    const auto datasetStart = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(datasetStart - start).count();
    const std::size_t left = manifest->datasets.size() - i;
    std::string pace;
    if (i > 0 && renderedDatasets > 0) {
      const double minutesPerDataset = renderingSeconds / static_cast<double>(renderedDatasets) / 60.0;
      pace = fmt::format(" ({} done in {:.1f} min; about {:.0f} min left at the {:.0f} min a dataset this run rendered took)", i, elapsed / 60.0,
                         minutesPerDataset * static_cast<double>(left), minutesPerDataset);
    } else if (i > 0)
      pace = fmt::format(" ({} done in {:.1f} min, all rendered before this run)", i, elapsed / 60.0);
    log(fmt::format("[{}/{}] {}{}", i + 1, manifest->datasets.size(), spec.name, pace));
    const auto& [dataset, digests] = (*prepared)[i];
    const fs::path run = root / "runs" / spec.name;
    DatasetRunSettings s = settings;
    s.seed = spec.seed;
    auto measured = pipeline::measureDataset(dataset, run, s, log);
    if (!measured) return std::unexpected(measured.error());
    if (measured->framesRendered > 0) {
      renderingSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - datasetStart).count();
      ++renderedDatasets;
    }
    DatasetResult result;
    result.name = spec.name;
    result.measures = measuresOf(measured->motion, measured->firstFrame, measured->lastFrame, measured->discard);
    result.errors = errorsOf(measured->methods);
    auto plan = capturePlan(spec, root);
    if (!plan) return std::unexpected(plan.error());
    result.match = plan->key, result.camera = spec.camera;
    if (measured->referenceFloor) result.referenceFloor = measured->referenceFloor->mean, result.floorFrames = static_cast<int>(measured->referenceFloor->count);
    outcome.datasets.push_back(result);
    doc["datasets"].push_back({{"name", spec.name},
                               {"dataset", fs::relative(dataset, root).string()},
                               {"run", fs::relative(run, root).string()},
                               {"sha256", {{"capture", digests.capture}, {"dataset", digests.dataset}}},
                               {"window", {{"first", measured->firstFrame}, {"last", measured->lastFrame}}},
                               {"measures", result.measures},
                               {"errors", result.errors},
                               {"match", result.match},
                               {"camera", result.camera},
                               {"reference_floor", referenceFloorJson(result)}});
    for (const fs::path& file : recordedFiles(root, dataset, run)) {
      auto sum = sha256File(root / file);
      if (!sum) return std::unexpected(sum.error());
      doc["files"][file.string()] = *sum;
    }
  }
  outcome.validity = validity(outcome.datasets);
  doc["validity"] = validityJson(outcome.validity);
  const std::vector<WithinMatchCell> paired = withinMatches(outcome.datasets);
  doc["within_matches"] = withinMatchesJson(paired);
  outcome.json = root / "suite.json";
  outcome.markdown = root / "suite.md";
  auto md = suiteMarkdown(*manifest, outcome.datasets, outcome.validity, paired, root);
  if (!md) return std::unexpected(md.error());
  if (auto ok = writeFileAtomic(outcome.markdown, *md); !ok) return std::unexpected(ok.error());
  // suite.json last: its presence says the run is complete.
  if (auto ok = writeFileAtomic(outcome.json, jsonFileText(doc)); !ok) return std::unexpected(ok.error());
  return outcome;
}

Expected<cluster::ChainOutcome> runSuiteOnSlurm(const SuiteOptions& options, const cluster::Options& slurm,
                                                        const std::function<void(const cluster::ChainStatus&)>& progress) {
  auto manifest = readManifest(options.manifest);
  if (!manifest) return std::unexpected(manifest.error());
  const fs::path root = fs::absolute(options.output).lexically_normal();
  cluster::ChainSpec spec;
  spec.name = "suite";
  spec.output = root;
  spec.arguments = {fs::absolute(options.manifest).lexically_normal().string(), "-o", root.string()};
  spec.frameRenders = suiteFrameRenders(*manifest);
  spec.datasetsWhat = "every dataset's capture, convert and fly-through";
  spec.finalWhat = "the whole suite, reusing the datasets and frames: stats, discard, evaluate, suite.json";
  auto lastDataset = datasetPath(manifest->datasets.back(), root);
  if (!lastDataset) return std::unexpected(lastDataset.error());
  spec.datasetsDone = *lastDataset;
  spec.finalFile = root / "suite.json";
  return cluster::chainOfJobs(spec, slurm, progress);
}

}  // namespace dynbench::suite
