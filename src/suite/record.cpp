#include "suite/record.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "dynbench/build_commit.h"
#include "dynbench/version.h"
#include "suite/score.h"
#include "suite/suite.h"

namespace dynbench::suite {

namespace fs = std::filesystem;

std::string manifestDigest(const Manifest& manifest) { return sha256Text(manifest.document.dump()); }

nlohmann::json recordSettings(const Manifest& manifest) {
  nlohmann::json settings = pipeline::datasetRunSettingsJson(manifest.run, true);
  // per dataset (its seed) or not a property of the numbers (render threads give the same bytes)
  settings.erase("seed");
  settings.erase("threads");
  settings["method_inputs"] = manifest.run.methodInputs;
  return settings;
}

fs::path recordPath(const fs::path& suiteFolder, const std::string& dataset) { return suiteFolder / "records" / (dataset + ".json"); }

nlohmann::json recordJson(const Manifest& manifest, std::size_t index, const nlohmann::json& entry, const std::map<std::string, std::string>& files,
                          const std::map<std::string, StageSeconds>& seconds, std::uintmax_t diskBytes, const core::MachineInfo& machine) {
  nlohmann::json timing = nlohmann::json::object();
  for (const auto& [part, s] : seconds) timing[part] = {{"wall", s.wall}, {"cpu", s.cpu}};
  return {{"dynbench_suite_record", kRecordVersion},
          {"results_version", kResultsVersion},
          {"numbers_version", kNumbersVersion},
          {"suite", manifest.name},
          {"manifest_sha256", manifestDigest(manifest)},
          {"manifest", manifest.document},
          {"dataset", manifest.document["datasets"][index]},
          {"settings", recordSettings(manifest)},
          {"tool", {{"version", kVersion}, {"commit", kBuildCommit}}},
          {"machine",
           {{"cpu", machine.cpu},
            {"vendor", machine.vendor},
            {"family", machine.family},
            {"model", machine.model},
            {"stepping", machine.stepping},
            {"isa", machine.isa},
            {"threads", machine.threads},
            {"reciprocal_estimates", machine.reciprocalEstimates}}},
          {"seconds", timing},
          {"disk_bytes", diskBytes},
          {"result", entry},
          {"files", files}};
}

Expected<SuiteRecord> readRecord(const fs::path& file, const Manifest& manifest, NumbersVersions accept) {
  auto doc = readJsonFile(file);
  if (!doc) return std::unexpected(doc.error());
  SuiteRecord record;
  record.file = file;
  record.document = std::move(*doc);
  const JsonFields f(record.document, file);
  const std::string name = file.string();
  if (!record.document.is_object()) return fail(ErrorCode::kInvalidData, "{}: expected a dynbench suite record (a JSON object)", name);
  // Versions first: a record of another version may spell everything else otherwise.
  auto version = f.integer("/dynbench_suite_record");
  if (!version) return std::unexpected(version.error());
  if (*version != kRecordVersion)
    return fail(ErrorCode::kInvalidData, "{}: /dynbench_suite_record: a record of version {}, which this dynbench (record version {}) cannot compare",
                name, *version, kRecordVersion);
  auto results = f.integer("/results_version");
  if (!results) return std::unexpected(results.error());
  if (*results != kResultsVersion)
    return fail(ErrorCode::kInvalidData, "{}: /results_version: numbers of results version {}, which this dynbench (version {}) cannot compare with its own",
                name, *results, kResultsVersion);
  auto numbers = f.integer("/numbers_version");
  if (!numbers) return std::unexpected(numbers.error());
  if (*numbers != kNumbersVersion && accept == NumbersVersions::kThisBuild)
    return fail(ErrorCode::kInvalidData,
                "{}: /numbers_version: numbers of version {}, and this dynbench makes version {}: made by a build whose numbers differ "
                "(make the dataset again)",
                name, *numbers, kNumbersVersion);
  record.numbersVersion = static_cast<int>(*numbers);
  auto digest = f.string("/manifest_sha256");
  if (!digest) return std::unexpected(digest.error());
  if (*digest != manifestDigest(manifest)) {
    auto suite = f.string("/suite");
    return fail(ErrorCode::kInvalidData, "{}: /manifest_sha256: a record of another manifest ('{}', SHA-256 {}), not {}'s ('{}', SHA-256 {})", name,
                suite ? *suite : std::string("?"), *digest, manifest.path.string(), manifest.name, manifestDigest(manifest));
  }
  auto copy = f.value("/manifest");
  if (!copy) return std::unexpected(copy.error());
  if (**copy != manifest.document)
    return fail(ErrorCode::kInvalidData, "{}: /manifest: not the document its /manifest_sha256 is the digest of (the record was edited)", name);
  auto dataset = f.value("/dataset");
  if (!dataset) return std::unexpected(dataset.error());
  auto datasetName = f.string("/dataset/name");
  if (!datasetName) return std::unexpected(datasetName.error());
  const auto& specs = manifest.datasets;
  const auto spec = std::find_if(specs.begin(), specs.end(), [&](const DatasetSpec& d) { return d.name == *datasetName; });
  if (spec == specs.end())
    return fail(ErrorCode::kInvalidData, "{}: /dataset/name: '{}' is no dataset of {}", name, *datasetName, manifest.path.string());
  const std::size_t index = static_cast<std::size_t>(spec - specs.begin());
  if (**dataset != manifest.document["datasets"][index])
    return fail(ErrorCode::kInvalidData, "{}: /dataset: dataset '{}' with other pins or settings than {}'s /datasets/{}", name, *datasetName,
                manifest.path.string(), index);
  auto settings = f.value("/settings");
  if (!settings) return std::unexpected(settings.error());
  if (**settings != recordSettings(manifest))
    return fail(ErrorCode::kInvalidData, "{}: /settings: made with other settings ({}) than this dynbench makes {}'s with ({})", name,
                (*settings)->dump(), manifest.path.string(), recordSettings(manifest).dump());
  record.dataset = *datasetName;
  // What it found: suite.json's entry, checked as suite.json's are read.
  auto entry = f.value("/result");
  if (!entry) return std::unexpected(entry.error());
  record.entry = **entry;
  auto recorded = readRecordedDataset(f, "/result");
  if (!recorded) return std::unexpected(recorded.error());
  if (recorded->result.name != record.dataset)
    return fail(ErrorCode::kInvalidData, "{}: /result/name: '{}', not the record's dataset '{}'", name, recorded->result.name, record.dataset);
  record.result = std::move(recorded->result);
  auto files = f.value("/files");
  if (!files) return std::unexpected(files.error());
  if (!(*files)->is_object()) return fail(ErrorCode::kInvalidData, "{}: /files: expected an object of SHA-256 sums", name);
  for (const auto& [path, sum] : (*files)->items()) {
    const std::string s = sum.is_string() ? sum.get<std::string>() : std::string();
    if (s.size() != 64 || s.find_first_not_of("0123456789abcdef") != std::string::npos)
      return fail(ErrorCode::kInvalidData, "{}: /files/{}: expected 64 lower-case hex digits, found {}", name, path, sum.dump());
    record.files[path] = s;
  }
  for (const char* key : {"/tool/version", "/tool/commit", "/machine/cpu", "/machine/vendor", "/machine/isa"})
    if (auto v = f.string(key); !v) return std::unexpected(v.error());
  return record;
}

Expected<Manifest> recordManifest(const fs::path& file) {
  auto doc = readJsonFile(file);
  if (!doc) return std::unexpected(doc.error());
  if (!doc->is_object()) return fail(ErrorCode::kInvalidData, "{}: expected a dynbench suite record (a JSON object)", file.string());
  const JsonFields f(*doc, file);
  auto version = f.integer("/dynbench_suite_record");
  if (!version) return std::unexpected(version.error());
  if (*version != kRecordVersion)
    return fail(ErrorCode::kInvalidData, "{}: /dynbench_suite_record: a record of version {}, which this dynbench (record version {}) cannot read",
                file.string(), *version, kRecordVersion);
  auto document = f.value("/manifest");
  if (!document) return std::unexpected(document.error());
  auto digest = f.string("/manifest_sha256");
  if (!digest) return std::unexpected(digest.error());
  auto manifest = parseManifest(**document, file.string() + " /manifest");
  if (!manifest) return std::unexpected(manifest.error());
  if (manifestDigest(*manifest) != *digest)
    return fail(ErrorCode::kInvalidData, "{}: /manifest: its SHA-256 is {}, not the record's /manifest_sha256 {} (the record was edited)",
                file.string(), manifestDigest(*manifest), *digest);
  return manifest;
}

std::vector<fs::path> recordFiles(const fs::path& folder) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".json" && !entry.path().filename().string().starts_with("."))
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

