#include "suite/verify.h"

#include <cmath>

#include <fmt/format.h>

#include "core/checksum.h"
#include "core/json_fields.h"
#include "pipeline/stages.h"
#include "suite/manifest.h"
#include "suite/suite.h"
#include "suite/validity.h"

namespace dynbench::suite {

namespace fs = std::filesystem;
using pipeline::DatasetRunSettings;

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
