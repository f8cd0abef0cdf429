#include "suite/suite_markdown.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "dynbench/version.h"
#include "report/plots.h"
#include "report/stats_output.h"

namespace dynbench::suite {

namespace fs = std::filesystem;

namespace {

// Below this many datasets a bootstrap interval is not shown: resamples of a few points are
// mostly ties and duplicates, and their rho takes only a handful of values.
constexpr int kMinDatasetsForInterval = 8;

std::string cellText(const ValidityCell& c) {
  if (!c.correlation.rho) return "—";
  if (!c.correlation.low || c.datasets < kMinDatasetsForInterval) return fmt::format("{:+.2f}", *c.correlation.rho);
  const bool sure = *c.correlation.low > 0 || *c.correlation.high < 0;  // the interval excludes 0
  return fmt::format("{}{:+.2f} [{:+.2f}, {:+.2f}]{}", sure ? "**" : "", *c.correlation.rho, *c.correlation.low, *c.correlation.high, sure ? "**" : "");
}


}  // namespace

nlohmann::json referenceFloorJson(const DatasetResult& d) {
  if (!d.referenceFloor) return nullptr;
  return {{"flip", *d.referenceFloor}, {"frames", d.floorFrames}};
}

nlohmann::json withinMatchesJson(const std::vector<WithinMatchCell>& cells) {
  nlohmann::json out = nlohmann::json::array();
  auto number = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  for (const WithinMatchCell& c : cells)
    out.push_back({{"camera_a", c.cameraA}, {"camera_b", c.cameraB}, {"measure", c.measure}, {"method", c.method}, {"error", c.error},
                   {"matches", c.matches}, {"measure_higher", c.measureHigher}, {"error_higher", c.errorHigher},
                   {"error_sign_test_p", c.errorSignTestP}, {"rho", number(c.correlation.rho)}, {"low", number(c.correlation.low)},
                   {"high", number(c.correlation.high)}, {"resamples", c.correlation.resamples}});
  return out;
}

nlohmann::json validityJson(const std::vector<ValidityCell>& cells) {
  nlohmann::json out = nlohmann::json::array();
  for (const ValidityCell& c : cells) {
    auto number = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
    out.push_back({{"measure", c.measure}, {"method", c.method}, {"error", c.error}, {"rho", number(c.correlation.rho)}, {"low", number(c.correlation.low)},
                   {"high", number(c.correlation.high)}, {"datasets", c.datasets}, {"resamples", c.correlation.resamples}});
  }
  return out;
}

// suite.md: the datasets' numbers, the validity table (each method's ranking error), and a
// scatter plot per method of that error against its best-correlated measure.
Expected<std::string> suiteMarkdown(const Manifest& manifest, const std::vector<DatasetResult>& datasets, const std::vector<ValidityCell>& cells,
                                    const std::vector<WithinMatchCell>& paired, const fs::path& root, const nlohmann::json& scoredMethods) {
  std::string md = fmt::format("# Suite {}\n\n{}\n\n", manifest.name, manifest.description);
  const auto& r = manifest.run;
  md += fmt::format("{} datasets; each a window of {} frames at {}x{}, references converged (tolerance {}, {}-{} spp, {} bounces), "
                    "input {} spp; dynbench {}.\n\n",
                    datasets.size(), r.renderFrames, r.width, r.height, r.tolerance, r.samplesPerPixel, r.maxSamplesPerPixel, r.bounces,
                    r.inputSamplesPerPixel, kVersion);
  {
    std::vector<std::string> inputs;
    for (const auto& [method, input] : r.methodInputs) inputs.push_back(fmt::format("{} {}", method, input));
    if (!inputs.empty())
      md += fmt::format("Each method's input: {} (jittered: the projection jittered frame to frame; still: the pixel centres; `{}` is "
                        "`none` on the still input, the ratio's base for the methods there).\n\n",
                        fmt::join(inputs, ", "), kStillNone);
  }
  if (!scoredMethods.empty()) {
    md += "Scored afterwards with `dynbench suite score`, on the same stored input and reference frames:\n\n";
    for (const auto& s : scoredMethods)
      md += fmt::format("- `{}`: {}{}\n", s.value("name", ""), s.value("spec", ""),
                        s.contains("parameters") && !s["parameters"].empty() ? fmt::format(", parameters {}", s["parameters"].dump()) : std::string());
    md += "\n";
  }
  std::vector<std::string> methods;
  if (!datasets.empty())
    for (const auto& [method, errors] : datasets.front().errors) methods.push_back(method);
  {
    std::vector<std::string> header{"dataset"};
    for (const auto& m : measureKeys()) header.push_back(m);
    header.push_back("reference floor");
    for (const auto& m : methods) header.push_back(m + " ꟻLIP");
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> undecided;  // "dataset: method" within the floor
    for (const DatasetResult& d : datasets) {
      std::vector<std::string> row{d.name};
      for (const auto& m : measureKeys()) row.push_back(fmt::format("{:.3f}", d.measures.at(m)));
      row.push_back(d.referenceFloor ? fmt::format("{:.4f}", *d.referenceFloor) : "—");
      for (const auto& m : methods) {
        const bool within = withinNoiseFloor(d, m);
        row.push_back(fmt::format("{}{:.4f}", within ? "≈ " : "", d.errors.at(m).at("flip")));
        if (within) undecided.push_back(fmt::format("{}: {}", d.name, m));
      }
      rows.push_back(row);
    }
    const bool anyFloor = std::any_of(datasets.begin(), datasets.end(), [](const DatasetResult& d) { return d.referenceFloor.has_value(); });
    md += "## Datasets\n\nTable 6.7's columns over the window (%), the camera over the same frames (units or degrees per frame, cuts counted), "
          "the reference's noise floor (mean ꟻLIP between the reference and its render with another seed, on a few of the window's "
          "frames) and each method's mean ꟻLIP; ≈ marks a method whose ꟻLIP differs from `none`'s by less than the floor: the "
          "reference cannot tell them apart there, and the dataset does not rank them.\n\n" +
          report::markdownTable(header, rows) + "\n";
    if (anyFloor)
      md += undecided.empty() ? std::string("Every method's difference with `none` is larger than its dataset's noise floor.\n\n")
                              : fmt::format("Within the noise floor (not ranked against `none`): {}.\n\n", fmt::join(undecided, "; "));
  }
  {
    std::vector<std::string> header{"measure"};
    for (const auto& m : methods) header.push_back(fmt::format("{} ({})", m, rankingError(m)));
    std::vector<std::vector<std::string>> rows;
    for (const auto& measure : measureKeys()) {
      std::vector<std::string> row{measure};
      for (const auto& m : methods) {
        const auto c = std::find_if(cells.begin(), cells.end(), [&](const ValidityCell& v) { return v.measure == measure && v.method == m && v.error == rankingError(m); });
        row.push_back(c == cells.end() ? "—" : cellText(*c));
      }
      rows.push_back(row);
    }
    md += "## Validity\n\nSpearman's rank correlation of each difficulty measure with each method's error over the datasets, with its "
          "bootstrap 95 % interval (2000 resamples of the datasets); in bold where the interval excludes 0. Methods are ranked by "
          "their ꟻLIP over `none`'s on the same frames (below 1 where history helps: the content's own difficulty and the input's "
          "noise, the same for every method, divide out), `none` by its ꟻLIP. Every error's table is in suite.json." +
          (datasets.size() < static_cast<std::size_t>(kMinDatasetsForInterval)
               ? fmt::format(" With fewer than {} datasets no interval is shown: a bootstrap of so few points says nothing.", kMinDatasetsForInterval)
               : std::string()) +
          "\n\n" +
          report::markdownTable(header, rows) + "\n";
  }
  // Within matches: each camera pair's differences over the matches that have both.
  if (!paired.empty()) {
    md += "## Within matches\n\nThe same match seen by two cameras: each difference is camera A's dataset minus camera B's over one "
          "match, so the content (map, players, moments) is the same on both sides and cannot stand in for difficulty. For each "
          "measure: in how many matches it is higher on A; for each method: Spearman's rho between the matches' differences of the "
          "measure and of the method's ranking error (bootstrap 95 % interval over the matches, shown from 8 matches; bold where it "
          "excludes 0). Below: in how many matches each method's ranking error is higher on A, with the one-sided sign test's p.\n\n";
    std::vector<std::pair<std::string, std::string>> pairs;
    for (const WithinMatchCell& c : paired)
      if (std::find(pairs.begin(), pairs.end(), std::pair{c.cameraA, c.cameraB}) == pairs.end()) pairs.emplace_back(c.cameraA, c.cameraB);
    for (const auto& [a, b] : pairs) {
      auto cellOf = [&](const std::string& measure, const std::string& method) -> const WithinMatchCell* {
        for (const WithinMatchCell& c : paired)
          if (c.cameraA == a && c.cameraB == b && c.measure == measure && c.method == method) return &c;
        return nullptr;
      };
      std::vector<std::string> header{"measure", fmt::format("higher on {}", a)};
      for (const auto& m : methods) header.push_back(fmt::format("{}: rho of differences", m));
      std::vector<std::vector<std::string>> rows;
      int matches = 0;
      for (const auto& measure : measureKeys()) {
        const WithinMatchCell* any = cellOf(measure, methods.front());
        if (!any) continue;
        matches = any->matches;
        std::vector<std::string> row{measure, fmt::format("{} of {}", any->measureHigher, any->matches)};
        for (const auto& m : methods) {
          const WithinMatchCell* c = cellOf(measure, m);
          row.push_back(c ? cellText(ValidityCell{c->measure, c->method, c->error, c->correlation, c->matches}) : "—");
        }
        rows.push_back(row);
      }
      md += fmt::format("### {} (A) against {} (B), {} matches\n\n", a, b, matches) + report::markdownTable(header, rows) + "\n";
      for (const auto& m : methods)
        if (const WithinMatchCell* c = cellOf(measureKeys().front(), m))
          md += fmt::format("- {} ({}): higher on {} in {} of {} matches (one-sided sign test p = {:.3f})\n", m, c->error, a, c->errorHigher, c->matches,
                            c->errorSignTestP);
      md += "\n";
    }
  }
  // A scatter plot per method: its ranking error against the measure with the largest |rho|.
  md += "## Each method against its best-correlated measure\n\n";
  for (const auto& m : methods) {
    const ValidityCell* best = nullptr;
    for (const ValidityCell& c : cells)
      if (c.method == m && c.error == rankingError(m) && c.correlation.rho && (!best || std::abs(*c.correlation.rho) > std::abs(*best->correlation.rho)))
        best = &c;
    if (!best) continue;
    std::vector<report::ScatterPoint> points;
    for (const DatasetResult& d : datasets) points.push_back({d.name, d.measures.at(best->measure), d.errors.at(m).at(rankingError(m))});
    auto plot = report::writeScatterPlot(points, measureLabel(best->measure), fmt::format("{}: {}", m, m == "none" ? "mean ꟻLIP" : "mean ꟻLIP over none's"),
                                         fmt::format("{}: rho {:+.2f}", m, *best->correlation.rho), root / "plots", "scatter_" + m);
    if (!plot) return std::unexpected(plot.error());
    md += fmt::format("![{} against {}](plots/scatter_{}.png)\n\n", m, best->measure, m);
  }
  return md;
}
}  // namespace dynbench::suite
