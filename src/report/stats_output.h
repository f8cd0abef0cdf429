#pragma once
// `dynbench stats` outputs: aligned Markdown tables (thesis Tables 6.1-6.6), JSON, CSV and the
// per-frame camera series. Pure functions from measurements to text; the CLI writes the files.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "metrics/camera_motion.h"
#include "metrics/properties.h"

namespace dynbench::report {

struct StatsRow {
  std::string name;  // dataset label: the file name, made unique among the inputs
  std::string path;
  metrics::DatasetProperties properties;
  metrics::CameraMotion motion;
};

std::string formatBytes(std::uint64_t bytes);  // "1.50 MiB"

// A Markdown table with every column padded to its widest cell.
std::string markdownTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows);

std::string statsMarkdown(const std::vector<StatsRow>& rows);
nlohmann::json statsJson(const std::vector<StatsRow>& rows, double fps);
// The inverse of statsJson for what the tables show: dataset `index` of a stats.json document
// (`fps` from its root). Errors name the file and the JSON pointer of a missing or malformed value.
Expected<StatsRow> readStatsRow(const nlohmann::json& document, const std::filesystem::path& file, std::size_t index);
std::string statsCsv(const std::vector<StatsRow>& rows);
std::string cameraSeriesCsv(const metrics::CameraMotion& motion);

}  // namespace dynbench::report
