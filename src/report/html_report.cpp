#include "report/html_report.h"

#include <algorithm>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/files.h"
#include "core/image_io.h"
#include "discard/discard.h"
#include "frames/frame_io.h"
#include "frames/preview.h"
#include "report/plots.h"
#include "report/stats_output.h"

namespace dynbench::report {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Run {
  std::string name;
  fs::path dir;
  json stats, discard;
  std::string cameraCsv;
  std::vector<fs::path> masks;
  std::vector<frames::FrameEntry> frames;
};

struct Table {
  std::string title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

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

Expected<json> readJson(const fs::path& path, const std::string& what) {
  auto text = readWholeFile(path);
  if (!text) return fail(ErrorCode::kIo, "{}: missing ({}); {}", path.string(), text.error().message, what);
  try {
    return json::parse(*text);
  } catch (const json::parse_error& e) {
    return fail(ErrorCode::kParse, "{}: not valid JSON: {}", path.string(), e.what());
  }
}

// A JSON value at a pointer, with an error naming file and pointer when it is not there.
Expected<json> at(const json& j, const fs::path& file, const std::string& pointer) {
  const json::json_pointer p(pointer);
  if (!j.contains(p)) return fail(ErrorCode::kInvalidData, "{}: {}: missing", file.string(), pointer);
  return j.at(p);
}

Expected<Run> readRun(const fs::path& dir) {
  Run run;
  run.dir = dir;
  run.name = dir.filename().string().empty() ? dir.parent_path().filename().string() : dir.filename().string();
  auto stats = readJson(dir / "stats.json", "write it with `dynbench stats DATASET --json RUN/stats.json`");
  if (!stats) return std::unexpected(stats.error());
  auto discardJson = readJson(dir / "discard.json", "write it with `dynbench discard FRAMES --json RUN/discard.json`");
  if (!discardJson) return std::unexpected(discardJson.error());
  auto dataset = at(*stats, dir / "stats.json", "/datasets/0");
  if (!dataset) return std::unexpected(dataset.error());
  run.stats = *dataset;
  for (const char* key : {"properties", "camera_motion"})
    if (!run.stats.contains(key))
      return fail(ErrorCode::kInvalidData, "{}: /datasets/0/{}: missing (the stats of a dataset with a camera are needed)",
                  (dir / "stats.json").string(), key);
  for (const char* p : {"/mean", "/frames"})
    if (auto ok = at(*discardJson, dir / "discard.json", p); !ok) return std::unexpected(ok.error());
  run.discard = *discardJson;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() > 11 && name.ends_with("_camera.csv")) {
      auto text = readWholeFile(e.path());
      if (text) run.cameraCsv = *text;
    }
  }
  if (fs::is_directory(dir / "masks", ec)) {
    for (const auto& e : fs::directory_iterator(dir / "masks", ec))
      if (e.path().extension() == ".png") run.masks.push_back(e.path());
    std::sort(run.masks.begin(), run.masks.end());
  }
  if (fs::is_directory(dir / "frames", ec))
    if (auto listed = frames::listFrames(dir / "frames")) run.frames = *listed;
  return run;
}

std::string number(const json& j, const char* pointer, int decimals = 3) {
  const json::json_pointer p(pointer);
  if (!j.contains(p) || !j.at(p).is_number()) return "-";
  return fmt::format("{:.{}f}", j.at(p).get<double>(), decimals);
}
std::string integer(const json& j, const char* pointer) {
  const json::json_pointer p(pointer);
  if (!j.contains(p) || !j.at(p).is_number()) return "-";
  return fmt::format("{}", j.at(p).get<long long>());
}
std::string text(const json& j, const char* pointer) {
  const json::json_pointer p(pointer);
  if (!j.contains(p)) return "-";
  if (j.at(p).is_boolean()) return j.at(p).get<bool>() ? "Yes" : "No";
  if (j.at(p).is_string()) return j.at(p).get<std::string>();
  return j.at(p).dump();
}

