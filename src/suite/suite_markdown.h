#pragma once
// suite.md and suite.json's validity table: the datasets' numbers, the validity table (each
// method's ranking error, with bootstrap intervals) and a scatter plot per method.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "suite/manifest.h"
#include "suite/validity.h"

namespace dynbench::suite {

// suite.json's /datasets/N/reference_floor: {"flip", "frames"}, or null when it was not rendered.
nlohmann::json referenceFloorJson(const DatasetResult& dataset);
// suite.json's /within_matches: one object per cell.
nlohmann::json withinMatchesJson(const std::vector<WithinMatchCell>& cells);
// suite.json's /validity: one object per cell.
nlohmann::json validityJson(const std::vector<ValidityCell>& cells);
// suite.md, with its scatter plots written into root/plots: the validity table from `cells`, the
// within-match comparisons from `paired`; `scoredMethods` is suite.json's /scored_methods (the
// methods `suite score` added afterwards), listed with what they were.
Expected<std::string> suiteMarkdown(const Manifest& manifest, const std::vector<DatasetResult>& datasets, const std::vector<ValidityCell>& cells,
                                    const std::vector<WithinMatchCell>& paired, const std::filesystem::path& root,
                                    const nlohmann::json& scoredMethods = nlohmann::json::array());

}  // namespace dynbench::suite
