#include "report/tables.h"

#include <fmt/format.h>

namespace dynbench::report {
namespace {

std::string fixed3(double v) { return fmt::format("{:.3f}", v); }
std::string yesNo(bool b) { return b ? "Yes" : "No"; }

template <typename Cells>
Table table(std::string title, std::vector<std::string> header, const std::vector<StatsRow>& rows, Cells cells) {
  Table t{std::move(title), std::move(header), {}};
  for (const auto& r : rows) {
    std::vector<std::string> row{r.name};
    for (auto& c : cells(r)) row.push_back(std::move(c));
    t.rows.push_back(std::move(row));
  }
  return t;
}

// Mean, variance (and max) of a camera-motion summary; "-" without a camera.
std::vector<std::string> motionCells(const StatsRow& r, const metrics::Summary& s, bool withMax) {
  if (!r.motion.hasCamera) return std::vector<std::string>(withMax ? 3 : 2, "-");
  std::vector<std::string> cells{fixed3(s.mean), fixed3(s.variance)};
  if (withMax) cells.push_back(fixed3(s.max));
  return cells;
}

}  // namespace

std::string escapeHtml(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

std::vector<Table> statsTables(const std::vector<StatsRow>& rows) {
  std::vector<Table> out;
  out.push_back(table("Table 6.1. Dataset properties.",
                      {"dataset", "file format", "file(s) size", "faces", "animated camera", "morph targets"}, rows, [](const StatsRow& r) {
                        const auto& p = r.properties;
                        return std::vector<std::string>{p.fileFormat, formatBytes(p.totalBytes), fmt::format("{}", p.faces),
                                                        yesNo(p.animatedCamera), yesNo(p.morphTargets)};
                      }));
  out.push_back(table("Table 6.2. Texture details.", {"dataset", "material count", "texture count", "texture size", "material workflow"},
                      rows, [](const StatsRow& r) {
                        const auto& p = r.properties;
                        std::string workflow = p.materialWorkflow;
                        const auto main = p.workflowCounts.find(p.materialWorkflow);
                        if (p.workflowCounts.size() > 1 && main != p.workflowCounts.end())
                          workflow += fmt::format(" (+{} other)", p.materialCount - main->second);
                        return std::vector<std::string>{fmt::format("{}", p.materialCount), fmt::format("{}", p.textureCount),
                                                        formatBytes(p.textureBytes), workflow};
                      }));
  out.push_back(table(fmt::format("Table 6.3. Animation details (frames at {} fps).", rows.empty() ? 0.0 : rows[0].properties.fps),
                      {"dataset", "animation frames", "static objects", "dynamic rigid objects", "armatures", "static point lights",
                       "dynamic point lights"},
                      rows, [](const StatsRow& r) {
                        const auto& p = r.properties;
                        return std::vector<std::string>{fmt::format("{}", p.animationFrames), fmt::format("{}", p.staticObjects),
                                                        fmt::format("{}", p.dynamicRigidObjects), fmt::format("{}", p.armatures),
                                                        fmt::format("{}", p.staticPointLights), fmt::format("{}", p.dynamicPointLights)};
                      }));
  out.push_back(table("Table 6.4. Change in camera position per frame (scene units; Tables 6.4-6.6 leave camera cuts out).",
                      {"dataset", "mean", "variance", "max", "cuts"}, rows, [](const StatsRow& r) {
                        auto cells = motionCells(r, r.motion.position, true);
                        cells.push_back(r.motion.hasCamera ? fmt::format("{}", r.motion.cuts) : "-");
                        return cells;
                      }));
  out.push_back(table("Table 6.5. Change in camera rotation per frame (degrees, geodesic, the full angle; Eq. 2.4 taken literally, as the thesis's table, gives half: --json rotation_eq24).", {"dataset", "mean", "variance", "max"}, rows,
                      [](const StatsRow& r) { return motionCells(r, r.motion.rotation, true); }));
  out.push_back(table("Table 6.6. Change in camera rotation per axis (degrees / frame).",
                      {"dataset", "pitch mean", "pitch variance", "yaw mean", "yaw variance", "roll mean", "roll variance"}, rows,
                      [](const StatsRow& r) {
                        auto cells = motionCells(r, r.motion.pitch, false);
                        for (const auto* s : {&r.motion.yaw, &r.motion.roll})
                          for (auto& c : motionCells(r, *s, false)) cells.push_back(std::move(c));
                        return cells;
                      }));
  return out;
}

namespace {

// "mean ± half width" of a 95 % interval (intervals can be asymmetric where they meet 0 or 100:
// the larger side is printed).
std::string withInterval(double mean, const std::optional<discard::Interval>& interval) {
  if (!interval) return fixed3(mean);
  return fmt::format("{} ± {}", fixed3(mean), fixed3(std::max(mean - interval->low, interval->high - mean)));
}

}  // namespace

Table discardTable(const std::vector<DiscardRow>& rows, const std::string& detail) {
  Table t{"Table 6.7. Discarded pixels, % of the image, mean over the frame pairs" + (detail.empty() ? "" : " (" + detail + ")") + ".",
          {"dataset", "frustum %", "world position %", "shading normal %", "direct radiance %", "indirect radiance %"},
          {}};
  // † marks a radiance column that the render's noise leaves uncertain (discard::uncertainLimit).
  bool markedNoisy = false, markedUndecided = false;
  auto radiance = [&](double value, const std::optional<discard::Interval>& interval, double noisy, discard::Thresholds::RadianceTest test) {
    std::string cell = withInterval(value, interval);
    if (noisy > discard::uncertainLimit(test)) {
      (test == discard::Thresholds::RadianceTest::kPairs ? markedUndecided : markedNoisy) = true;
      cell += " †";
    }
    return cell;
  };
  for (const auto& r : rows)
    t.rows.push_back({r.name, fixed3(r.mean.frustum), fixed3(r.mean.position), fixed3(r.mean.normal),
                      radiance(r.mean.direct, r.mean.directInterval, r.mean.directNoisy, r.radianceTest),
                      radiance(r.mean.indirect, r.mean.indirectInterval, r.mean.indirectNoisy, r.radianceTest)});
  if (markedUndecided)
    t.title += " †: more than 0.5 % of the pixels stayed undecided at the render's pair cap; the interval bounds them both ways.";
  if (markedNoisy)
    t.title += " †: the noise of more than 5 % of the pixels exceeds half the threshold, and there noise alone counts as change:"
               " the column measures the render's noise as much as the dataset.";
  return t;
}

bool MethodsRow::withinFloor() const {
  return scores.name != "none" && noneFlip && floor && scores.flip.count && evaluate::withinNoiseFloor(scores.flip.mean - *noneFlip, floor->mean);
}

bool MethodsRow::losesToNone() const {
  return scores.name != "none" && noneFlip && scores.flip.count && scores.flip.mean > *noneFlip && !withinFloor();
}

Table temporalMethodsTable(const std::vector<MethodsRow>& rows) {
  Table t;
  t.title = "Temporal methods against the converged reference (mean ± standard error over frames; each method on the input it is built "
            "for, its ratio to `none` on the same input; ≈: the difference with `none` is within the reference's noise floor, so this "
            "dataset does not rank them; docs/metrics.md, docs/suite.md)";
  t.header = {"dataset", "method", "input", "ꟻLIP ↓", "ꟻLIP / none", "PSNR (dB) ↑", "SSIM ↑", "tPSNR (dB) ↑", "warped error change ↓", "history use"};
  auto cell = [](const evaluate::MeanWithError& m, int digits) {
    return m.count ? fmt::format("{:.{}f} ± {:.{}f}", m.mean, digits, m.standardError, digits) : std::string("n/a");
  };
  std::string floorShown;  // the dataset whose floor row is written
  for (const auto& r : rows) {
    if (r.floor && r.dataset != floorShown) {
      t.rows.push_back({r.dataset, "reference noise floor", fmt::format("{} frames, two seeds", r.floor->count), cell(*r.floor, 4), "", "", "",
                        "", "", ""});
      floorShown = r.dataset;
    }
    const auto& s = r.scores;
    const std::string ratio = r.noneFlip && *r.noneFlip > 0 && s.flip.count ? fmt::format("{:.3f}", s.flip.mean / *r.noneFlip) : "";
    t.rows.push_back({r.dataset, s.name, r.input.empty() ? "—" : r.input, (r.withinFloor() ? "≈ " : "") + cell(s.flip, 4), ratio, cell(s.psnr, 2),
                      cell(s.ssim, 4), cell(s.tPsnr, 2), cell(s.warpedErrorChange, 4), cell(s.historyUse, 3)});
  }
  return t;
}

std::string markdownTable(const Table& t) { return fmt::format("{}\n\n{}\n", t.title, markdownTable(t.header, t.rows)); }

std::string htmlTable(const Table& t) {
  std::string out = fmt::format("<table>\n<caption>{}</caption>\n<thead><tr>", escapeHtml(t.title));
  for (const auto& h : t.header) out += "<th>" + escapeHtml(h) + "</th>";
  out += "</tr></thead>\n<tbody>\n";
  for (const auto& row : t.rows) {
    // Published reference rows (report/reference.h) are set apart from measured ones.
    out += !row.empty() && row[0].ends_with("(published)") ? "<tr class=\"published\">" : "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c)
      out += (c == 0 ? "<th scope=\"row\">" : "<td>") + escapeHtml(row[c]) + (c == 0 ? "</th>" : "</td>");
    out += "</tr>\n";
  }
  return out + "</tbody>\n</table>\n";
}

}  // namespace dynbench::report
