#include "report/reference.h"

#include <charconv>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "report/thesis_reference_json.h"

namespace dynbench::report {

Expected<Reference> parseReference(const std::string& text, const std::string& name) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    return fail(ErrorCode::kParse, "{}: invalid JSON: {}", name, e.what());
  }
  auto bad = [&](const std::string& pointer, const char* expected) {
    return fail(ErrorCode::kInvalidData, "{}: {}: expected {}", name, pointer, expected);
  };
  auto strings = [](const nlohmann::json& a, std::vector<std::string>& out) {
    if (!a.is_array()) return false;
    for (const auto& s : a) {
      if (!s.is_string()) return false;
      out.push_back(s.get<std::string>());
    }
    return true;
  };
  Reference r;
  if (!j.is_object() || !j.contains("source") || !j["source"].is_string()) return bad("/source", "a string");
  r.source = j["source"];
  if (!j.contains("tables") || !j["tables"].is_array()) return bad("/tables", "an array");
  for (std::size_t t = 0; t < j["tables"].size(); ++t) {
    const auto& jt = j["tables"][t];
    const std::string p = fmt::format("/tables/{}", t);
    ReferenceTable table;
    for (const char* key : {"table", "caption"})
      if (!jt.contains(key) || !jt[key].is_string()) return bad(p + "/" + key, "a string");
    table.table = jt["table"];
    table.caption = jt["caption"];
    if (!jt.contains("columns") || !strings(jt["columns"], table.columns)) return bad(p + "/columns", "an array of strings");
    if (!jt.contains("occurrence") || !jt["occurrence"].is_number_integer() || jt["occurrence"].get<int>() < 1)
      return bad(p + "/occurrence", "an integer >= 1");
    table.occurrence = jt["occurrence"];
    if (!jt.contains("rows") || !jt["rows"].is_array()) return bad(p + "/rows", "an array");
    for (std::size_t k = 0; k < jt["rows"].size(); ++k) {
      const auto& jr = jt["rows"][k];
      const std::string rp = fmt::format("{}/rows/{}", p, k);
      ReferenceTable::Row row;
      for (const char* key : {"dataset", "label"})
        if (!jr.contains(key) || !jr[key].is_string()) return bad(rp + "/" + key, "a string");
      row.dataset = jr["dataset"];
      row.label = jr["label"];
      if (!jr.contains("cells") || !strings(jr["cells"], row.cells) || row.cells.size() != table.columns.size())
        return bad(rp + "/cells", fmt::format("an array of {} strings, one per column", table.columns.size()).c_str());
      table.rows.push_back(std::move(row));
    }
    r.tables.push_back(std::move(table));
  }
  return r;
}

Expected<Reference> thesisReference() { return parseReference(kThesisReferenceJson, "data/thesis-alanko2021.json (compiled in)"); }

namespace {

// A published cell times a factor, to three decimals as the thesis prints; non-numbers unchanged.
std::string scaled(const std::string& cell, double factor) {
  double v = 0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc() || end != cell.data() + cell.size()) return cell;
  return fmt::format("{:.3f}", v * factor);
}

}  // namespace

void appendReferenceRows(std::vector<Table>& tables, const Reference& reference) {
  for (const auto& rt : reference.tables) {
    const std::string prefix = "Table " + rt.table + ".";
    for (auto& t : tables) {
      if (!t.title.starts_with(prefix)) continue;
      for (const auto& row : rt.rows) {
        std::vector<std::string> cells{row.dataset + " (published)"};
        for (std::size_t c = 0; c < row.cells.size(); ++c) {
          // Table 6.5: Eq. 2.4 taken literally is half the angle; dynbench's columns are the full one.
          if (rt.table == "6.5") cells.push_back(scaled(row.cells[c], c == 1 ? 4.0 : 2.0));
          else cells.push_back(row.cells[c]);
        }
        cells.resize(t.header.size(), "-");
        t.rows.push_back(std::move(cells));
      }
    }
  }
}

}  // namespace dynbench::report
