#include "suite/score.h"

#include <algorithm>
#include <regex>
#include <set>

#include <fmt/format.h>

#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "evaluate/evaluate.h"
#include "suite/suite.h"
#include "suite/suite_markdown.h"

namespace dynbench::suite {

namespace fs = std::filesystem;

namespace {

// A method scored under the suite's name for it: `evaluate` names an external method by its folder,
// which differs per dataset; suite.json's column and DIR/scored/DATASET/NAME need one name.
class NamedMethod final : public evaluate::TemporalMethod {
 public:
  NamedMethod(std::string name, std::shared_ptr<evaluate::TemporalMethod> inner) : name_(std::move(name)), inner_(std::move(inner)) {}
  std::string name() const override { return name_; }
  nlohmann::json parameters() const override { return inner_->parameters(); }
  void reset() override { inner_->reset(); }
  Expected<evaluate::MethodOutput> process(const frames::FeatureFrame& frame) override { return inner_->process(frame); }

 private:
  std::string name_;
  std::shared_ptr<evaluate::TemporalMethod> inner_;
};

// A name that can be suite.json's key and a folder's name as it is (evaluate::methodFolder keeps it).
bool isPlainName(const std::string& name) {
  static const std::regex kName("[A-Za-z0-9_-]+");
  return std::regex_match(name, kName);
}

bool isBuiltIn(const std::string& name) {
  const auto names = evaluate::builtInMethodNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

// An external spec's folder for one dataset: PATH/DATASET, or PATH with {dataset} replaced.
fs::path externalFolder(const std::string& spec, const std::string& dataset) {
  std::string path = spec.substr(std::string_view("external:").size());
  const auto at = path.find("{dataset}");
  if (at == std::string::npos) return fs::path(path) / dataset;
  return path.replace(at, std::string_view("{dataset}").size(), dataset);
}

// One stored output folder: DIR/scored/DATASET/NAME.
fs::path storedFolder(const fs::path& dir, const std::string& dataset, const std::string& method) { return dir / "scored" / dataset / method; }

std::string storedPrefix(const std::string& dataset, const std::string& method) { return fmt::format("scored/{}/{}/", dataset, method); }

}  // namespace

Expected<RecordedDataset> readRecordedDataset(const JsonFields& f, const std::string& at) {
  RecordedDataset d;
  auto name = f.string(at + "/name");
  auto dataset = f.string(at + "/dataset");
  auto run = f.string(at + "/run");
  for (const auto* e : {&name, &dataset, &run})
    if (!*e) return std::unexpected(e->error());
  auto first = f.integer(at + "/window/first");
  auto last = f.integer(at + "/window/last");
  for (const auto* e : {&first, &last})
    if (!*e) return std::unexpected(e->error());
  d.result.name = *name, d.dataset = *dataset, d.run = *run, d.first = *first, d.last = *last;
  for (const auto& [key, target] : {std::pair{"/match", &d.result.match}, std::pair{"/camera", &d.result.camera}})
    if (f.has(at + key)) {
      auto v = f.string(at + key);
      if (!v) return std::unexpected(v.error());
      *target = *v;
    }
  for (const char* group : {"/measures", "/errors"}) {
    auto object = f.value(at + group);
    if (!object) return std::unexpected(object.error());
    if (!(*object)->is_object()) return fail(ErrorCode::kInvalidData, "{}: {}{}: expected an object", f.file().string(), at, group);
  }
  for (const auto& [measure, value] : (*f.value(at + "/measures"))->items()) {
    auto v = f.number(at + "/measures/" + measure);
    if (!v) return std::unexpected(v.error());
    d.result.measures[measure] = *v;
  }
  for (const auto& [method, errors] : (*f.value(at + "/errors"))->items()) {
    if (!errors.is_object()) return fail(ErrorCode::kInvalidData, "{}: {}/errors/{}: expected an object", f.file().string(), at, method);
    for (const auto& [error, value] : errors.items()) {
      auto v = f.number(fmt::format("{}/errors/{}/{}", at, method, error));
      if (!v) return std::unexpected(v.error());
      d.result.errors[method][error] = *v;
    }
  }
  if (f.has(at + "/reference_floor") && !(*f.value(at + "/reference_floor"))->is_null()) {
    auto floor = f.number(at + "/reference_floor/flip");
    auto frames = f.integer(at + "/reference_floor/frames");
    if (!floor) return std::unexpected(floor.error());
    if (!frames) return std::unexpected(frames.error());
    d.result.referenceFloor = *floor, d.result.floorFrames = static_cast<int>(*frames);
  }
  return d;
}

Expected<SuiteResults> readSuiteResults(const fs::path& dir) {
  SuiteResults out;
  out.path = dir / "suite.json";
  auto doc = readJsonFile(out.path);
  if (!doc) return std::unexpected(doc.error());
  out.document = std::move(*doc);
  const JsonFields f(out.document, out.path);
  auto version = f.integer("/dynbench_suite_results");
  if (!version) return std::unexpected(version.error());
  if (*version != kResultsVersion)
    return fail(ErrorCode::kInvalidData, "{}: /dynbench_suite_results: expected {}, found {}", out.path.string(), kResultsVersion, *version);
  // The manifest as recorded: the settings the numbers were made with.
  auto recordedManifest = f.value("/manifest");
  if (!recordedManifest) return std::unexpected(recordedManifest.error());
  auto manifest = parseManifest(**recordedManifest, out.path.string() + " /manifest");
  if (!manifest) return std::unexpected(manifest.error());
  out.manifest = std::move(*manifest);
  auto datasets = f.value("/datasets");
  if (!datasets) return std::unexpected(datasets.error());
  if (!(*datasets)->is_array()) return fail(ErrorCode::kInvalidData, "{}: /datasets: expected an array", out.path.string());
  for (std::size_t i = 0; i < (*datasets)->size(); ++i) {
    auto d = readRecordedDataset(f, fmt::format("/datasets/{}", i));
    if (!d) return std::unexpected(d.error());
    out.datasets.push_back(std::move(*d));
  }
  return out;
}

Expected<MethodToScore> parseMethodToScore(const std::string& text) {
  const auto equals = text.find('=');
  MethodToScore m;
  m.name = equals == std::string::npos ? text : text.substr(0, equals);
  m.spec = equals == std::string::npos ? text : text.substr(equals + 1);
  if (!isPlainName(m.name))
    return fail(ErrorCode::kUsage, "--method {}: the name '{}' must be letters, digits, '-' and '_' (it names suite.json's column and a folder)", text, m.name);
  if (m.spec.starts_with("external:")) {
    if (m.spec.size() == std::string_view("external:").size()) return fail(ErrorCode::kUsage, "--method {}: external: needs a folder", text);
    return m;
  }
  if (!isBuiltIn(m.spec))
    return fail(ErrorCode::kUsage, "--method {}: '{}' is not a method (expected NAME=external:PATH or one of {})", text, m.spec, evaluate::methodSpecHelp());
  if (m.name != m.spec)
    return fail(ErrorCode::kUsage, "--method {}: a built-in method is scored under its own name ('{}')", text, m.spec);
  return m;
}

namespace {

// The methods scored on `input` (evaluate::kJitteredInput or kStillInput) for one dataset, their
// outputs into pending/DATASET/NAME, their errors added to `result`.
Expected<void> scoreOnInput(const SuiteResults& suite, const fs::path& dir, const RecordedDataset& d, const std::vector<MethodToScore>& methods,
                            std::string_view input, const fs::path& pending, DatasetResult& result) {
  if (std::none_of(methods.begin(), methods.end(), [&](const MethodToScore& m) { return m.input == input; })) return {};
  const bool still = input == evaluate::kStillInput;
  evaluate::EvaluateOptions options;
  options.frames = dir / d.run / (still ? "input-still" : "input");
  if (still && !fs::is_directory(options.frames))
    return fail(ErrorCode::kIo, "{}: dataset '{}': no still input ({}): no method of the manifest was scored on it, so the suite did not render it",
                suite.path.string(), d.result.name, options.frames.string());
  options.reference = dir / d.run / "frames";
  options.methods.clear();
  options.outDir = pending / d.result.name;
  for (const MethodToScore& m : methods) {
    if (m.input != input) continue;
    if (m.method) {
      options.callerMethods.push_back(m.method);
    } else if (m.spec.starts_with("external:")) {
      auto external = evaluate::makeExternalMethod(externalFolder(m.spec, d.result.name));
      if (!external) return fail(external.error().code, "{}: dataset '{}': {}", suite.path.string(), d.result.name, external.error().message);
      options.callerMethods.push_back(std::make_shared<NamedMethod>(m.name, std::move(*external)));
    } else {
      options.methods.push_back(m.spec);
    }
  }
  auto run = evaluate::runEvaluate(options);
  if (!run) return fail(run.error().code, "{}: dataset '{}': {}", suite.path.string(), d.result.name, run.error().message);
  // The ratio and difference against `none` as the suite recorded it on the same input's frames.
  std::optional<double> noneFlip;
  if (auto none = d.result.errors.find(still ? kStillNone : "none"); none != d.result.errors.end() && none->second.count("flip"))
    noneFlip = none->second.at("flip");
  for (const auto& [method, errors] : errorsOf(run->methods, noneFlip)) result.errors[method] = errors;
  return {};
}

// Each method on every dataset of the suite, on its input, its outputs into pending/DATASET/NAME;
// the datasets' recorded numbers with the methods' errors added.
Expected<std::vector<DatasetResult>> scoreEveryDataset(const SuiteResults& suite, const fs::path& dir, const std::vector<MethodToScore>& methods,
                                                       const fs::path& pending, const pipeline::RunLog& log) {
  std::vector<DatasetResult> results;
  for (std::size_t i = 0; i < suite.datasets.size(); ++i) {
    const RecordedDataset& d = suite.datasets[i];
    log(fmt::format("[{}/{}] {}", i + 1, suite.datasets.size(), d.result.name));
    DatasetResult result = d.result;
    for (const std::string_view input : {evaluate::kJitteredInput, evaluate::kStillInput})
      if (auto ok = scoreOnInput(suite, dir, d, methods, input, pending, result); !ok) return std::unexpected(ok.error());
    results.push_back(std::move(result));
  }
  return results;
}

}  // namespace

Expected<ScoreOutcome> scoreSuite(const fs::path& dir, const std::vector<MethodToScore>& methods, const pipeline::RunLog& log) {
  auto suite = readSuiteResults(dir);
  if (!suite) return std::unexpected(suite.error());
  if (methods.empty()) return fail(ErrorCode::kUsage, "suite score: no methods (expected --method NAME=SPEC)");
  const std::vector<std::string>& manifestMethods = suite->manifest.run.methods;
  std::set<std::string> names;
  for (const MethodToScore& m : methods) {
    if (!isPlainName(m.name))
      return fail(ErrorCode::kUsage, "suite score: method name '{}': expected letters, digits, '-' and '_' (it names suite.json's column and a folder)", m.name);
    if (std::find(manifestMethods.begin(), manifestMethods.end(), m.name) != manifestMethods.end())
      return fail(ErrorCode::kUsage, "{}: method '{}' is one of the manifest's ({}); give the new method another name", suite->path.string(), m.name,
                  fmt::join(manifestMethods, ", "));
    if (m.name == kStillNone) return fail(ErrorCode::kUsage, "suite score: '{}' is suite.json's name for none on the still input", m.name);
    if (!names.insert(m.name).second) return fail(ErrorCode::kUsage, "suite score: method '{}' twice", m.name);
    if (m.input != evaluate::kJitteredInput && m.input != evaluate::kStillInput)
      return fail(ErrorCode::kUsage, "suite score: method '{}': input '{}': expected \"jittered\" or \"still\"", m.name, m.input);
  }

  // The frames every dataset's scoring reads (its reference and the jittered input), all named
  // before anything is scored: a folder assembled from records (`suite --assemble`,
  // published results) has the numbers but not the frames.
  std::vector<std::string> withoutFrames;
  for (const RecordedDataset& d : suite->datasets) {
    // (a still input the suite never rendered, with the rest there, has its own message below)
    std::vector<fs::path> needed{dir / d.run / "frames"};
    for (const MethodToScore& m : methods)
      if (m.input != evaluate::kStillInput) needed.push_back(dir / d.run / "input");
    if (std::any_of(needed.begin(), needed.end(), [](const fs::path& folder) { return !fs::is_directory(folder); }))
      withoutFrames.push_back(d.result.name);
  }
  if (!withoutFrames.empty())
    return fail(ErrorCode::kIo,
                "{}: the frames of {} of the {} datasets are not here ({}): a method is scored on every dataset's stored reference and "
                "input frames, and this folder has only their numbers (records). Score in the folder that made them, or make them again "
                "here (move their records aside and run `dynbench suite MANIFEST -o {}`)",
                dir.string(), withoutFrames.size(), suite->datasets.size(), fmt::join(withoutFrames, ", "), dir.string());

  // Every dataset's outputs go to DIR/scored/.pending first and move into place only when every
  // dataset has been scored: a failure leaves the suite as it was.
  const fs::path pending = dir / "scored" / ".pending";
  std::error_code ec;
  fs::remove_all(pending, ec);
  auto scoredResults = scoreEveryDataset(*suite, dir, methods, pending, log);
  if (!scoredResults) {
    fs::remove_all(pending, ec);
    return std::unexpected(scoredResults.error());
  }
  std::vector<DatasetResult>& results = *scoredResults;

  nlohmann::json doc = suite->document;
  nlohmann::json scored = doc.contains("scored_methods") && doc["scored_methods"].is_array() ? doc["scored_methods"] : nlohmann::json::array();
  scored.erase(std::remove_if(scored.begin(), scored.end(), [&](const nlohmann::json& s) { return s.is_object() && names.count(s.value("name", "")); }),
               scored.end());
  for (const MethodToScore& m : methods)
    scored.push_back({{"name", m.name}, {"spec", m.spec}, {"parameters", m.method ? m.method->parameters() : nlohmann::json::object()},
                      {"input", m.input}, {"outputs", fmt::format("scored/{{dataset}}/{}", m.name)}});
  doc["scored_methods"] = scored;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const std::string& dataset = results[i].name;
    for (const MethodToScore& m : methods) {
      const fs::path folder = storedFolder(dir, dataset, m.name);
      fs::remove_all(folder, ec);
      fs::create_directories(folder.parent_path(), ec);
      fs::rename(pending / dataset / evaluate::methodFolder(m.name), folder, ec);
      if (ec) return fail(ErrorCode::kIo, "{}: cannot move the outputs into place: {}", folder.string(), ec.message());
      // Its outputs replace any recorded under the same name.
      const std::string prefix = storedPrefix(dataset, m.name);
      for (auto it = doc["files"].begin(); it != doc["files"].end();)
        it = it.key().starts_with(prefix) ? doc["files"].erase(it) : std::next(it);
      std::vector<fs::path> outputs;
      for (const auto& entry : fs::directory_iterator(folder, ec))
        if (entry.path().extension() == ".exr") outputs.push_back(entry.path());
      std::sort(outputs.begin(), outputs.end());
      for (const fs::path& output : outputs) {
        auto sum = sha256File(output);
        if (!sum) return std::unexpected(sum.error());
        doc["files"][fs::relative(output, dir).string()] = *sum;
      }
      doc["datasets"][i]["errors"][m.name] = results[i].errors.at(m.name);
    }
  }
  fs::remove_all(pending, ec);

