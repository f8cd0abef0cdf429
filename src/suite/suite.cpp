#include "suite/suite.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <utility>

#include <sys/resource.h>
#include <unistd.h>

#include <fmt/format.h>

#include "capture/cube2.h"
#include "capture/openarena.h"
#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "core/machine.h"
#include "dynbench/version.h"
#include "camera/flythrough.h"
#include "camera/slowed.h"
#include "camera/vr_head.h"
#include "capture/reader.h"
#include "report/plots.h"
#include "report/stats_output.h"
#include "render/cpu_estimates.h"
#include "scene/load.h"
#include "scene/dataset_digest.h"

#include "suite/record.h"
#include "suite/suite_markdown.h"

namespace dynbench::suite {

namespace fs = std::filesystem;
using pipeline::DatasetRunSettings;

namespace {

// Wall and CPU seconds since it was made (CPU: this process's and its waited-for children's, the
// games and Blender included).
class StageClock {
 public:
  StageClock() : wall_(std::chrono::steady_clock::now()), cpu_(cpuSeconds()) {}
  StageSeconds elapsed() const {
    return {std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count(), cpuSeconds() - cpu_};
  }

 private:
  static double cpuSeconds() {
    double total = 0.0;
    for (const int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
      rusage u{};
      if (::getrusage(who, &u) == 0)
        total += static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    }
    return total;
  }
  std::chrono::steady_clock::time_point wall_;
  double cpu_;
};

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
  return root / "captures" / plan->key / (d.cameraLabel() + ".gltf");
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
  if (d.camera == "vr") {
    const fs::path vr = folder / (d.cameraLabel() + ".gltf");
    if (isNewerThan(vr, bot) && isNewerThan(vr, d.tracePath)) {
      indented("vr camera: " + vr.string() + " is newer than its sources, reused");
      return vr;
    }
    camera::VrCameraOptions options;
    options.trace = d.tracePath;
    options.body = o;  // the fly-through's own path: the VR and fly-through datasets of a match differ by the head alone
    // The head's offset in the map's units: the capture's own scale (its `k` record).
    auto reader = capture::CaptureReader::open(plan->openArena ? plan->openArenaOptions.output : plan->options.output);
    if (!reader) return std::unexpected(reader.error());
    options.metresPerUnit = (*reader)->settings().metresPerUnit;
    indented(fmt::format("vr camera: the head trace {} on the fly-through's path -> {}", d.tracePath.string(), vr.string()));
    auto made = camera::makeVrCameraDataset(bot, vr, folder / (d.cameraLabel() + ".csv"), options);
    if (!made) return std::unexpected(made.error());
    indented("  " + camera::describe(made->report));
    return vr;
  }
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
                manifestName, index, d.name, d.camera == "bot" ? "convert" : d.camera == "slowed" ? "convert or slowed-turns" : d.camera == "vr" ? "convert or vr-camera" : "convert or fly-through", dataset.string(), *made,
                d.datasetSha256, d.captureSha256.empty() ? "is not pinned" : "matches its pin: convert or flythrough made another dataset");
  return Digests{capture, *made};
}

// A suite's datasets captured, converted and flown through as needed, and their pins checked: all
// of them before anything is rendered. `which` are the manifest's indices to prepare (all when
// empty); each comes back with the wall and CPU seconds its preparation took (a shared capture's
// are its first dataset's).
struct PreparedDataset {
  std::size_t index = 0;
  fs::path dataset;
  Digests digests;
  StageSeconds seconds;
};
Expected<std::vector<PreparedDataset>> prepareDatasets(const Manifest& manifest, const std::vector<std::size_t>& which, const fs::path& root,
                                                       double fps, const pipeline::RunLog& log) {
  std::vector<PreparedDataset> prepared;
  std::map<fs::path, std::string> captureDigests;
  std::vector<std::size_t> indices = which;
  if (indices.empty())
    for (std::size_t i = 0; i < manifest.datasets.size(); ++i) indices.push_back(i);
  for (const std::size_t i : indices) {
    log(fmt::format("[{}/{}] {}: dataset", i + 1, manifest.datasets.size(), manifest.datasets[i].name));
    const StageClock clock;
    auto dataset = prepareDataset(manifest.datasets[i], root, fps, log);
    if (!dataset) return std::unexpected(dataset.error());
    auto digests = checkPins(manifest, i, *dataset, root, captureDigests);
    if (!digests) return std::unexpected(digests.error());
    const DatasetSpec& d = manifest.datasets[i];
    log(fmt::format("  sha256: capture {}{}, dataset {}{}", digests->capture, d.captureSha256.empty() ? "" : " (as pinned)", digests->dataset,
                    d.datasetSha256.empty() ? "" : " (as pinned)"));
    prepared.push_back({i, *dataset, *digests, clock.elapsed()});
  }
  return prepared;
}

