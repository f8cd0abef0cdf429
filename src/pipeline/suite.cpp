#include "pipeline/suite.h"

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
#include "report/plots.h"
#include "report/stats_output.h"
#include "scene/load.h"
#include "scene/dataset_digest.h"

namespace dynbench::suite {

namespace fs = std::filesystem;
using pipeline::DatasetRunSettings;

namespace {

// The measures, in the order tables list them.
// Table 6.7's columns by their keys (discard::kTable67Columns), then the camera's motion.
const std::vector<std::string> kMeasures = [] {
  std::vector<std::string> measures;
  for (const auto& column : discard::kTable67Columns) measures.push_back(column.key);
  for (const char* camera : {"camera_position", "camera_rotation", "camera_yaw", "camera_pitch", "camera_cuts"}) measures.push_back(camera);
  return measures;
}();
const std::vector<std::string> kErrors{"flip", "warped_error_change", "flip_over_none"};
// Axis labels with units.
std::string measureLabel(const std::string& measure) {
  static const std::map<std::string, std::string> labels = [] {
    std::map<std::string, std::string> l{
      {"camera_position", "camera position change (scene units per frame)"}, {"camera_rotation", "camera rotation (degrees per frame)"},
      {"camera_yaw", "camera yaw change (degrees per frame)"}, {"camera_pitch", "camera pitch change (degrees per frame)"},
      {"camera_cuts", "camera cuts in the window"}};
    for (const auto& column : discard::kTable67Columns) l[column.key] = fmt::format("{} discard (%)", column.label);
    return l;
  }();
  const auto it = labels.find(measure);
  return it == labels.end() ? measure : it->second;
}
// Below this many datasets a bootstrap interval is not shown: resamples of a few points are
// mostly ties and duplicates, and their rho takes only a handful of values.
constexpr int kMinDatasetsForInterval = 8;

bool validName(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'; }) &&
         s != "." && s != "..";
}

}  // namespace

Expected<Manifest> readManifest(const fs::path& path) {
  auto doc = readJsonFile(path);
  if (!doc) return std::unexpected(doc.error());
  return parseManifest(*doc, path);
}

Expected<Manifest> parseManifest(const nlohmann::json& document, const fs::path& path) {
  Manifest m;
  m.document = document;
  const JsonFields f(m.document, path);
  m.path = path;
  auto bad = [&](const std::string& pointer, const std::string& expected) {
    return fail(ErrorCode::kInvalidData, "{}: {}: expected {}", path.string(), pointer, expected);
  };
  if (!m.document.is_object()) return bad("", "an object");
  auto version = f.integer("/dynbench_suite");
  if (!version) return std::unexpected(version.error());
  if (*version != kManifestVersion) return bad("/dynbench_suite", fmt::format("{} (the manifest version this dynbench reads), found {}", kManifestVersion, *version));
  auto name = f.string("/name");
  if (!name) return std::unexpected(name.error());
  if (!validName(*name)) return bad("/name", "letters, digits, '-', '_' or '.'");
  m.name = *name;
  if (f.has("/description")) {
    auto d = f.string("/description");
    if (!d) return std::unexpected(d.error());
    m.description = *d;
  }
  // The render window: every field optional, defaulting to DatasetRunSettings'.
  if (auto ok = readDatasetRunSettings(JsonSettingsReader(m.document, path), "/render", m.run, false); !ok) return std::unexpected(ok.error());
  DatasetRunSettings& r = m.run;
  if (f.has("/methods")) {
    auto methods = f.value("/methods");
    if (!(*methods)->is_array() || (*methods)->empty()) return bad("/methods", "a non-empty array of method names");
    r.methods.clear();
    for (std::size_t i = 0; i < (*methods)->size(); ++i) {
      auto method = f.string(fmt::format("/methods/{}", i));
      if (!method) return std::unexpected(method.error());
      r.methods.push_back(*method);
    }
  }
  auto datasets = f.value("/datasets");
  if (!datasets) return std::unexpected(datasets.error());
  if (!(*datasets)->is_array() || (*datasets)->empty()) return bad("/datasets", "a non-empty array of datasets");
  std::set<std::string> names;
  for (std::size_t i = 0; i < (*datasets)->size(); ++i) {
    const std::string at = fmt::format("/datasets/{}", i);
    DatasetSpec d;
    auto dname = f.string(at + "/name");
    if (!dname) return std::unexpected(dname.error());
    if (!validName(*dname)) return bad(at + "/name", "letters, digits, '-', '_' or '.'");
    if (!names.insert(*dname).second) return bad(at + "/name", fmt::format("a name no other dataset has ('{}' is repeated)", *dname));
    d.name = *dname;
    if (f.has(at + "/engine")) {
      auto engine = f.string(at + "/engine");
      if (!engine) return std::unexpected(engine.error());
      d.engine = *engine;
    }
    if (d.engine != "cube2" && d.engine != "openarena")
      return bad(at + "/engine", fmt::format("\"cube2\" or \"openarena\" (the engines dynbench captures), found \"{}\"", d.engine));
    const bool openArena = d.engine == "openarena";
    for (const auto& [key, target] : {std::pair{"/preset", &d.preset}, std::pair{"/map", &d.map}}) {
      if (!f.has(at + key)) continue;
      auto v = f.string(at + key);
      if (!v) return std::unexpected(v.error());
      *target = *v;
    }
    if (!d.preset.empty()) {
      if (openArena) return bad(at + "/preset", "no preset: OpenArena has none (give map and bots)");
      capture::Cube2Options probe;
      if (auto ok = capture::applyCube2Preset(d.preset, probe); !ok) return bad(at + "/preset", ok.error().message);
    }
    if (f.has(at + "/bots")) {
      auto bots = f.integer(at + "/bots");
      if (!bots) return std::unexpected(bots.error());
      const auto range = openArena ? capture::kOpenArenaBotsRange : capture::kBotsRange;
      if (*bots < range.first || *bots > range.second) return bad(at + "/bots", fmt::format("a whole number in [{}, {}]", range.first, range.second));
      d.bots = static_cast<int>(*bots);
    }
    auto seed = f.count(at + "/seed");
    if (!seed) return std::unexpected(seed.error());
    d.seed = static_cast<unsigned>(*seed);
    auto seconds = f.number(at + "/seconds");
    if (!seconds) return std::unexpected(seconds.error());
    if (!(*seconds > 0 && *seconds <= 3600)) return bad(at + "/seconds", "a number of game seconds in (0, 3600]");
    d.seconds = *seconds;
    auto camera = f.string(at + "/camera");
    if (!camera) return std::unexpected(camera.error());
    if (*camera != "bot" && *camera != "flythrough") return bad(at + "/camera", fmt::format("\"bot\" or \"flythrough\", found \"{}\"", *camera));
    d.camera = *camera;
    if (f.has(at + "/sha256")) {
      auto pins = f.value(at + "/sha256");
      if (!(*pins)->is_object()) return bad(at + "/sha256", "an object with \"capture\" and/or \"dataset\" SHA-256s");
      for (const auto& [key, value] : (*pins)->items())
        if (key != "capture" && key != "dataset") return bad(at + "/sha256/" + key, "no other key than \"capture\" and \"dataset\"");
      for (const auto& [key, target] : {std::pair{"capture", &d.captureSha256}, std::pair{"dataset", &d.datasetSha256}}) {
        const std::string pointer = at + "/sha256/" + key;
        if (!f.has(pointer)) continue;
        auto v = f.string(pointer);
        if (!v) return std::unexpected(v.error());
        if (v->size() != 64 || v->find_first_not_of("0123456789abcdef") != std::string::npos)
          return bad(pointer, fmt::format("a SHA-256 as 64 lower-case hex digits, found \"{}\"", *v));
        *target = *v;
      }
    }
    m.datasets.push_back(d);
  }
  return m;
}

Expected<std::string> captureDigest(const fs::path& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->path().filename().string().starts_with(".")) {
      if (it->is_directory()) it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file()) files.push_back(fs::relative(it->path(), folder).generic_string());
  }
  if (ec) return fail(ErrorCode::kIo, "{}: cannot list the capture: {}", folder.string(), ec.message());
  if (files.empty()) return fail(ErrorCode::kIo, "{}: no capture there", folder.string());
  return sha256Listing(folder, std::move(files));
}

