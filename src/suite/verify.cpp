#include "suite/verify.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>

#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "pipeline/stages.h"
#include "suite/manifest.h"
#include "suite/score.h"
#include "suite/suite.h"
#include "suite/suite_markdown.h"
#include "suite/validity.h"

namespace dynbench::suite {

namespace fs = std::filesystem;
using pipeline::DatasetRunSettings;

Expected<VerifyOutcome> verifySuite(const fs::path& root, const pipeline::RunLog& log) {
  auto suite = readSuiteResults(root);
  if (!suite) return std::unexpected(suite.error());
  const fs::path& path = suite->path;
  const JsonFields f(suite->document, path);

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
  for (std::size_t i = 0; i < suite->datasets.size(); ++i) {
    const RecordedDataset& d = suite->datasets[i];
    const std::string& name = d.result.name;
    log(fmt::format("[{}/{}] {}", i + 1, suite->datasets.size(), name));
    DatasetRunSettings s = suite->manifest.run;
    auto stats = pipeline::measureStats(root / d.dataset, root / d.run, s, false);
    if (!stats) return std::unexpected(stats.error());
    pipeline::DiscardStage discardStage;
    discardStage.frames = root / d.run / "frames";
    auto discarded = pipeline::runDiscard(discardStage);
    if (!discarded) return std::unexpected(discarded.error());
    // The methods `suite score` added: built-in ones run again (on the input score ran them on),
    // the others from their stored outputs.
    auto scored = storedScoredMethods(*suite, root, name);
    if (!scored) return std::unexpected(scored.error());
    s.methods.insert(s.methods.end(), scored->builtIn.begin(), scored->builtIn.end());
    for (const auto& [method, input] : scored->inputs) s.methodInputs[method] = input;
    auto evaluated = pipeline::evaluateOnTheirInputs(root / d.run, s, scored->stored, false, scored->storedStill);
    if (!evaluated) return std::unexpected(evaluated.error());
    DatasetResult result = d.result;  // its name, match and camera as recorded; its numbers recomputed below
    result.measures = measuresOf(stats->rows.front().motion, d.first, d.last, discarded->run.mean);
    result.errors = errorsOf(*evaluated);
    result.referenceFloor.reset(), result.floorFrames = 0;
    if (d.result.referenceFloor) {
      auto floor = evaluate::referenceNoiseFloor(root / d.run / "frames", root / d.run / "floor");
      if (!floor) return std::unexpected(floor.error());
      result.referenceFloor = floor->mean, result.floorFrames = static_cast<int>(floor->count);
      check(fmt::format("{}: reference noise floor", name), *d.result.referenceFloor, floor->mean);
      check(fmt::format("{}: reference noise floor frames", name), d.result.floorFrames, floor->count);
    } else if (s.floorFrames > 0) {
      out.differences.push_back(fmt::format("{}: no reference noise floor recorded, but the manifest asks for {} frames", name, s.floorFrames));
    }
    const std::string at = fmt::format("/datasets/{}", i);
    for (const auto& [measure, value] : result.measures) {
      auto recorded = f.number(at + "/measures/" + measure);
      if (!recorded) return std::unexpected(recorded.error());
      check(fmt::format("{}: {}", name, measure), *recorded, value);
    }
    for (const auto& [method, errors] : result.errors)
      for (const auto& [error, value] : errors) {
        auto recorded = f.number(at + "/errors/" + method + "/" + error);
        if (!recorded) return std::unexpected(recorded.error());
        check(fmt::format("{}: {} {}", name, method, error), *recorded, value);
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
  // 4. The within-match comparisons, from the recomputed numbers.
  const auto paired = withinMatchesJson(withinMatches(recomputed));
  auto recordedPaired = f.value("/within_matches");
  if (!recordedPaired || !(*recordedPaired)->is_array() || (*recordedPaired)->size() != paired.size())
    out.differences.push_back(fmt::format("/within_matches: recorded {} cells, recomputed {}",
                                          recordedPaired && (*recordedPaired)->is_array() ? (*recordedPaired)->size() : 0, paired.size()));
  else
    for (std::size_t k = 0; k < paired.size(); ++k) {
      const nlohmann::json &c = (**recordedPaired)[k], &p = paired[k];
      const std::string where = fmt::format("within matches {} / {} / {} / {}", p["camera_a"].get<std::string>(), p["camera_b"].get<std::string>(),
                                            p["measure"].get<std::string>(), p["method"].get<std::string>());
      for (const auto& [key, value] : p.items()) {
        if (!c.contains(key) || c[key].is_null() != value.is_null() || c[key].is_number() != value.is_number()) {
          out.differences.push_back(fmt::format("{}: {} differs: recorded {}, recomputed {}", where, key, c.value(key, nlohmann::json()).dump(), value.dump()));
          continue;
        }
        if (value.is_number()) check(fmt::format("{}: {}", where, key), c[key].get<double>(), value.get<double>());
        else if (c[key] != value) out.differences.push_back(fmt::format("{}: {}: recorded {}, recomputed {}", where, key, c[key].dump(), value.dump()));
      }
    }
  return out;
}

RecordComparison compareRecords(const SuiteRecord& recorded, const SuiteRecord& remade) {
  RecordComparison out;
  out.dataset = recorded.dataset;
  const std::string file = recorded.file.string();
  const auto differs = [&](const std::string& pointer, const std::string& was, const std::string& now, const std::string& why) {
    out.differences.push_back(fmt::format("{}: {}: recorded {}, remade {}{}", file, pointer, was, now, why.empty() ? "" : " (" + why + ")"));
  };
  const DatasetResult &a = recorded.result, &b = remade.result;
  // What is exact: the window and the digests the pins are checked against.
  for (const char* pointer : {"/window/first", "/window/last", "/sha256/capture", "/sha256/dataset", "/match", "/camera"}) {
    ++out.numbers;
    const nlohmann::json::json_pointer p(pointer);
    const nlohmann::json was = recorded.entry.contains(p) ? recorded.entry[p] : nlohmann::json(), now = remade.entry.contains(p) ? remade.entry[p] : nlohmann::json();
    if (was != now) differs(std::string("/result") + pointer, was.dump(), now.dump(), "");
  }
  // The measures to the digits the tables show.
  for (const auto& [measure, value] : a.measures) {
    ++out.numbers;
    const auto found = b.measures.find(measure);
    const std::string shown = fmt::format("{:.3f}", value);
    if (found == b.measures.end()) differs("/result/measures/" + measure, shown, "nothing", "");
    else if (fmt::format("{:.3f}", found->second) != shown) differs("/result/measures/" + measure, shown, fmt::format("{:.3f}", found->second), "as suite.md shows them");
  }
  // The scores within a tenth of the noise floor: the reference cannot tell finer differences apart.
  const double tolerance = 0.1 * a.referenceFloor.value_or(0.0);
  const auto within = [&](const std::string& pointer, double was, double now, double allowed) {
    ++out.numbers;
    if (!(std::abs(was - now) <= allowed))
      differs(pointer, fmt::format("{:.6g}", was), fmt::format("{:.6g}", now), fmt::format("more than {:.3g} apart: a tenth of the noise floor", allowed));
  };
  if (a.referenceFloor.has_value() != b.referenceFloor.has_value()) {
    ++out.numbers;
    differs("/result/reference_floor", a.referenceFloor ? fmt::format("{:.6g}", *a.referenceFloor) : "null",
            b.referenceFloor ? fmt::format("{:.6g}", *b.referenceFloor) : "null", "");
  } else if (a.referenceFloor) {
    within("/result/reference_floor/flip", *a.referenceFloor, *b.referenceFloor, tolerance);
  }
  for (const auto& [method, errors] : a.errors) {
    const auto found = b.errors.find(method);
    if (found == b.errors.end()) {
      ++out.numbers;
      differs("/result/errors/" + method, "its scores", "nothing", "");
      continue;
    }
    // the `none` its ratio is to: the one on its own input
    const nlohmann::json& inputs = recorded.document["settings"]["method_inputs"];
    const bool still = inputs.is_object() && inputs.value(method, std::string()) == evaluate::kStillInput;
    const std::string none = method == kStillNone || method == "none" ? method : still ? kStillNone : "none";
    const double noneFlip = a.errors.count(none) && a.errors.at(none).count("flip") ? a.errors.at(none).at("flip") : 0.0;
    for (const auto& [error, value] : errors) {
      const std::string pointer = fmt::format("/result/errors/{}/{}", method, error);
      const auto now = found->second.find(error);
      if (now == found->second.end()) {
        ++out.numbers;
        differs(pointer, fmt::format("{:.6g}", value), "nothing", "");
      } else if (error == "flip_ratio_to_none") {
        within(pointer, value, now->second, noneFlip > 0 ? tolerance * (1.0 + value) / noneFlip : 0.0);
      } else {
        within(pointer, value, now->second, tolerance);
      }
    }
  }
  // The files, where both machines can give the same bytes (docs/suite.md, "Records").
  const nlohmann::json &machineA = recorded.document["machine"], &machineB = remade.document["machine"];
  const std::string estimatesA = machineA.value("reciprocal_estimates", ""), estimatesB = machineB.value("reciprocal_estimates", "");
  const std::string vendorA = machineA.value("vendor", ""), vendorB = machineB.value("vendor", "");
  const auto model = [](const nlohmann::json& m) {
    return m.value("family", -1) < 0 ? std::string("family and model not recorded")
                                     : fmt::format("family {} model {}", m.value("family", -1), m.value("model", -1));
  };
  const bool byEstimates = !estimatesA.empty() && !estimatesB.empty();
  if (byEstimates && estimatesA != estimatesB) {
    out.filesNote = fmt::format("the record was made on {} ({}), whose reciprocal estimates differ from this machine's ({}, {}: fingerprint {} against {}): "
                                "frame digests are not compared",
                                machineA.value("cpu", "?"), model(machineA), machineB.value("cpu", "?"), model(machineB), estimatesA.substr(0, 12),
                                estimatesB.substr(0, 12));
    return out;
  }
  if (!byEstimates && vendorA != vendorB) {
    out.filesNote = fmt::format("the record was made on {} ({}), this machine is {} ({}): frame digests are not compared across CPU vendors",
                                machineA.value("cpu", "?"), vendorA, machineB.value("cpu", "?"), vendorB);
    return out;
  }
  out.filesCompared = true;
  const std::size_t numbersDiffering = out.differences.size();
  for (const auto& [path, sum] : recorded.files) {
    ++out.files;
    const auto now = remade.files.find(path);
    if (now == remade.files.end()) differs("/files/" + path, sum.substr(0, 12) + "…", "no such file", "");
    else if (now->second != sum) differs("/files/" + path, sum.substr(0, 12) + "…", now->second.substr(0, 12) + "…", "SHA-256");
  }
  for (const auto& [path, sum] : remade.files)
    if (!recorded.files.count(path)) {
      ++out.files;
      differs("/files/" + path, "no such file", sum.substr(0, 12) + "…", "");
    }
  if (!byEstimates && out.differences.size() > numbersDiffering)
    out.filesNote = fmt::format("compared because both CPUs are {}, but the record names no fingerprint of its CPU's reciprocal estimates ({}; "
                                "this machine {}): the frames that differ may come from a CPU that estimates otherwise, or from a job of a build "
                                "before 2026-11-30 resumed at them (it began the scene's stepping there, docs/suite.md)",
                                vendorA, model(machineA), model(machineB));
  return out;
}

Expected<RecordComparison> verifyRecord(const fs::path& file, const fs::path& work, int threads, const pipeline::RunLog& log) {
  auto manifest = recordManifest(file);
  if (!manifest) return std::unexpected(manifest.error());
  auto recorded = readRecord(file, *manifest, NumbersVersions::kAnyOne);
  if (!recorded) return std::unexpected(recorded.error());
  if (recorded->numbersVersion != kNumbersVersion) {
    const std::string commit = recorded->document.value("/tool/commit"_json_pointer, std::string("unknown"));
    return fail(ErrorCode::kUnsupported,
                "{}: /numbers_version: made by a build of numbers version {} (git commit {}), and this dynbench makes version {}: its numbers "
                "are re-made by that build (git checkout {}), or the dataset is made again as a new record",
                file.string(), recorded->numbersVersion, commit, kNumbersVersion, commit);
  }
  // From nothing: an empty folder with the record's own manifest in it.
  std::error_code ec;
  fs::remove_all(work, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot empty: {}", work.string(), ec.message());
  const fs::path manifestFile = work / (manifest->name + ".json");
  if (auto ok = writeFileAtomic(manifestFile, manifest->document.dump(2) + "\n"); !ok) return std::unexpected(ok.error());
  SuiteOptions options;
  options.manifest = manifestFile;
  options.output = work;
  options.threads = threads;
  options.only = {recorded->dataset};
  auto run = runSuite(options, log);
  if (!run) return std::unexpected(run.error());
  auto remade = readRecord(recordPath(work, recorded->dataset), *manifest);
  if (!remade) return std::unexpected(remade.error());
  return compareRecords(*recorded, *remade);
}

std::vector<fs::path> sampleRecords(std::vector<fs::path> records, std::size_t k, std::uint64_t seed) {
  std::sort(records.begin(), records.end());
  std::mt19937_64 random(seed);
  std::vector<std::size_t> order(records.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  // Fisher-Yates with the generator's raw output (std::shuffle and the distributions are not the
  // same across standard libraries; mt19937_64's sequence is): j uniform in [0, i] by rejection.
  for (std::size_t i = order.size(); i > 1; --i) {
    const std::uint64_t n = i, limit = std::numeric_limits<std::uint64_t>::max() - std::numeric_limits<std::uint64_t>::max() % n;
    std::uint64_t r;
    do r = random();
    while (r >= limit);
    std::swap(order[i - 1], order[r % n]);
  }
  order.resize(std::min(k, order.size()));
  std::sort(order.begin(), order.end());
  std::vector<fs::path> chosen;
  for (std::size_t i : order) chosen.push_back(records[i]);
  return chosen;
}

}  // namespace dynbench::suite
