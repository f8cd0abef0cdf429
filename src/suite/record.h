#pragma once
// A suite's result for one dataset, as a small file that outlives the machine that made it
// (docs/suite.md, "Records"): DIR/records/NAME.json, written atomically as soon as the dataset is
// finished. A record says what it is of (the manifest's SHA-256, the dataset's entry with its pins,
// the settings every number depends on), what made it (dynbench's version and commit, the machine,
// the seconds each part took) and what it found (suite.json's entry for the dataset, and the
// SHA-256 of every file its numbers came from). Records are the unit of resumption and of
// distribution: a dataset with a matching record is not made again, and suite.json and suite.md
// are assembled from the records alone, wherever each was made.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/machine.h"
#include "suite/manifest.h"
#include "suite/validity.h"

namespace dynbench::suite {

// "dynbench_suite_record" in a record: bumped when a record's meaning changes.
inline constexpr int kRecordVersion = 1;
// "numbers_version" in a record: bumped by every change that moves a number a record holds for the
// same manifest (capture adapters, convert, cameras, the renderer, discard, the metrics, the
// methods), so that records of builds whose numbers differ are never assembled into one table. A
// record of another numbers version is refused where records are made (a run resumes or takes in
// records); published results of an earlier version still assemble (all of one version) and say
// which commit made them, which is the build that can re-make them.
// Version 2: OpenArena's map lights end at q3map2's envelope (fit version 9) and the references'
// light selection learns visibility (render/light_visibility.h).
// Version 3: every point and spot light in reach is evaluated where at most 16 reach a point, and
// at a path's first vertex the lights learned to arrive are summed (render/light_visibility.h);
// the light tree's walks interleaved (the same bits); the pixel filter's points are stratified
// (render/pixel_filter.h, stratifiedPoint). Commits 0e27888 to 4385b1c; no record of it was
// published.
// Version 4: where every light in reach is evaluated, the lights a learned cell saw occluded are
// traced by roulette (LightGuide::keepFactors). suites/results/v2 holds version 2's records.
inline constexpr int kNumbersVersion = 4;

// Which numbers versions a read accepts: this build's alone (a run that makes records beside them),
// or any one (assembling or publishing tables of records already made: readRecords then requires
// every record to share it).
enum class NumbersVersions { kThisBuild, kAnyOne };

// The manifest's digest a record carries: the SHA-256 of its document as compact JSON with sorted
// keys (nlohmann::json::dump()), so spacing and key order do not matter, every value does.
std::string manifestDigest(const Manifest& manifest);

// Everything a dataset's numbers depend on beyond its manifest entry: the run settings as this
// dynbench resolves them (its defaults included: max_pairs, floor frames, each method's input).
// Two records are comparable only where this is equal.
nlohmann::json recordSettings(const Manifest& manifest);

// Wall and CPU seconds of one part of a dataset's run (CPU: this process and its children).
struct StageSeconds {
  double wall = 0.0, cpu = 0.0;
};

struct SuiteRecord {
  std::filesystem::path file;  // where it was read from (errors name it)
  std::string dataset;         // the manifest dataset's name
  nlohmann::json entry;        // suite.json's /datasets/N for it
  std::map<std::string, std::string> files;  // path relative to the suite folder -> SHA-256
  DatasetResult result;        // entry's numbers, parsed
  nlohmann::json document;     // the whole record as read
  int numbersVersion = kNumbersVersion;
};

// The record's JSON for dataset `index` of `manifest`: `entry` is suite.json's entry for it, `files`
// the SHA-256 of its recorded files; `seconds` by part ("dataset": capture, convert and camera;
// "measure": stats, renders, discard, evaluate); `diskBytes` the run folder's size.
nlohmann::json recordJson(const Manifest& manifest, std::size_t index, const nlohmann::json& entry, const std::map<std::string, std::string>& files,
                          const std::map<std::string, StageSeconds>& seconds, std::uintmax_t diskBytes, const core::MachineInfo& machine);

// A record read and checked against `manifest`. Refused with status 5 (kInvalidData), naming the
// file and the JSON pointer: a record this dynbench cannot compare (/dynbench_suite_record,
// /results_version), of another manifest (/manifest_sha256), of a dataset the manifest does not
// have or has otherwise (/dataset), made with other settings (/settings), or malformed (not JSON,
// a value missing or of the wrong type).
Expected<SuiteRecord> readRecord(const std::filesystem::path& file, const Manifest& manifest,
                                 NumbersVersions accept = NumbersVersions::kThisBuild);

// The record files (*.json, hidden names aside) in `folder`, sorted; none for a missing folder.
std::vector<std::filesystem::path> recordFiles(const std::filesystem::path& folder);

// Every record (*.json) in `folder`, each read as readRecord does, by dataset name; an error for the
// first one refused, or for two records of one dataset. A missing folder has none.
Expected<std::map<std::string, SuiteRecord>> readRecords(const std::filesystem::path& folder, const Manifest& manifest,
                                                         NumbersVersions accept = NumbersVersions::kThisBuild);
// An error naming two records of different numbers versions, if `records` has them.
Expected<void> requireOneNumbersVersion(const std::map<std::string, SuiteRecord>& records);

// The manifest a record was made from: its /manifest (a copy of the manifest's document, so that a
// record can be re-made, checked and assembled with nothing else), parsed, and refused when its
// digest is not the record's /manifest_sha256. `file` names the record in errors.
Expected<Manifest> recordManifest(const std::filesystem::path& file);

// DIR/records/NAME.json.
std::filesystem::path recordPath(const std::filesystem::path& suiteFolder, const std::string& dataset);

}  // namespace dynbench::suite
