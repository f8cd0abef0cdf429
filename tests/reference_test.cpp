// The thesis's published tables (data/thesis-alanko2021.json) against the thesis text itself: every
// column head, row label and cell, and the table each belongs to. Then the conversions that
// `report --reference thesis` applies.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/files.h"
#include "report/reference.h"

namespace dynbench::report {
namespace {

std::vector<std::string> splitTabs(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t tab; (tab = line.find('\t', start)) != std::string::npos; start = tab + 1) out.push_back(line.substr(start, tab - start));
  out.push_back(line.substr(start));
  return out;
}

std::string joinTabs(const std::vector<std::string>& cells) {
  std::string out;
  for (const auto& c : cells) out += "\t" + c;
  return out;
}

TEST(Reference, DataFileReproducesTheThesisTables) {
  const std::string thesisPath = std::string(DYNBENCH_TESTDATA_DIR) + "/../reference/alanko2021-dynamic-benchmark.txt";
  auto text = readWholeFile(thesisPath);
  ASSERT_TRUE(text) << text.error().message;
  std::vector<std::string> lines;
  for (std::istringstream in(*text); lines.emplace_back(), std::getline(in, lines.back());) {}
  auto file = readWholeFile(std::string(DYNBENCH_SOURCE_DIR) + "/data/thesis-alanko2021.json");
  ASSERT_TRUE(file) << file.error().message;
  auto reference = parseReference(*file, "data/thesis-alanko2021.json");
  ASSERT_TRUE(reference) << reference.error().message;
  ASSERT_EQ(reference->tables.size(), 7u);
  for (std::size_t t = 0; t < reference->tables.size(); ++t) {
    const auto& table = reference->tables[t];
    EXPECT_EQ(table.table, fmt::format("6.{}", t + 1));
    // The caption is the thesis's.
    const std::string caption = fmt::format("Table {}. {}", table.table, table.caption);
    EXPECT_NE(text->find(caption), std::string::npos) << caption;
    // The table: the occurrence-th line with exactly these column heads, then one line per row.
    std::size_t at = lines.size();
    for (std::size_t i = 0, seen = 0; i < lines.size(); ++i)
      if (lines[i] == joinTabs(table.columns) && ++seen == static_cast<std::size_t>(table.occurrence)) {
        at = i;
        break;
      }
    ASSERT_LT(at, lines.size()) << table.table << ": no line with its column heads";
    for (std::size_t k = 0; k < table.rows.size(); ++k) {
      const auto cells = splitTabs(lines[at + 1 + k]);
      ASSERT_EQ(cells.size(), table.rows[k].cells.size() + 1) << table.table << " row " << k << ": " << lines[at + 1 + k];
      EXPECT_EQ(cells[0], table.rows[k].label) << table.table;
      EXPECT_TRUE(cells[0].starts_with(table.rows[k].dataset)) << table.table << ": " << cells[0];
      for (std::size_t c = 0; c < table.rows[k].cells.size(); ++c)
        EXPECT_EQ(cells[c + 1], table.rows[k].cells[c]) << table.table << " " << table.rows[k].label << " column " << table.columns[c];
    }
    // No further row: the thesis's table has exactly these six.
    EXPECT_EQ(lines[at + 1 + table.rows.size()].find('\t'), std::string::npos) << table.table;
    // Its caption line is within a dozen lines of it (the extracted text puts most captions below
    // their tables, Table 6.4's above), with no other table's caption in between: 6.4 and 6.5 share
    // their column heads, and this tells them apart.
    const std::size_t first = at, last = at + table.rows.size();
    std::size_t captionLine = lines.size();
    for (std::size_t i = first >= 12 ? first - 12 : 0; i < std::min(lines.size(), last + 13); ++i)
      if (lines[i].starts_with("Table " + table.table + ".")) captionLine = i;
    ASSERT_LT(captionLine, lines.size()) << table.table << ": its caption is not near it";
    for (std::size_t i = std::min(captionLine, first) + 1; i < std::max(captionLine, last); ++i)
      EXPECT_FALSE(lines[i].starts_with("Table 6.")) << table.table << ": another caption between it and its own: " << lines[i];
  }
  // What the build compiled in is this file.
  auto compiled = thesisReference();
  ASSERT_TRUE(compiled) << compiled.error().message;
  ASSERT_EQ(compiled->tables.size(), reference->tables.size());
  for (std::size_t t = 0; t < compiled->tables.size(); ++t)
    for (std::size_t k = 0; k < compiled->tables[t].rows.size(); ++k)
      EXPECT_EQ(compiled->tables[t].rows[k].cells, reference->tables[t].rows[k].cells);
}

TEST(Reference, RowsAreConvertedToDynbenchsConventionsAndMarkedPublished) {
  auto reference = thesisReference();
  ASSERT_TRUE(reference);
  std::vector<Table> tables{{"Table 6.4. position", {"dataset", "mean", "variance", "max", "cuts"}, {}},
                            {"Table 6.5. rotation", {"dataset", "mean", "variance", "max"}, {}},
                            {"Table 6.7. discard", {"dataset", "frustum %", "world position %", "shading normal %", "direct radiance %", "indirect radiance %"}, {}}};
  appendReferenceRows(tables, *reference);
  for (const auto& t : tables) ASSERT_EQ(t.rows.size(), 6u) << t.title;
  // Eternal Valley FPS: Table 6.4 as printed, no cuts column in the thesis.
  EXPECT_EQ(tables[0].rows[0], (std::vector<std::string>{"Eternal Valley FPS (published)", "4.711", "1.741", "10.855", "-"}));
  // Table 6.5: half the angle in the thesis (1.931, 4.526, 13.665): the full angle doubles the mean
  // and max and quadruples the variance.
  EXPECT_EQ(tables[1].rows[0], (std::vector<std::string>{"Eternal Valley FPS (published)", "3.862", "18.104", "27.330"}));
  EXPECT_EQ(tables[1].rows[2], (std::vector<std::string>{"Toasters (published)", "0.000", "0.000", "0.000"}));
  EXPECT_EQ(tables[2].rows[5], (std::vector<std::string>{"Emerald Square (published)", "1.781", "11.416", "17.461", "4.983", "0.432"}));
  // A malformed reference document names the JSON pointer.
  const auto bad = parseReference(R"({"source": "x", "tables": [{"table": "6.1", "caption": "c", "columns": ["a"], "occurrence": 1, "rows": [{"dataset": "d", "label": "d", "cells": ["1", "2"]}]}]})", "bad.json");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("bad.json: /tables/0/rows/0/cells: expected an array of 1 strings"), std::string::npos) << bad.error().message;
}

}  // namespace
}  // namespace dynbench::report