// One `suite` at a time in a folder: an advisory lock on DIR/.suite.lock, released when the
// process ends however it ends. Render tasks (--part render) take none: a Slurm array runs many at
// once in one folder, each on frames of its own.
Expected<FileLock> lockFolder(const fs::path& root) {
  const fs::path file = root / ".suite.lock";
  auto lock = FileLock::tryTake(file);
  if (!lock) return std::unexpected(lock.error());
  if (!*lock) {
    const auto holder = readWholeFile(file);
    return fail(ErrorCode::kIo, "{}: another `dynbench suite` is running in this folder (process {} holds {}); wait for it, or use another folder",
                root.string(), holder && !holder->empty() ? *holder : std::string("?"), file.string());
  }
  (*lock)->note(std::to_string(::getpid()));  // who holds it, for the message above
  return std::move(**lock);
}

// The bytes of every file under `folder`.
std::uintmax_t folderBytes(const fs::path& folder) {
  std::uintmax_t total = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) total += it->file_size(ec);
  return total;
}

// The records of DIR/records and those of `elsewhere` (folders of records, or record files) that
// DIR lacks, the latter copied into DIR/records as they are. Every one is checked (readRecord).
Expected<std::map<std::string, SuiteRecord>> gatherRecords(const Manifest& manifest, const fs::path& root, const std::vector<fs::path>& elsewhere,
                                                           NumbersVersions accept, const pipeline::RunLog& log) {
  auto records = readRecords(root / "records", manifest, accept);
  if (!records) return std::unexpected(records.error());
  for (const fs::path& source : elsewhere) {
    std::map<std::string, SuiteRecord> found;
    std::error_code ec;
    if (fs::is_directory(source, ec)) {
      auto read = readRecords(source, manifest, accept);
      if (!read) return std::unexpected(read.error());
      found = std::move(*read);
    } else {
      auto read = readRecord(source, manifest, accept);
      if (!read) return std::unexpected(read.error());
      found.emplace(read->dataset, std::move(*read));
    }
    if (found.empty()) return fail(ErrorCode::kIo, "{}: no records (NAME.json) there", source.string());
    for (auto& [name, record] : found) {
      if (records->count(name)) {
        log(fmt::format("  {}: {} has its own record already; {} left as it is", name, root.string(), record.file.string()));
        continue;
      }
      auto bytes = readWholeFile(record.file);
      if (!bytes) return std::unexpected(bytes.error());
      const fs::path copy = recordPath(root, name);
      if (auto ok = writeFileAtomic(copy, *bytes); !ok) return std::unexpected(ok.error());
      log(fmt::format("  {}: record taken from {}", name, record.file.string()));
      record.file = copy;
      records->emplace(name, std::move(record));
    }
  }
  if (auto one = requireOneNumbersVersion(*records); !one) return std::unexpected(one.error());
  return records;
}

