#pragma once
// The thesis's Tables 6.1-6.7, each defined once: title, columns and how a cell is formatted from
// the measured structs. `stats` and `discard` print them as Markdown, `report` as HTML and
// Markdown; nothing else writes these tables.
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
// errors (evaluate --json).
struct MethodsRow {
  std::string dataset;
  evaluate::MethodScores scores;
};
Table temporalMethodsTable(const std::vector<MethodsRow>& rows);

std::string markdownTable(const Table& table);  // title, blank line, aligned Markdown table
std::string htmlTable(const Table& table);      // <table> with a <caption>
std::string escapeHtml(const std::string& text);  // & < > " as entities

}  // namespace dynbench::report