std::string rankingError(const std::string& method) { return method == "none" ? "flip" : "flip_over_none"; }

std::vector<ValidityCell> validity(const std::vector<DatasetResult>& datasets) {
  std::vector<ValidityCell> cells;
  if (datasets.empty()) return cells;
  std::vector<std::string> methods;
  for (const auto& [method, errors] : datasets.front().errors) methods.push_back(method);
  for (const std::string& measure : kMeasures)
    for (const std::string& method : methods)
      for (const std::string& error : kErrors) {
        std::vector<double> x, y;
        for (const DatasetResult& d : datasets) {
          const auto m = d.measures.find(measure);
          const auto e = d.errors.find(method);
          if (m == d.measures.end() || e == d.errors.end()) continue;
          const auto v = e->second.find(error);
          if (v == e->second.end()) continue;
          x.push_back(m->second), y.push_back(v->second);
        }
        if (x.empty()) continue;
        cells.push_back({measure, method, error, metrics::rankCorrelation(x, y), static_cast<int>(x.size())});
      }
  return cells;
}

namespace {

// The difficulty measures of one dataset's window (DatasetResult).
std::map<std::string, double> measuresOf(const metrics::CameraMotion& motion, long first, long last, const discard::FramePercentages& d) {
  std::map<std::string, double> m;
  for (const auto& column : discard::kTable67Columns) m[column.key] = d.*column.member;
  std::vector<double> position, rotation, yaw, pitch;
  double cuts = 0;
  for (long i = first + 1; i <= last && i < static_cast<long>(motion.frames.size()); ++i) {
    const metrics::CameraFrame& f = motion.frames[static_cast<std::size_t>(i)];
    if (f.cut) {
      ++cuts;
      continue;
    }
    position.push_back(f.positionDelta), rotation.push_back(f.rotationDelta), yaw.push_back(f.yawDelta), pitch.push_back(f.pitchDelta);
  }
  m["camera_position"] = metrics::summarize(position).mean;
  m["camera_rotation"] = metrics::summarize(rotation).mean;
  m["camera_yaw"] = metrics::summarize(yaw).mean;
  m["camera_pitch"] = metrics::summarize(pitch).mean;
  m["camera_cuts"] = cuts;
  return m;
}

std::map<std::string, std::map<std::string, double>> errorsOf(const std::vector<evaluate::MethodScores>& methods) {
  std::map<std::string, std::map<std::string, double>> e;
  const auto none = std::find_if(methods.begin(), methods.end(), [](const auto& m) { return m.name == "none"; });
  for (const auto& m : methods) {
    e[m.name]["flip"] = m.flip.mean;
    e[m.name]["warped_error_change"] = m.warpedErrorChange.mean;
    if (none != methods.end()) e[m.name]["flip_over_none"] = m.flip.mean - none->flip.mean;
  }
  return e;
}

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
    plan.key = fmt::format("openarena-custom-{}-{}bots-seed{}-{}s", c.map, c.bots, c.seed, c.seconds);
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

// Where a spec's dataset lives: its capture's folder, bot.gltf or flythrough.gltf.
Expected<fs::path> datasetPath(const DatasetSpec& d, const fs::path& root) {
  auto plan = capturePlan(d, root);
  if (!plan) return std::unexpected(plan.error());
  return root / "captures" / plan->key / (d.camera == "bot" ? "bot.gltf" : "flythrough.gltf");
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
                manifestName, index, d.name, d.camera == "bot" ? "convert" : "convert or fly-through", dataset.string(), *made,
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

// The files a dataset's numbers come from, relative to DIR: the dataset's .gltf and .bin, and the
// run's reference and input frames with their sidecars.
std::vector<fs::path> recordedFiles(const fs::path& root, const fs::path& dataset, const fs::path& run) {
  std::vector<fs::path> files{fs::relative(dataset, root), fs::relative(fs::path(dataset).replace_extension(".bin"), root)};
  for (const char* folder : {"frames", "input"}) {
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

nlohmann::json validityJson(const std::vector<ValidityCell>& cells) {
  nlohmann::json out = nlohmann::json::array();
  for (const ValidityCell& c : cells) {
    auto number = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
    out.push_back({{"measure", c.measure}, {"method", c.method}, {"error", c.error}, {"rho", number(c.correlation.rho)}, {"low", number(c.correlation.low)},
                   {"high", number(c.correlation.high)}, {"datasets", c.datasets}, {"resamples", c.correlation.resamples}});
  }
  return out;
}

std::string cellText(const ValidityCell& c) {
  if (!c.correlation.rho) return "—";
  if (!c.correlation.low || c.datasets < kMinDatasetsForInterval) return fmt::format("{:+.2f}", *c.correlation.rho);
  const bool sure = *c.correlation.low > 0 || *c.correlation.high < 0;  // the interval excludes 0
  return fmt::format("{}{:+.2f} [{:+.2f}, {:+.2f}]{}", sure ? "**" : "", *c.correlation.rho, *c.correlation.low, *c.correlation.high, sure ? "**" : "");
}

// suite.md: the datasets' numbers, the validity table (each method's ranking error), and a
// scatter plot per method of that error against its best-correlated measure.
Expected<std::string> suiteMarkdown(const Manifest& manifest, const std::vector<DatasetResult>& datasets, const std::vector<ValidityCell>& cells,
                                    const fs::path& root) {
  std::string md = fmt::format("# Suite {}\n\n{}\n\n", manifest.name, manifest.description);
  const auto& r = manifest.run;
  md += fmt::format("{} datasets; each a window of {} frames at {}x{}, references converged (tolerance {}, {}-{} spp, {} bounces), "
                    "input {} spp; dynbench {}.\n\n",
                    datasets.size(), r.renderFrames, r.width, r.height, r.tolerance, r.samplesPerPixel, r.maxSamplesPerPixel, r.bounces,
                    r.inputSamplesPerPixel, kVersion);
  std::vector<std::string> methods;
  if (!datasets.empty())
    for (const auto& [method, errors] : datasets.front().errors) methods.push_back(method);
  {
    std::vector<std::string> header{"dataset"};
    for (const auto& m : kMeasures) header.push_back(m);
    for (const auto& m : methods) header.push_back(m + " ꟻLIP");
    std::vector<std::vector<std::string>> rows;
    for (const DatasetResult& d : datasets) {
      std::vector<std::string> row{d.name};
      for (const auto& m : kMeasures) row.push_back(fmt::format("{:.3f}", d.measures.at(m)));
      for (const auto& m : methods) row.push_back(fmt::format("{:.4f}", d.errors.at(m).at("flip")));
      rows.push_back(row);
    }
    md += "## Datasets\n\nTable 6.7's columns over the window (%), the camera over the same frames (units or degrees per frame, cuts counted), "
          "each method's mean ꟻLIP.\n\n" + report::markdownTable(header, rows) + "\n";
  }
  {
    std::vector<std::string> header{"measure"};
    for (const auto& m : methods) header.push_back(fmt::format("{} ({})", m, rankingError(m)));
    std::vector<std::vector<std::string>> rows;
    for (const auto& measure : kMeasures) {
      std::vector<std::string> row{measure};
      for (const auto& m : methods) {
        const auto c = std::find_if(cells.begin(), cells.end(), [&](const ValidityCell& v) { return v.measure == measure && v.method == m && v.error == rankingError(m); });
        row.push_back(c == cells.end() ? "—" : cellText(*c));
      }
      rows.push_back(row);
    }
    md += "## Validity\n\nSpearman's rank correlation of each difficulty measure with each method's error over the datasets, with its "
          "bootstrap 95 % interval (2000 resamples of the datasets); in bold where the interval excludes 0. Methods are ranked by "
          "their ꟻLIP minus `none`'s on the same frames (what history costs or gains: the content's own difficulty, the same for "
          "every method, cancels), `none` by its ꟻLIP. Every error's table is in suite.json." +
          (datasets.size() < static_cast<std::size_t>(kMinDatasetsForInterval)
               ? fmt::format(" With fewer than {} datasets no interval is shown: a bootstrap of so few points says nothing.", kMinDatasetsForInterval)
               : std::string()) +
          "\n\n" +
          report::markdownTable(header, rows) + "\n";
  }
  // A scatter plot per method: its ranking error against the measure with the largest |rho|.
  md += "## Each method against its best-correlated measure\n\n";
  for (const auto& m : methods) {
    const ValidityCell* best = nullptr;
    for (const ValidityCell& c : cells)
      if (c.method == m && c.error == rankingError(m) && c.correlation.rho && (!best || std::abs(*c.correlation.rho) > std::abs(*best->correlation.rho)))
        best = &c;
    if (!best) continue;
    std::vector<report::ScatterPoint> points;
    for (const DatasetResult& d : datasets) points.push_back({d.name, d.measures.at(best->measure), d.errors.at(m).at(rankingError(m))});
    auto plot = report::writeScatterPlot(points, measureLabel(best->measure), fmt::format("{}: {}", m, m == "none" ? "mean ꟻLIP" : "mean ꟻLIP minus none's"),
                                         fmt::format("{}: rho {:+.2f}", m, *best->correlation.rho), root / "plots", "scatter_" + m);
    if (!plot) return std::unexpected(plot.error());
    md += fmt::format("![{} against {}](plots/scatter_{}.png)\n\n", m, best->measure, m);
  }
  return md;
}

}  // namespace

int suiteFrameRenders(const Manifest& manifest) {
  return static_cast<int>(manifest.datasets.size()) * 2 * std::max(2, manifest.run.renderFrames);
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
                        {"ranking_error", "flip_over_none (flip for none)"},
                        {"datasets", nlohmann::json::array()},
                        {"files", nlohmann::json::object()}};
  auto prepared = prepareDatasets(*manifest, root, settings.fps, log);
  if (!prepared) return std::unexpected(prepared.error());
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < manifest->datasets.size(); ++i) {
    const DatasetSpec& spec = manifest->datasets[i];
    // Progress: datasets done, and the time left at the mean time a dataset has taken so far.
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string pace = i == 0 ? std::string()
                                    : fmt::format(" ({} done in {:.1f} min, about {:.0f} min left)", i, elapsed / 60.0,
                                                  elapsed / static_cast<double>(i) * static_cast<double>(manifest->datasets.size() - i) / 60.0);
    log(fmt::format("[{}/{}] {}{}", i + 1, manifest->datasets.size(), spec.name, pace));
    const auto& [dataset, digests] = (*prepared)[i];
    const fs::path run = root / "runs" / spec.name;
    DatasetRunSettings s = settings;
    s.seed = spec.seed;
    auto measured = pipeline::measureDataset(dataset, run, s, log);
    if (!measured) return std::unexpected(measured.error());
    DatasetResult result{spec.name, measuresOf(measured->motion, measured->firstFrame, measured->lastFrame, measured->discard), errorsOf(measured->methods)};
    outcome.datasets.push_back(result);
    doc["datasets"].push_back({{"name", spec.name},
                               {"dataset", fs::relative(dataset, root).string()},
                               {"run", fs::relative(run, root).string()},
                               {"sha256", {{"capture", digests.capture}, {"dataset", digests.dataset}}},
                               {"window", {{"first", measured->firstFrame}, {"last", measured->lastFrame}}},
                               {"measures", result.measures},
                               {"errors", result.errors}});
    for (const fs::path& file : recordedFiles(root, dataset, run)) {
      auto sum = sha256File(root / file);
      if (!sum) return std::unexpected(sum.error());
      doc["files"][file.string()] = *sum;
    }
  }
  outcome.validity = validity(outcome.datasets);
  doc["validity"] = validityJson(outcome.validity);
  outcome.json = root / "suite.json";
  outcome.markdown = root / "suite.md";
  auto md = suiteMarkdown(*manifest, outcome.datasets, outcome.validity, root);
  if (!md) return std::unexpected(md.error());
  if (auto ok = writeFileAtomic(outcome.markdown, *md); !ok) return std::unexpected(ok.error());
  // suite.json last: its presence says the run is complete.
  if (auto ok = writeFileAtomic(outcome.json, doc.dump(2) + "\n"); !ok) return std::unexpected(ok.error());
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

Expected<VerifyOutcome> verifySuite(const fs::path& root, const pipeline::RunLog& log) {
  const fs::path path = root / "suite.json";
  auto doc = readJsonFile(path);
  if (!doc) return std::unexpected(doc.error());
  const JsonFields f(*doc, path);
  auto version = f.integer("/dynbench_suite_results");
  if (!version) return std::unexpected(version.error());
  if (*version != kResultsVersion) return fail(ErrorCode::kInvalidData, "{}: /dynbench_suite_results: expected {}, found {}", path.string(), kResultsVersion, *version);
  // The manifest as recorded: the settings the numbers were made with.
  auto recordedManifest = f.value("/manifest");
  if (!recordedManifest) return std::unexpected(recordedManifest.error());
  auto manifest = parseManifest(**recordedManifest, path.string() + " /manifest");
  if (!manifest) return std::unexpected(manifest.error());

  VerifyOutcome out;
  // 1. Every file as recorded.
  auto files = f.value("/files");
  if (!files || !(*files)->is_object()) return fail(ErrorCode::kInvalidData, "{}: /files: expected an object of SHA-256 sums", path.string());
  for (const auto& [file, sum] : (*files)->items()) {
    ++out.files;
    auto now = sha256File(root / file);
    if (!now) out.differences.push_back(fmt::format("{}: {}", file, now.error().message));
    else if (!sum.is_string() || *now != sum.get<std::string>()) out.differences.push_back(fmt::format("{}: SHA-256 differs from the one recorded", file));
  }
  // 2. Every number, recomputed from the files.
  auto close = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)) + 1e-12; };
  auto check = [&](const std::string& where, double recorded, double found) {
    ++out.numbers;
    if (!close(recorded, found)) out.differences.push_back(fmt::format("{}: recorded {:.10g}, recomputed {:.10g}", where, recorded, found));
  };
  std::vector<DatasetResult> recomputed;
  auto datasets = f.value("/datasets");
  if (!datasets || !(*datasets)->is_array()) return fail(ErrorCode::kInvalidData, "{}: /datasets: expected an array", path.string());
  for (std::size_t i = 0; i < (*datasets)->size(); ++i) {
    const std::string at = fmt::format("/datasets/{}", i);
    auto name = f.string(at + "/name");
    auto dataset = f.string(at + "/dataset");
    auto run = f.string(at + "/run");
    auto first = f.integer(at + "/window/first");
    auto last = f.integer(at + "/window/last");
    for (const auto* e : {&name, &dataset, &run})
      if (!*e) return std::unexpected(e->error());
    for (const auto* e : {&first, &last})
      if (!*e) return std::unexpected(e->error());
    log(fmt::format("[{}/{}] {}", i + 1, (*datasets)->size(), *name));
    DatasetRunSettings s = manifest->run;
    auto stats = pipeline::measureStats(root / *dataset, root / *run, s, false);
    if (!stats) return std::unexpected(stats.error());
    pipeline::DiscardStage discardStage;
    discardStage.frames = root / *run / "frames";
    auto discarded = pipeline::runDiscard(discardStage);
    if (!discarded) return std::unexpected(discarded.error());
    evaluate::EvaluateOptions evaluation;
    evaluation.frames = root / *run / "input";
    evaluation.reference = root / *run / "frames";
    evaluation.methods = s.methods;
    auto evaluated = evaluate::runEvaluate(evaluation);
    if (!evaluated) return std::unexpected(evaluated.error());
    DatasetResult result{*name, measuresOf(stats->rows.front().motion, *first, *last, discarded->run.mean), errorsOf(evaluated->methods)};
    for (const auto& [measure, value] : result.measures) {
      auto recorded = f.number(at + "/measures/" + measure);
      if (!recorded) return std::unexpected(recorded.error());
      check(fmt::format("{}: {}", *name, measure), *recorded, value);
    }
    for (const auto& [method, errors] : result.errors)
      for (const auto& [error, value] : errors) {
        auto recorded = f.number(at + "/errors/" + method + "/" + error);
        if (!recorded) return std::unexpected(recorded.error());
        check(fmt::format("{}: {} {}", *name, method, error), *recorded, value);
      }
    recomputed.push_back(result);
  }
  // 3. The validity table, from the recomputed numbers.
  const auto cells = validity(recomputed);
  auto table = f.value("/validity");
  if (!table || !(*table)->is_array() || (*table)->size() != cells.size())
    out.differences.push_back(fmt::format("/validity: recorded {} cells, recomputed {}", table && (*table)->is_array() ? (*table)->size() : 0, cells.size()));
  else
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const nlohmann::json& c = (**table)[k];
      const std::string where = fmt::format("validity {} / {} / {}", cells[k].measure, cells[k].method, cells[k].error);
      for (const auto& [key, value] : {std::pair{"rho", cells[k].correlation.rho}, std::pair{"low", cells[k].correlation.low}, std::pair{"high", cells[k].correlation.high}}) {
        if (!c.contains(key) || c[key].is_null() != !value.has_value()) {
          out.differences.push_back(fmt::format("{}: {} defined in one and not the other", where, key));
          continue;
        }
        if (value) check(fmt::format("{}: {}", where, key), c[key].get<double>(), *value);
      }
    }
  return out;
}

}  // namespace dynbench::suite