// suite.json and suite.md from one record per dataset of the manifest, in the manifest's order:
// what a run that made every dataset at once writes, byte for byte (the run writes them this way).
Expected<void> assembleSuite(const Manifest& manifest, const std::map<std::string, SuiteRecord>& records, const fs::path& root, SuiteOutcome& outcome) {
  nlohmann::json doc = {{"dynbench_suite_results", kResultsVersion},
                        {"tool_version", kVersion},
                        {"manifest", manifest.document},
                        {"ranking_error", "flip_ratio_to_none (flip for none)"},
                        {"method_inputs", manifest.run.methodInputs},
                        {"datasets", nlohmann::json::array()},
                        {"files", nlohmann::json::object()}};
  outcome.datasets.clear();
  for (const DatasetSpec& spec : manifest.datasets) {
    const SuiteRecord& record = records.at(spec.name);
    doc["datasets"].push_back(record.entry);
    for (const auto& [file, sum] : record.files) doc["files"][file] = sum;
    outcome.datasets.push_back(record.result);
  }
  outcome.validity = validity(outcome.datasets);
  doc["validity"] = validityJson(outcome.validity);
  const std::vector<WithinMatchCell> paired = withinMatches(outcome.datasets);
  doc["within_matches"] = withinMatchesJson(paired);
  outcome.json = root / "suite.json";
  outcome.markdown = root / "suite.md";
  auto md = suiteMarkdown(manifest, outcome.datasets, outcome.validity, paired, root);
  if (!md) return std::unexpected(md.error());
  if (auto ok = writeFileAtomic(outcome.markdown, *md); !ok) return std::unexpected(ok.error());
  // suite.json last: its presence says the suite is complete.
  return writeFileAtomic(outcome.json, jsonFileText(doc));
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
  auto lock = lockFolder(root);
  if (!lock) return std::unexpected(lock.error());
  if (options.part == SuitePart::kDatasets) {
    if (auto prepared = prepareDatasets(*manifest, {}, root, settings.fps, log); !prepared) return std::unexpected(prepared.error());
    return outcome;
  }
  // The datasets to make: those asked for (all unless --only) that have no record yet.
  std::set<std::string> asked(options.only.begin(), options.only.end());
  for (const std::string& name : asked)
    if (std::none_of(manifest->datasets.begin(), manifest->datasets.end(), [&](const DatasetSpec& d) { return d.name == name; }))
      return fail(ErrorCode::kUsage, "--only {}: no dataset of {} has that name", name, options.manifest.string());
  // Assembling alone reads records of an earlier build too (all of one numbers version); a run
  // that makes records beside them takes this build's alone.
  auto records = gatherRecords(*manifest, root, options.records, options.assembleOnly ? NumbersVersions::kAnyOne : NumbersVersions::kThisBuild, log);
  if (!records) return std::unexpected(records.error());
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < manifest->datasets.size(); ++i) {
    const DatasetSpec& spec = manifest->datasets[i];
    if (auto found = records->find(spec.name); found != records->end()) {
      const nlohmann::json& machine = found->second.document["machine"];
      log(fmt::format("[{}/{}] {}: done (record {}, made on {} at {})", i + 1, manifest->datasets.size(), spec.name, found->second.file.string(),
                      machine["cpu"].get<std::string>(), found->second.document["tool"]["commit"].get<std::string>().substr(0, 12)));
      ++outcome.recordsReused;
    } else if (!options.assembleOnly && (asked.empty() || asked.count(spec.name))) {
      todo.push_back(i);
    }
  }
  if (!todo.empty()) {
    auto prepared = prepareDatasets(*manifest, todo, root, settings.fps, log);
    if (!prepared) return std::unexpected(prepared.error());
    core::MachineInfo machine = core::machineInfo();
    machine.reciprocalEstimates = render::reciprocalEstimates();
    // Progress: datasets made, and the time left at the mean time of those this run rendered (a
    // dataset whose frames were complete is re-read in seconds; it would make the estimate a guess).
    const auto start = std::chrono::steady_clock::now();
    double renderingSeconds = 0.0;
    std::size_t renderedDatasets = 0;
    for (std::size_t k = 0; k < prepared->size(); ++k) {
      const PreparedDataset& p = (*prepared)[k];
      const DatasetSpec& spec = manifest->datasets[p.index];
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::size_t left = prepared->size() - k;
      std::string pace;
      if (k > 0 && renderedDatasets > 0) {
        const double minutesPerDataset = renderingSeconds / static_cast<double>(renderedDatasets) / 60.0;
        pace = fmt::format(" ({} of {} made in {:.1f} min; about {:.0f} min left at the {:.0f} min a dataset this run rendered took)", k,
                           prepared->size(), elapsed / 60.0, minutesPerDataset * static_cast<double>(left), minutesPerDataset);
      } else if (k > 0)
        pace = fmt::format(" ({} of {} made in {:.1f} min, all rendered before this run)", k, prepared->size(), elapsed / 60.0);
      log(fmt::format("[{}/{}] {}{}", p.index + 1, manifest->datasets.size(), spec.name, pace));
      const fs::path run = root / "runs" / spec.name;
      DatasetRunSettings s = settings;
      s.seed = spec.seed;
      const StageClock clock;
      auto measured = pipeline::measureDataset(p.dataset, run, s, log);
      if (!measured) return std::unexpected(measured.error());
      const StageSeconds measuring = clock.elapsed();
      if (measured->framesRendered > 0) {
        renderingSeconds += measuring.wall;
        ++renderedDatasets;
      }
      DatasetResult result;
      result.name = spec.name;
      result.measures = measuresOf(measured->motion, measured->firstFrame, measured->lastFrame, measured->discard);
      result.errors = errorsOf(measured->methods);
      auto plan = capturePlan(spec, root);
      if (!plan) return std::unexpected(plan.error());
      result.match = plan->key, result.camera = spec.cameraLabel();
      if (measured->referenceFloor) result.referenceFloor = measured->referenceFloor->mean, result.floorFrames = static_cast<int>(measured->referenceFloor->count);
      const nlohmann::json entry = {{"name", spec.name},
                                    {"dataset", fs::relative(p.dataset, root).string()},
                                    {"run", fs::relative(run, root).string()},
                                    {"sha256", {{"capture", p.digests.capture}, {"dataset", p.digests.dataset}}},
                                    {"window", {{"first", measured->firstFrame}, {"last", measured->lastFrame}}},
                                    {"measures", result.measures},
                                    {"errors", result.errors},
                                    {"match", result.match},
                                    {"camera", result.camera},
                                    {"reference_floor", referenceFloorJson(result)}};
      std::map<std::string, std::string> files;
      for (const fs::path& file : recordedFiles(root, p.dataset, run)) {
        auto sum = sha256File(root / file);
        if (!sum) return std::unexpected(sum.error());
        files[file.string()] = *sum;
      }
      // The record, as soon as the dataset is finished; read back as any record is, so that a run
      // and an assembly of records give the same tables.
      const fs::path file = recordPath(root, spec.name);
      const nlohmann::json record = recordJson(*manifest, p.index, entry, files, {{"dataset", p.seconds}, {"measure", measuring}}, folderBytes(run), machine);
      if (auto ok = writeFileAtomic(file, jsonFileText(record)); !ok) return std::unexpected(ok.error());
      auto readBack = readRecord(file, *manifest);
      if (!readBack) return std::unexpected(readBack.error());
      records->emplace(spec.name, std::move(*readBack));
      ++outcome.recordsMade;
      log(fmt::format("  record: {}", file.string()));
    }
  }
  for (const DatasetSpec& spec : manifest->datasets)
    if (!records->count(spec.name)) outcome.missing.push_back(spec.name);
  if (!outcome.missing.empty()) {
    if (options.assembleOnly)
      return fail(ErrorCode::kIncomplete, "{}: no record of {} of the {} datasets ({}): run them (`dynbench suite {} -o {}`), or bring their records (--records PATH)",
                  root.string(), outcome.missing.size(), manifest->datasets.size(), fmt::join(outcome.missing, ", "), options.manifest.string(), root.string());
    log(fmt::format("{} of {} datasets have records; suite.json and suite.md are assembled when every one has (still to make: {})", records->size(),
                    manifest->datasets.size(), fmt::join(outcome.missing, ", ")));
    return outcome;
  }
  if (auto ok = assembleSuite(*manifest, *records, root, outcome); !ok) return std::unexpected(ok.error());
  return outcome;
}