  const std::vector<ValidityCell> cells = validity(results);
  doc["validity"] = validityJson(cells);
  const std::vector<WithinMatchCell> paired = withinMatches(results);
  doc["within_matches"] = withinMatchesJson(paired);
  ScoreOutcome outcome;
  outcome.json = dir / "suite.json";
  outcome.markdown = dir / "suite.md";
  for (const MethodToScore& m : methods) outcome.methods.push_back(m.name);
  auto md = suiteMarkdown(suite->manifest, results, cells, paired, dir, scored);
  if (!md) return std::unexpected(md.error());
  if (auto ok = writeFileAtomic(outcome.markdown, *md); !ok) return std::unexpected(ok.error());
  if (auto ok = writeFileAtomic(outcome.json, jsonFileText(doc)); !ok) return std::unexpected(ok.error());
  return outcome;
}

Expected<StoredMethods> storedScoredMethods(const SuiteResults& suite, const fs::path& dir, const std::string& dataset) {
  StoredMethods out;
  if (!suite.document.contains("scored_methods")) return out;
  const JsonFields f(suite.document, suite.path);
  const nlohmann::json& scored = suite.document["scored_methods"];
  if (!scored.is_array()) return fail(ErrorCode::kInvalidData, "{}: /scored_methods: expected an array", suite.path.string());
  for (std::size_t i = 0; i < scored.size(); ++i) {
    auto name = f.string(fmt::format("/scored_methods/{}/name", i));
    auto spec = f.string(fmt::format("/scored_methods/{}/spec", i));
    for (const auto* e : {&name, &spec})
      if (!*e) return std::unexpected(e->error());
    // Suites scored before the input was recorded scored every added method on the jittered input.
    std::string input{evaluate::kJitteredInput};
    if (const std::string at = fmt::format("/scored_methods/{}/input", i); scored[i].contains("input")) {
      auto recorded = f.string(at);
      if (!recorded) return std::unexpected(recorded.error());
      if (*recorded != evaluate::kJitteredInput && *recorded != evaluate::kStillInput)
        return fail(ErrorCode::kInvalidData, "{}: {}: expected \"jittered\" or \"still\"", suite.path.string(), at);
      input = *recorded;
    }
    if (isBuiltIn(*spec)) {
      out.builtIn.push_back(*spec);
      out.inputs[*spec] = input;
      continue;
    }
    auto external = evaluate::makeExternalMethod(storedFolder(dir, dataset, *name));
    if (!external) return std::unexpected(external.error());
    (input == evaluate::kStillInput ? out.storedStill : out.stored).push_back(std::make_shared<NamedMethod>(*name, std::move(*external)));
  }
  return out;
}

}  // namespace dynbench::suite
