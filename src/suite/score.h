#pragma once
// `dynbench suite score DIR --method NAME=SPEC` (and `dynbench.suite_score` in Python): a method that
// is not in the suite's manifest scored on every dataset of a finished suite, from the input and
// reference frames the suite stored, without capturing or rendering anything (docs/suite.md, "Score
// your own method"). Its column and its validity rows join suite.json and suite.md; its output
// frames are kept in DIR/scored/DATASET/NAME (recorded with their SHA-256) so that `suite verify`
// re-derives its numbers from the files as it does the manifest's methods'.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_fields.h"
#include "evaluate/method.h"
#include "pipeline/dataset_run.h"
#include "suite/manifest.h"
#include "suite/validity.h"

namespace dynbench::suite {

// A finished suite's suite.json, read back: the document, its manifest and every dataset's
// recorded numbers (errors name suite.json and the JSON pointer).
struct RecordedDataset {
  std::string dataset, run;  // relative to DIR
  long first = 0, last = 0;  // the window
  DatasetResult result;      // as recorded
};
struct SuiteResults {
  std::filesystem::path path;  // DIR/suite.json
  nlohmann::json document;
  Manifest manifest;           // as recorded in /manifest
  std::vector<RecordedDataset> datasets;
};
Expected<SuiteResults> readSuiteResults(const std::filesystem::path& dir);
// One dataset's entry of suite.json (or of a record: suite/record.h) at JSON pointer `at`; errors
// name f's file and the pointer.
Expected<RecordedDataset> readRecordedDataset(const JsonFields& f, const std::string& at);

// One method to score. `spec` is a built-in method's name (then `name` must be the same), or
// "external:PATH": PATH/DATASET/frame_NNNNN.exr per dataset, or PATH with "{dataset}" where the
// dataset's name goes. With `method` set (a method the caller made: the Python module's), `spec`
// only records what it was.
struct MethodToScore {
  std::string name;  // suite.json's key and DIR/scored/DATASET/NAME: letters, digits, '-', '_'
  std::string spec;
  std::shared_ptr<evaluate::TemporalMethod> method;
  // The input it is scored on: evaluate::kJitteredInput (RUN/input) or kStillInput (RUN/input-still,
  // the same render without the jitter; there only when a manifest method was scored on it). Its
  // ratio and difference are against `none` on the same input.
  std::string input{evaluate::kJitteredInput};
};
// "NAME=SPEC" or a built-in method's name alone (the CLI's --method).
Expected<MethodToScore> parseMethodToScore(const std::string& text);

struct ScoreOutcome {
  std::filesystem::path json, markdown;
  std::vector<std::string> methods;  // scored now
};
// Scores each method on every dataset of the suite in DIR and rewrites suite.json and suite.md
// (suite.json last, from a temporary file; a method scored before under the same name is replaced;
// a name of the manifest's methods is an error). Nothing changes in suite.json unless every
// dataset was scored.
Expected<ScoreOutcome> scoreSuite(const std::filesystem::path& dir, const std::vector<MethodToScore>& methods, const pipeline::RunLog& log);

// The methods `suite score` added to a suite (/scored_methods), as `evaluate` re-derives them for
// one dataset: a built-in one by its name in `builtIn`, the others from their stored outputs in
// DIR/scored/DATASET/NAME.
struct StoredMethods {
  std::vector<std::string> builtIn;
  std::map<std::string, std::string> inputs;  // each built-in one's input (DatasetRunSettings::methodInputs)
  std::vector<std::shared_ptr<evaluate::TemporalMethod>> stored, storedStill;  // by the input they were scored on
};
Expected<StoredMethods> storedScoredMethods(const SuiteResults& suite, const std::filesystem::path& dir, const std::string& dataset);

}  // namespace dynbench::suite