Expected<void> requireOneNumbersVersion(const std::map<std::string, SuiteRecord>& records) {
  const SuiteRecord* first = nullptr;
  for (const auto& [name, record] : records) {
    if (!first) first = &record;
    else if (record.numbersVersion != first->numbersVersion)
      return fail(ErrorCode::kInvalidData,
                  "{}: /numbers_version: numbers version {}, and {} numbers version {}: records of builds whose numbers differ are never "
                  "assembled into one table",
                  record.file.string(), record.numbersVersion, first->file.string(), first->numbersVersion);
  }
  return {};
}

Expected<std::map<std::string, SuiteRecord>> readRecords(const fs::path& folder, const Manifest& manifest, NumbersVersions accept) {
  std::map<std::string, SuiteRecord> records;
  for (const fs::path& file : recordFiles(folder)) {
    auto record = readRecord(file, manifest, accept);
    if (!record) return std::unexpected(record.error());
    if (auto [it, fresh] = records.emplace(record->dataset, *record); !fresh)
      return fail(ErrorCode::kInvalidData, "{}: /dataset/name: a second record of dataset '{}' (the first: {})", file.string(), record->dataset,
                  it->second.file.string());
  }
  if (auto one = requireOneNumbersVersion(records); !one) return std::unexpected(one.error());
  return records;
}

}  // namespace dynbench::suite
