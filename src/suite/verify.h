#pragma once
// `dynbench suite verify DIR`: a finished suite's numbers re-derived from the files it recorded.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "pipeline/dataset_run.h"
#include "suite/record.h"

namespace dynbench::suite {

struct VerifyOutcome {
  std::size_t files = 0, numbers = 0;    // checked
  std::vector<std::string> differences;  // one line each: what differs, recorded and found
};
// Recomputes every number of DIR/suite.json from the files it lists (their SHA-256, discard and
// evaluate on the recorded frames, the camera measures from the datasets, the validity table).
Expected<VerifyOutcome> verifySuite(const std::filesystem::path& dir, const pipeline::RunLog& log);

// One record made again from nothing and compared with what it says (docs/suite.md, "Records").
struct RecordComparison {
  std::string dataset;
  std::size_t numbers = 0, files = 0;    // compared
  bool filesCompared = false;            // the frame digests: only where both CPUs can give the same bytes
  std::string filesNote;                 // why they were not, or what a difference among them may mean
  std::vector<std::string> differences;  // "FILE: POINTER: recorded A, remade B (...)"
};
// Compares a remade record with the recorded one: the window, the pins' digests and the camera and
// Table 6.7 measures to the digits suite.md shows them (3 decimals); every method's ꟻLIP, its
// difference from `none`'s and the noise floor within a tenth of the recorded floor, the ratio to
// `none` within what that allows it (0.1 floor (1 + ratio) / none's ꟻLIP); and the SHA-256 of every
// recorded file where the two records' machines can give the same bytes: the same fingerprint of the
// CPU's reciprocal estimates (core::reciprocalEstimates), or, where the recorded one names none
// (records made before 2026-11-30), the same CPU vendor.
RecordComparison compareRecords(const SuiteRecord& recorded, const SuiteRecord& remade);

// Makes the dataset of the record `file` again from nothing (capture, convert, camera, renders,
// discard, evaluate) in the fresh folder `work` (emptied first), from the manifest the record
// carries, and compares (compareRecords).
Expected<RecordComparison> verifyRecord(const std::filesystem::path& file, const std::filesystem::path& work, int threads,
                                        const pipeline::RunLog& log);

// `k` of `records` chosen at random with `seed`: the same choice on every machine (a Fisher-Yates
// shuffle over std::mt19937_64, whose sequence the C++ standard fixes), in the input's order.
std::vector<std::filesystem::path> sampleRecords(std::vector<std::filesystem::path> records, std::size_t k, std::uint64_t seed);

}  // namespace dynbench::suite
