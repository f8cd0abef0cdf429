#pragma once
// Published reference rows: the thesis's Tables 6.1-6.7 for its six datasets (Eternal Valley FPS
// and VR, Toasters, Bistro Interior and Exterior, Emerald Square), from data/thesis-alanko2021.json,
// the one copy of those numbers, compiled in. `report --reference thesis` adds them to its tables,
// converted to dynbench's conventions where they differ, and marked as published.
#include <string>
#include <vector>

#include "core/error.h"
#include "report/tables.h"

namespace dynbench::report {

struct ReferenceTable {
  std::string table;                 // "6.1" ... "6.7"
  std::string caption;               // the thesis's
  std::vector<std::string> columns;  // its column heads, as printed
  int occurrence = 1;                // which table with these column heads in the thesis text (6.4 and 6.5 share theirs)
  struct Row {
    std::string dataset;             // the dataset's name
    std::string label;               // the row's label as printed (Table 6.5 says "Bistro Interior Wine")
    std::vector<std::string> cells;  // as printed: "240 584", "0,62 MiB", "-"
  };
  std::vector<Row> rows;
};

struct Reference {
  std::string source;  // citation and where the text is
  std::vector<ReferenceTable> tables;
};

// The compiled-in thesis tables (the JSON parsed; an error only if the build embedded a bad file).
Expected<Reference> thesisReference();
// Parses a reference document (the data file's format); errors name the JSON pointer.
Expected<Reference> parseReference(const std::string& json, const std::string& name);

// Appends the reference rows to the matching "Table 6.N." tables, labelled "NAME (published)".
// Conversions: Table 6.5's rotation is Eq. 2.4 taken literally, half the angle, so its mean and max
// are doubled and its variance multiplied by four to dynbench's full angle; columns the thesis
// lacks (Table 6.4's cuts) are "-". Other cells are as printed.
void appendReferenceRows(std::vector<Table>& tables, const Reference& reference);

}  // namespace dynbench::report
