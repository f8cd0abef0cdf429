#include "suite/verify.h"

#include <cmath>

#include <fmt/format.h>

#include "core/checksum.h"
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

}  // namespace dynbench::suite