std::vector<Table> tables(const std::vector<Run>& runs) {
  std::vector<Table> t(7);
  t[0] = {"Table 6.1. Dataset properties.", {"dataset", "file format", "file(s) size", "faces", "animated camera", "morph targets"}, {}};
  t[1] = {"Table 6.2. Texture details.", {"dataset", "material count", "texture count", "texture size", "material workflow"}, {}};
  t[2] = {"Table 6.3. Animation details.",
          {"dataset", "animation frames", "static objects", "dynamic rigid objects", "armatures", "static point lights", "dynamic point lights"},
          {}};
  t[3] = {"Table 6.4. Change in camera position per frame (scene units).", {"dataset", "mean", "variance", "max"}, {}};
  t[4] = {"Table 6.5. Change in camera rotation per frame (degrees, geodesic).", {"dataset", "mean", "variance", "max"}, {}};
  t[5] = {"Table 6.6. Change in pitch, yaw and roll per frame (degrees).",
          {"dataset", "pitch mean", "pitch variance", "yaw mean", "yaw variance", "roll mean", "roll variance"},
          {}};
  t[6] = {"Table 6.7. Discarded pixels, % of the image, mean over the animation.",
          {"dataset", "frustum %", "world position %", "shading normal %", "direct radiance %", "indirect radiance %"},
          {}};
  for (const auto& r : runs) {
    const json& s = r.stats;
    const auto bytes = s.contains("/properties/total_bytes"_json_pointer) ? s["properties"]["total_bytes"].get<std::uint64_t>() : 0;
    const auto textureBytes =
        s.contains("/properties/texture_bytes"_json_pointer) ? s["properties"]["texture_bytes"].get<std::uint64_t>() : 0;
    t[0].rows.push_back({r.name, text(s, "/properties/file_format"), formatBytes(bytes), integer(s, "/properties/faces"),
                         text(s, "/properties/animated_camera"), text(s, "/properties/morph_targets")});
    t[1].rows.push_back({r.name, integer(s, "/properties/material_count"), integer(s, "/properties/texture_count"), formatBytes(textureBytes),
                         text(s, "/properties/material_workflow")});
    t[2].rows.push_back({r.name, integer(s, "/properties/animation_frames"), integer(s, "/properties/static_objects"),
                         integer(s, "/properties/dynamic_rigid_objects"), integer(s, "/properties/armatures"),
                         integer(s, "/properties/static_point_lights"), integer(s, "/properties/dynamic_point_lights")});
    t[3].rows.push_back({r.name, number(s, "/camera_motion/position/mean"), number(s, "/camera_motion/position/variance"),
                         number(s, "/camera_motion/position/max")});
    t[4].rows.push_back({r.name, number(s, "/camera_motion/rotation_degrees/mean"), number(s, "/camera_motion/rotation_degrees/variance"),
                         number(s, "/camera_motion/rotation_degrees/max")});
    t[5].rows.push_back({r.name, number(s, "/camera_motion/pitch_degrees/mean"), number(s, "/camera_motion/pitch_degrees/variance"),
                         number(s, "/camera_motion/yaw_degrees/mean"), number(s, "/camera_motion/yaw_degrees/variance"),
                         number(s, "/camera_motion/roll_degrees/mean"), number(s, "/camera_motion/roll_degrees/variance")});
    const json& d = r.discard;
    t[6].rows.push_back({r.name, number(d, "/mean/frustum"), number(d, "/mean/world_position"), number(d, "/mean/shading_normal"),
                         number(d, "/mean/direct_radiance"), number(d, "/mean/indirect_radiance")});
  }
  return t;
}

std::string htmlTable(const Table& t) {
  std::string out = fmt::format("<table>\n<caption>{}</caption>\n<thead><tr>", escapeHtml(t.title));
  for (const auto& h : t.header) out += "<th>" + escapeHtml(h) + "</th>";
  out += "</tr></thead>\n<tbody>\n";
  for (const auto& row : t.rows) {
    out += "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c) out += (c == 0 ? "<th scope=\"row\">" : "<td>") + escapeHtml(row[c]) + (c == 0 ? "</th>" : "</td>");
    out += "</tr>\n";
  }
  return out + "</tbody>\n</table>\n";
}

struct Figure {
  std::string caption;
  fs::path png;  // in the assets folder
};

}  // namespace