Expected<SuiteOutcome> publishSuite(const fs::path& dir, const fs::path& to, bool partial, const pipeline::RunLog& log) {
  const std::vector<fs::path> files = recordFiles(dir / "records");
  if (files.empty()) return fail(ErrorCode::kIo, "{}: no records to publish", (dir / "records").string());
  std::error_code ec;
  auto manifest = recordManifest(files.front());
  if (!manifest) return std::unexpected(manifest.error());
  auto records = readRecords(dir / "records", *manifest, NumbersVersions::kAnyOne);
  if (!records) return std::unexpected(records.error());
  std::vector<std::string> missing;
  for (const DatasetSpec& spec : manifest->datasets)
    if (!records->count(spec.name)) missing.push_back(spec.name);
  if (!missing.empty() && !partial)
    return fail(ErrorCode::kIncomplete,
                "{}: no record of {} of the {} datasets of suite '{}' ({}): a suite is published whole (--partial keeps the records of a run "
                "still going, without tables)",
                dir.string(), missing.size(), manifest->datasets.size(), manifest->name, fmt::join(missing, ", "));
  // The folder holds this suite's records and nothing else that looks like one.
  fs::remove_all(to / "records", ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot empty: {}", (to / "records").string(), ec.message());
  for (auto& [name, record] : *records) {
    auto bytes = readWholeFile(record.file);
    if (!bytes) return std::unexpected(bytes.error());
    record.file = recordPath(to, name);
    if (auto ok = writeFileAtomic(record.file, *bytes); !ok) return std::unexpected(ok.error());
  }
  log(fmt::format("{} records of suite '{}' -> {}", records->size(), manifest->name, (to / "records").string()));
  SuiteOutcome outcome;
  outcome.missing = missing;
  if (!missing.empty()) {
    // A run still going: its records, and no tables that could be taken for the suite's.
    for (const char* stale : {"suite.json", "suite.md"}) fs::remove(to / stale, ec);
    fs::remove_all(to / "plots", ec);
    outcome.recordsReused = records->size();
    return outcome;
  }
  if (auto ok = assembleSuite(*manifest, *records, to, outcome); !ok) return std::unexpected(ok.error());
  outcome.recordsReused = records->size();
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
