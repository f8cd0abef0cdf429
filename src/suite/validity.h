#pragma once
// A suite's numbers and whether its difficulty measures predict the methods' errors: each
// dataset's measures and errors, and the rank correlation of every (measure, method, error) over
// the datasets (docs/suite.md, "Validity").
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "discard/discard.h"
#include "evaluate/evaluate.h"
#include "metrics/camera_motion.h"
#include "metrics/rank_correlation.h"
#include "pipeline/dataset_run.h"

namespace dynbench::suite {

// One dataset's numbers. Difficulty measures (docs/suite.md): Table 6.7's five columns over the
// render window (percent) and the camera's motion over the same frames (Tables 6.4-6.6: position
// in scene units and rotation, yaw and pitch in degrees per frame, cuts left out; cuts counted).
// Method errors: "flip" (mean ꟻLIP), "warped_error_change", "flip_over_none" (the method's
// ꟻLIP minus `none`'s on the same frames: what history costs or gains) and "flip_ratio_to_none"
// (the method's mean ꟻLIP over `none`'s on the same frames: below 1 where history helps).
struct DatasetResult {
  std::string name;
  std::map<std::string, double> measures;
  std::map<std::string, std::map<std::string, double>> errors;  // method -> error name -> value
  // The reference's noise floor (evaluate::referenceNoiseFloor): mean ꟻLIP between the reference
  // and its re-render with another seed, over floorFrames frames; absent when not rendered.
  std::optional<double> referenceFloor;
  int floorFrames = 0;
  // The match it shows (its capture's folder key: the same for every camera over one match) and
  // its camera policy ("bot", "flythrough"): the pairs of the within-match comparison.
  std::string match, camera;
};

// True when the method's ꟻLIP differs from `none`'s (on the method's input: its flip_over_none) by
// less than the reference's noise floor: the reference cannot tell the two apart, so the dataset
// does not rank them.
bool withinNoiseFloor(const DatasetResult& dataset, const std::string& method);

// The rank correlation of one measure with one method's error over the suite's datasets.
struct ValidityCell {
  std::string measure, method, error;
  metrics::RankCorrelation correlation;
  int datasets = 0;
};

// One measure against one method's ranking error within matches (issue 48's paired design): for
// each match with a dataset of camera `a` and one of camera `b` (the same capture: the same
// players, map and moments, seen by two cameras), the difference a - b of the measure and of the
// error. Content is held fixed in each difference, so it cannot stand in for difficulty.
struct WithinMatchCell {
  std::string cameraA, cameraB, measure, method, error;
  int matches = 0;
  int measureHigher = 0;       // matches where a's measure is the higher
  int errorHigher = 0;         // matches where a's error is the higher
  double errorSignTestP = 1.0; // one-sided sign test of errorHigher of matches (metrics::signTestOneSided)
  metrics::RankCorrelation correlation;  // Spearman's rho of the differences over the matches, bootstrap over matches
};
// Every camera pair present (in the order bot, then any other, flythrough last), every measure,
// every method's ranking error.
std::vector<WithinMatchCell> withinMatches(const std::vector<DatasetResult>& datasets);

// The error each method is ranked by: flip_ratio_to_none, or flip for `none` itself.
std::string rankingError(const std::string& method);
// Every (measure, method, error) cell, over the datasets' numbers.
std::vector<ValidityCell> validity(const std::vector<DatasetResult>& datasets);

// The measures, in the order tables list them: Table 6.7's columns by their keys
// (discard::kTable67Columns), then the camera's motion; and the errors of each method.
const std::vector<std::string>& measureKeys();
const std::vector<std::string>& errorKeys();
// A measure's axis label, with its unit.
std::string measureLabel(const std::string& measure);

// The difficulty measures of one dataset's window, frames first..last (DatasetResult::measures):
// its discard mean and the camera's motion over the same frames, cuts left out and counted.
std::map<std::string, double> measuresOf(const metrics::CameraMotion& motion, long first, long last, const discard::FramePercentages& discarded);
// `none` on the still input, as suite.json names it beside `none` on the jittered one.
inline constexpr const char* kStillNone = "none-still";
// Each method's errors on the input it had: the jittered input's as errorsOf gives them, the still
// input's against that input's own `none`, which is kept as kStillNone.
std::map<std::string, std::map<std::string, double>> errorsOf(const pipeline::MethodsOnTheirInputs& methods);
// Each method's errors (DatasetResult::errors). The difference and ratio with `none` use its scores
// among `methods`, or else `noneFlip` (none's mean ꟻLIP on the same frames, as a suite recorded it).
std::map<std::string, std::map<std::string, double>> errorsOf(const std::vector<evaluate::MethodScores>& methods,
                                                              std::optional<double> noneFlip = std::nullopt);

}  // namespace dynbench::suite