std::string base64Encode(const std::string& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const auto b0 = static_cast<unsigned char>(bytes[i]);
    const auto b1 = i + 1 < bytes.size() ? static_cast<unsigned char>(bytes[i + 1]) : 0u;
    const auto b2 = i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0u;
    const unsigned v = (b0 << 16) | (b1 << 8) | b2;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

Expected<ReportFiles> writeReport(const ReportOptions& options) {
  if (options.runs.empty()) return fail(ErrorCode::kUsage, "report: name at least one RUN folder");
  std::vector<Run> runs;
  std::map<std::string, int> seen;
  for (const auto& dir : options.runs) {
    auto run = readRun(dir);
    if (!run) return std::unexpected(run.error());
    if (const int n = ++seen[run->name]; n > 1) run->name += fmt::format(" ({})", n);
    runs.push_back(std::move(*run));
  }
  ReportFiles files;
  files.html = options.output;
  files.markdown = fs::path(options.output).replace_extension(".md");
  files.assets = fs::path(options.output).replace_extension("").string() + "_files";
  std::error_code ec;
  fs::create_directories(files.assets, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create: {}", files.assets.string(), ec.message());

  // Figures: per run, A.1 / A.2 (when a camera series is there), the discard series, thumbnails, masks.
  std::vector<std::pair<std::string, std::vector<Figure>>> figures;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const Run& r = runs[k];
    const std::string stem = fmt::format("run{}", k + 1);
    std::vector<Figure> list;
    if (!r.cameraCsv.empty()) {
      auto written = writeRotationPlotsFromCsv(r.cameraCsv, r.name, files.assets, stem);
      if (!written) return std::unexpected(written.error());
      list.push_back({"Figure A.1: change in pitch, yaw and roll per frame", files.assets / (stem + "_rotation_per_axis.png")});
      list.push_back({"Figure A.2: geodesic change in rotation per frame", files.assets / (stem + "_rotation_geodesic.png")});
    }
    std::vector<discard::FramePercentages> series;
    for (const auto& f : r.discard["frames"])
      series.push_back({f.value("frame", 0L), f.value("time", 0.0), f.value("frustum", 0.0), f.value("world_position", 0.0),
                        f.value("shading_normal", 0.0), f.value("direct_radiance", 0.0), f.value("indirect_radiance", 0.0)});
    if (!series.empty()) {
      auto written = writeDiscardPlot(series, r.name, files.assets, stem);
      if (!written) return std::unexpected(written.error());
      list.push_back({"Discarded pixels per frame (Eq. 3.4)", files.assets / (stem + "_discard.png")});
    }
    const int n = std::max(0, options.thumbnails);
    for (int t = 0; t < n && !r.frames.empty(); ++t) {
      const auto& entry = r.frames[static_cast<std::size_t>(t) * (r.frames.size() - 1) / static_cast<std::size_t>(std::max(1, n - 1))];
      auto frame = frames::readFrame(entry);
      if (!frame) return std::unexpected(frame.error());
      auto rgb = frames::previewImage(*frame);
      const fs::path png = files.assets / fmt::format("{}_frame_{:05d}.png", stem, entry.frame);
      if (auto ok = writeImage(png, FloatImage{frame->width, frame->height, 3, std::move(rgb), {}}); !ok) return std::unexpected(ok.error());
      list.push_back({fmt::format("Frame {} (direct + indirect, tone-mapped)", entry.frame), png});
      if (t == 0 && r.frames.size() == 1) break;
    }
    for (int t = 0; t < n && !r.masks.empty(); ++t) {
      const fs::path& mask = r.masks[static_cast<std::size_t>(t) * (r.masks.size() - 1) / static_cast<std::size_t>(std::max(1, n - 1))];
      const fs::path copy = files.assets / fmt::format("{}_{}", stem, mask.filename().string());
      fs::copy_file(mask, copy, fs::copy_options::overwrite_existing, ec);
      if (ec) return fail(ErrorCode::kIo, "{}: cannot copy: {}", mask.string(), ec.message());
      list.push_back({"Discard mask " + mask.stem().string() + " (red frustum, yellow position, blue normal, magenta direct, cyan indirect)", copy});
    }
    figures.emplace_back(r.name, std::move(list));
  }

  const auto allTables = tables(runs);
  // Markdown twin.
  std::string md = fmt::format("# {}\n\n", options.title);
  for (const auto& t : allTables) md += fmt::format("{}\n\n{}\n", t.title, markdownTable(t.header, t.rows));
  for (const auto& [name, list] : figures) {
    md += fmt::format("## {}\n\n", name);
    for (const auto& f : list)
      md += fmt::format("![{}]({}/{})\n\n", f.caption, files.assets.filename().string(), f.png.filename().string());
  }
  // HTML: everything inline.
  std::string html = fmt::format(R"(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{0}</title>
<style>
body {{ font-family: sans-serif; margin: 2em; color: #222; }}
table {{ border-collapse: collapse; margin: 1.5em 0; }}
caption {{ text-align: left; font-weight: bold; padding-bottom: .4em; }}
th, td {{ border: 1px solid #bbb; padding: .25em .6em; }}
td {{ text-align: right; font-variant-numeric: tabular-nums; }}
figure {{ display: inline-block; margin: .5em; vertical-align: top; }}
figure img {{ max-width: 600px; border: 1px solid #ccc; }}
figcaption {{ font-size: .85em; max-width: 600px; }}
</style></head><body>
<h1>{0}</h1>
)",
                                 escapeHtml(options.title));
  for (const auto& t : allTables) html += htmlTable(t);
  for (const auto& [name, list] : figures) {
    html += fmt::format("<section class=\"run\"><h2>{}</h2>\n", escapeHtml(name));
    for (const auto& f : list) {
      auto bytes = readWholeFile(f.png);
      if (!bytes) return std::unexpected(bytes.error());
      html += fmt::format("<figure><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"><figcaption>{0}</figcaption></figure>\n",
                          escapeHtml(f.caption), base64Encode(*bytes));
    }
    html += "</section>\n";
  }
  // Counts the images the browser decoded (a check for tests and a hint for readers).
  html += R"(<script>
window.addEventListener('load', () => {
  const images = Array.from(document.images);
  document.body.dataset.imagesDecoded = images.filter(i => i.complete && i.naturalWidth > 0).length;
  document.body.dataset.images = images.length;
});
</script>
</body></html>
)";
  if (auto ok = writeFileAtomic(files.markdown, md); !ok) return std::unexpected(ok.error());
  if (auto ok = writeFileAtomic(files.html, html); !ok) return std::unexpected(ok.error());
  return files;
}

}  // namespace dynbench::report
