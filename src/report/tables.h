#pragma once
// The thesis's Tables 6.1-6.7, each defined once: title, columns and how a cell is formatted from
// the measured structs. `stats` and `discard` print them as Markdown, `report` as HTML and
// Markdown; nothing else writes these tables.
#include <optional>
#include <string>
#include <vector>

#include "discard/discard.h"
#include "evaluate/evaluate.h"
#include "report/stats_output.h"

namespace dynbench::report {

struct Table {
  std::string title;
  std::vector<std::string> header;              // the first column names the dataset
  std::vector<std::vector<std::string>> rows;   // formatted cells, one row per dataset
};

// Tables 6.1-6.6, one row per dataset.
std::vector<Table> statsTables(const std::vector<StatsRow>& rows);

struct DiscardRow {
  std::string name;
  discard::FramePercentages mean;  // Eq. (3.5), percent of the image
  discard::Thresholds::RadianceTest radianceTest = discard::Thresholds::RadianceTest::kPairs;  // what made the radiance columns
};
// Table 6.7, one row per dataset; `detail` is appended to the title (frame pairs, size).
Table discardTable(const std::vector<DiscardRow>& rows, const std::string& detail = {});

// "Temporal methods": one row per dataset and method, the means over frames with their standard
// errors (evaluate --json), each method on its input with its ratio to `none` on the same input,
// ≈ where that difference is within the reference's noise floor (evaluate::withinNoiseFloor), and
// per dataset a row for the floor itself when it was measured.
struct MethodsRow {
  std::string dataset;
  std::string input;                   // "jittered" or "still" (empty: not said)
  evaluate::MethodScores scores;
  std::optional<double> noneFlip;      // `none`'s mean ꟻLIP on the same input
  std::optional<evaluate::MeanWithError> floor;  // the dataset's reference noise floor (ꟻLIP)
  // A method other than `none` whose difference with `none` is within the floor (≈).
  bool withinFloor() const;
  // The ratio to `none` is above 1 and the difference is not within the floor.
  bool losesToNone() const;
};
Table temporalMethodsTable(const std::vector<MethodsRow>& rows);

std::string markdownTable(const Table& table);  // title, blank line, aligned Markdown table
std::string htmlTable(const Table& table);      // <table> with a <caption>
std::string escapeHtml(const std::string& text);  // & < > " as entities

}  // namespace dynbench::report
