#include "report/html_report.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <span>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/files.h"
#include "core/image_io.h"
#include "discard/discard.h"
#include "evaluate/evaluate.h"
#include "frames/frame_io.h"
#include "frames/preview.h"
#include "report/plots.h"
#include "report/reference.h"
#include "report/stats_output.h"
#include "report/tables.h"
#include "report/video.h"
#include "core/json_fields.h"

namespace dynbench::report {
namespace {

namespace fs = std::filesystem;

struct Run {
  std::string name;
  fs::path dir;
  StatsRow stats;
  discard::DiscardRun discard;
  std::string cameraCsv;
  std::vector<fs::path> masks;
  std::vector<frames::FrameEntry> frames;
  std::optional<evaluate::EvaluateRun> evaluation;  // RUN/evaluate.json, when the run has one
  std::optional<evaluate::EvaluateRun> stillEvaluation;  // RUN/evaluate-still.json: the methods built for the unjittered input
  std::optional<evaluate::MeanWithError> floor;          // RUN/floor.json: the reference's noise floor

  // Each scored method with its input and the folder of its outputs.
  struct Scored {
    const evaluate::MethodScores* scores;
    const char* input;
    const char* folder;
    const evaluate::EvaluateRun* run;
  };
  std::vector<Scored> scored() const {
    std::vector<Scored> out;
    if (evaluation)
      for (const auto& m : evaluation->methods) out.push_back({&m, stillEvaluation ? "jittered" : "", "evaluate", &*evaluation});
    if (stillEvaluation)
      for (const auto& m : stillEvaluation->methods) out.push_back({&m, "still", "evaluate-still", &*stillEvaluation});
    return out;
  }
};

// `none`'s mean ꟻLIP in one evaluation (nullopt without it).
std::optional<double> noneFlip(const evaluate::EvaluateRun& run) {
  for (const auto& m : run.methods)
    if (m.name == "none" && m.flip.count) return m.flip.mean;
  return std::nullopt;
}

Expected<Run> readRun(const fs::path& dir) {
  Run run;
  run.dir = dir;
  run.name = dir.filename().string().empty() ? dir.parent_path().filename().string() : dir.filename().string();
  auto need = [&](const fs::path& file, const char* how) -> Expected<void> {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return fail(ErrorCode::kIo, "{}: missing; write it with `{}`", file.string(), how);
    return {};
  };
  if (auto ok = need(dir / "stats.json", "dynbench stats DATASET --json RUN/stats.json"); !ok) return std::unexpected(ok.error());
  if (auto ok = need(dir / "discard.json", "dynbench discard FRAMES --json RUN/discard.json"); !ok) return std::unexpected(ok.error());
  auto stats = readJsonFile(dir / "stats.json");
  if (!stats) return std::unexpected(stats.error());
  auto row = readStatsRow(*stats, dir / "stats.json", 0);
  if (!row) return std::unexpected(row.error());
  run.stats = std::move(*row);
  auto discarded = discard::readDiscardJson(dir / "discard.json");
  if (!discarded) return std::unexpected(discarded.error());
  run.discard = std::move(*discarded);
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
  for (const auto& [file, target] : {std::pair{"evaluate.json", &run.evaluation}, std::pair{"evaluate-still.json", &run.stillEvaluation}})
    if (fs::is_regular_file(dir / file, ec)) {
      auto evaluated = evaluate::readEvaluateJson(dir / file);
      if (!evaluated) return std::unexpected(evaluated.error());
      *target = std::move(*evaluated);
    }
  if (fs::is_regular_file(dir / "floor.json", ec)) {
    auto floor = evaluate::readNoiseFloorJson(dir / "floor.json");
    if (!floor) return std::unexpected(floor.error());
    run.floor = *floor;
  }
  if (fs::is_directory(dir / "frames", ec))
    if (auto listed = frames::listFrames(dir / "frames")) run.frames = *listed;
  return run;
}

std::vector<MethodsRow> methodRows(const std::vector<Run>& runs) {
  std::vector<MethodsRow> rows;
  for (const auto& r : runs)
    for (const auto& m : r.scored()) rows.push_back({r.name, m.input, *m.scores, noneFlip(*m.run), r.floor});
  return rows;
}

// A sentence for each dataset where a history method ends worse than `none` on its own input by
// more than the reference's noise floor: what the suite found about why (docs/suite.md).
std::string losesToNoneNote(const std::vector<Run>& runs) {
  std::vector<std::string> cases;
  for (const MethodsRow& row : methodRows(runs))
    if (row.losesToNone()) cases.push_back(fmt::format("{} on {} ({:.3f} times none's ꟻLIP)", row.scores.name, row.dataset, row.scores.flip.mean / *row.noneFlip));
  if (cases.empty()) return {};
  return fmt::format("Worse than `none` on its own input, by more than the reference's noise floor: {}. A method with a history pays for it "
                     "even with no noise to remove: each frame's history is a resample of the last, and sub-pixel motion blurs texture "
                     "detail through it (accumulate and SVGF through bilinear taps; TAA's Catmull-Rom taps and neighbourhood clip pay "
                     "less). Where that cost exceeds the 4-path input's noise, the method loses to `none`; the suites measured it on "
                     "colos (docs/suite.md, \"Why accumulate and SVGF still lose to none on colos in v2\").",
                     fmt::join(cases, "; "));
}

std::vector<Table> tables(const std::vector<Run>& runs) {
  std::vector<StatsRow> statsRows;
  std::vector<DiscardRow> discardRows;
  for (const auto& r : runs) {
    statsRows.push_back(r.stats);
    statsRows.back().name = r.name;
    discardRows.push_back({r.name, r.discard.mean, r.discard.thresholds.radianceTest});
  }
  auto all = statsTables(statsRows);
  all.push_back(discardTable(discardRows));
  const auto rows = methodRows(runs);
  if (!rows.empty()) all.push_back(temporalMethodsTable(rows));
  return all;
}

// The geodesic rotation per frame of a camera series CSV (stats --series), NaN where there is none:
// frame 0 and cut frames (the series' `cut` column, when it has one).
std::vector<double> rotationSeries(const std::string& csv) {
  std::vector<double> out;
  std::istringstream in(csv);
  std::string header, line;
  if (!std::getline(in, header)) return out;
  int rotationColumn = -1, cutColumn = -1, column = 0;
  for (std::istringstream h(header); std::getline(h, line, ','); ++column) {
    if (line == "rotation_delta_deg") rotationColumn = column;
    if (line == "cut") cutColumn = column;
  }
  if (rotationColumn < 0) return out;
  for (std::size_t row = 0; std::getline(in, line); ++row) {
    std::vector<std::string> cells;
    for (std::istringstream c(line); std::getline(c, header, ',');) cells.push_back(header);
    const bool cut = cutColumn >= 0 && cutColumn < static_cast<int>(cells.size()) && cells[static_cast<std::size_t>(cutColumn)] == "1";
    const bool has = rotationColumn < static_cast<int>(cells.size());
    out.push_back(row == 0 || cut || !has ? std::nan("") : std::strtod(cells[static_cast<std::size_t>(rotationColumn)].c_str(), nullptr));
  }
  return out;
}

// The colours of discard::maskImage, in its order of reasons.
constexpr const char* kMaskLegend = "red frustum, yellow position, blue normal, magenta direct, cyan indirect, white undecided (radiance)";

// Up to n indices of [0, count), evenly spaced from the first to the last, none twice.
std::vector<std::size_t> evenlySpaced(std::size_t count, int n) {
  std::vector<std::size_t> picked;
  for (int t = 0; t < n && count > 0; ++t) {
    const std::size_t k = static_cast<std::size_t>(t) * (count - 1) / static_cast<std::size_t>(std::max(1, n - 1));
    if (picked.empty() || picked.back() != k) picked.push_back(k);
  }
  return picked;
}

struct Figure {
  std::string caption;
  fs::path png;       // in the assets folder: a PNG, or the WebM of `video`
  bool wide = false;  // shown at the page's width (the shared-axes comparisons), not as a 600-pixel tile
  std::optional<Video> video = std::nullopt;
  bool pixels = false;  // a frame-sized image (thumbnail, mask, heatmap): enlarged by a whole factor, pixels kept sharp
};

// A run's section: its figures, and how its frames were sampled (said once, above them).
struct RunFigures {
  std::string name, sampling;
  std::vector<Figure> list;
};

// A figure as HTML with its PNG (or WebM) inline. Videos play muted in a loop, with controls to
// pause and step; data-frames is the frame count the encoder was given.
Expected<std::string> figureHtml(const Figure& f) {
  auto bytes = readWholeFile(f.png);
  if (!bytes) return std::unexpected(bytes.error());
  if (f.video) {
    // Small videos are shown enlarged by a whole factor, pixels kept sharp, to at least 270 rows.
    const int factor = std::max(1, std::min((270 + f.video->height - 1) / f.video->height, 1200 / f.video->width));
    return fmt::format(
        "<figure class=\"wide\"><video src=\"data:video/webm;base64,{1}\" width=\"{2}\" height=\"{3}\" data-frames=\"{4}\" "
        "autoplay loop muted playsinline controls></video><figcaption>{0}</figcaption></figure>\n",
        escapeHtml(f.caption), base64Encode(*bytes), f.video->width * factor, f.video->height * factor, f.video->frames);
  }
  std::string size;
  if (f.pixels) {
    // Up to 400 pixels wide, so that three fit beside each other on a laptop's screen.
    auto header = readImageHeader(f.png);
    if (!header) return std::unexpected(header.error());
    const int factor = std::max(1, 400 / std::max(1, header->width));
    size = fmt::format(" class=\"pixels\" width=\"{}\" height=\"{}\"", header->width * factor, header->height * factor);
  }
  return fmt::format("<figure{2}><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"{3}><figcaption>{0}</figcaption></figure>\n",
                     escapeHtml(f.caption), base64Encode(*bytes), f.wide ? " class=\"wide\"" : "", size);
}

// A figure in the Markdown twin: an image, or a link to the video (Markdown has no video).
std::string figureMarkdown(const Figure& f, const fs::path& assets) {
  const std::string file = assets.filename().string() + "/" + f.png.filename().string();
  return f.video ? fmt::format("[{}]({})\n\n", f.caption, file) : fmt::format("![{}]({})\n\n", f.caption, file);
}

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

// Every run on the same axes: rotation per frame and its distribution, discard per frame, Table
// 6.7 as bars (with the thesis's published rows when asked for), and the temporal methods' ꟻLIP per
// frame.
Expected<std::vector<Figure>> comparisonFigures(const std::vector<Run>& runs, const std::optional<Reference>& reference, const fs::path& assets) {
  std::vector<Figure> comparison;
  {
    std::vector<ComparisonSeries> series;
    for (const Run& r : runs) {
      ComparisonSeries s;
      s.name = r.name;
      s.rotation = rotationSeries(r.cameraCsv);
      s.discard = r.discard.frames;
      s.mean = r.discard.mean;
      series.push_back(std::move(s));
    }
    for (const auto& t : reference ? reference->tables : std::span<const ReferenceTable>{}) {
      if (t.table != "6.7") continue;
      for (const auto& row : t.rows) {
        ComparisonSeries s;
        s.name = row.dataset;
        s.published = true;
        discard::FramePercentages m;
        for (std::size_t c = 0; c < discard::kTable67Columns.size() && c < row.cells.size(); ++c)
          m.*discard::kTable67Columns[c].member = std::strtod(row.cells[c].c_str(), nullptr);
        s.mean = m;
        series.push_back(std::move(s));
      }
    }
    auto written = writeComparisonPlots(series, assets, "all");
    if (!written) return std::unexpected(written.error());
    static const std::map<std::string, std::string> captions = {
        {"all_rotation.png", "Geodesic change in camera rotation per frame, every dataset on one axis (cut frames left out)"},
        {"all_cdf_rotation_cdf.png", "Cumulative distribution of the change in rotation per frame: the share of frames turning at most x degrees"},
        {"all_discard.png", "Discarded pixels per frame pair, one panel per feature, every dataset on one axis (cut pairs left out)"},
        {"all_table67.png", "Table 6.7 as bars: mean discard per feature; whiskers: 95 % intervals of the radiance columns"}};
    for (const auto& png : *written) {
      const auto caption = captions.find(png.filename().string());
      comparison.push_back({caption != captions.end() ? caption->second : png.stem().string(), png, true});
    }
  }
  // Temporal methods of every run on one axis, then per run (below) each method's worst frame.
  {
    std::vector<std::pair<std::string, std::vector<double>>> series;
    for (const Run& r : runs)
      for (const auto& m : r.scored()) {
        std::vector<double> values;
        for (const auto& f : m.scores->frames) values.push_back(f.flip);
        series.emplace_back(fmt::format("{} {}{}", r.name, m.scores->name, std::string(m.input) == "still" ? " (still)" : ""), std::move(values));
      }
    if (!series.empty()) {
      auto written = writeMethodsPlot(series, assets, "all");
      if (!written) return std::unexpected(written.error());
      comparison.push_back({"ꟻLIP per frame of every temporal method and dataset (lower is better)", assets / "all_methods_flip.png", true});
    }
  }

  return comparison;
}

// One run's section (RUN is the k-th, counting from 0): Figures A.1 / A.2 (when a camera series is
// there), the discard series, the video, thumbnails and masks, and each method's worst frame.
Expected<RunFigures> runFigures(const Run& r, std::size_t k, const ReportOptions& options, const fs::path& assets) {
  std::error_code ec;
  const std::string stem = fmt::format("run{}", k + 1);
  std::vector<Figure> list;
  if (!r.cameraCsv.empty()) {
    auto written = writeRotationPlotsFromCsv(r.cameraCsv, r.name, assets, stem);
    if (!written) return std::unexpected(written.error());
    list.push_back({"Figure A.1: change in pitch, yaw and roll per frame", assets / (stem + "_rotation_per_axis.png")});
    list.push_back({"Figure A.2: geodesic change in rotation per frame", assets / (stem + "_rotation_geodesic.png")});
  }
  const auto& series = r.discard.frames;
  if (!series.empty()) {
    auto written = writeDiscardPlot(series, r.name, assets, stem);
    if (!written) return std::unexpected(written.error());
    list.push_back({"Discarded pixels per frame (Eq. 3.4)", assets / (stem + "_discard.png")});
  }
  // The video and thumbnails share one exposure, so that they neither flicker nor disagree, and
  // say how many samples per pixel they show.
  const int n = std::max(0, options.thumbnails);
  std::optional<frames::PreviewToneMap> toneMap;
  std::string sampling;
  if (!r.frames.empty() && (n > 0 || options.videoFrames > 0)) {
    auto map = clipToneMap(r.frames);
    if (!map) return std::unexpected(map.error());
    toneMap = *map;
    auto note = samplingNote(r.frames);
    if (!note) return std::unexpected(note.error());
    sampling = *note;
  }
  if (toneMap && options.videoFrames > 0) {
    VideoOptions videoOptions;
    videoOptions.maxFrames = options.videoFrames;
    auto video = writeRunVideo(r.frames, r.dir / "masks", *toneMap, assets / (stem + "_motion.webm"), videoOptions);
    if (!video) return std::unexpected(video.error());
    std::string caption = fmt::format("Frames {}-{} at {:g} fps ({} frames): direct + indirect radiance, tone-mapped", video->firstFrame,
                                      video->lastFrame, video->fps, video->frames);
    if (video->masks)
      caption += fmt::format("; beside it, the discard mask of the pair ending at each frame ({}; grey: no pair, at the first frame or a camera cut)",
                             kMaskLegend);
    if (static_cast<std::size_t>(video->frames) < r.frames.size())
      caption += fmt::format("; the first {} of the run's {} frames", video->frames, r.frames.size());
    list.insert(list.begin(), {caption, video->file, true, *video});  // first: motion is the subject
  }
  for (const std::size_t f : evenlySpaced(r.frames.size(), n)) {
    const auto& entry = r.frames[f];
    auto frame = frames::readFrame(entry);
    if (!frame) return std::unexpected(frame.error());
    auto rgb = frames::previewImage(*frame, *toneMap);
    const fs::path png = assets / fmt::format("{}_frame_{:05d}.png", stem, entry.frame);
    if (auto ok = writeImage(png, FloatImage{frame->width, frame->height, 3, std::move(rgb), {}, {}, {}}); !ok) return std::unexpected(ok.error());
    list.push_back({fmt::format("Frame {} (direct + indirect, tone-mapped)", entry.frame), png, false, std::nullopt, true});
  }
  for (const std::size_t f : evenlySpaced(r.masks.size(), n)) {
    const fs::path& mask = r.masks[f];
    const fs::path copy = assets / fmt::format("{}_{}", stem, mask.filename().string());
    fs::copy_file(mask, copy, fs::copy_options::overwrite_existing, ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot copy: {}", mask.string(), ec.message());
    list.push_back({fmt::format("Discard mask {} ({})", mask.stem().string(), kMaskLegend), copy,
                    false, std::nullopt, true});
  }
  for (const auto& scored : r.scored()) {
    const evaluate::MethodScores& m = *scored.scores;
    const fs::path heat = r.dir / scored.folder / evaluate::methodFolder(m.name) / "flip_worst.png";
    if (!fs::is_regular_file(heat, ec)) continue;
    const fs::path copy = assets / fmt::format("{}_{}_{}_flip_worst.png", stem, scored.folder, evaluate::methodFolder(m.name));
    fs::copy_file(heat, copy, fs::copy_options::overwrite_existing, ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot copy: {}", heat.string(), ec.message());
    list.push_back({fmt::format("{}{}: ꟻLIP error of its worst frame, {} (magma: black 0, yellow 1)", m.name,
                                *scored.input ? fmt::format(" ({} input)", scored.input) : "", m.worstFrame),
                    copy, false, std::nullopt, true});
  }
  if (!sampling.empty())
    sampling = fmt::format("Video and thumbnails: {}/frames, {}; one exposure for all of them.", r.dir.filename().string(), sampling);
  return RunFigures{r.name, sampling, std::move(list)};
}

Expected<ReportFiles> writeReport(const ReportOptions& options) {
  if (options.runs.empty()) return fail(ErrorCode::kUsage, "report: name at least one RUN folder");
  // The published rows (--reference thesis): read once, for the tables and Table 6.7's bars.
  std::optional<Reference> reference;
  if (!options.reference.empty()) {
    if (options.reference != "thesis") return fail(ErrorCode::kUsage, "--reference '{}': expected thesis", options.reference);
    auto thesis = thesisReference();
    if (!thesis) return std::unexpected(thesis.error());
    reference = std::move(*thesis);
  }
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

  auto comparisonOrError = comparisonFigures(runs, reference, files.assets);
  if (!comparisonOrError) return std::unexpected(comparisonOrError.error());
  const std::vector<Figure>& comparison = *comparisonOrError;
  // Figures: per run.
  std::vector<RunFigures> figures;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    auto section = runFigures(runs[k], k, options, files.assets);
    if (!section) return std::unexpected(section.error());
    figures.push_back(std::move(*section));
  }

  auto allTables = tables(runs);
  std::string referenceNote;
  if (reference) {
    appendReferenceRows(allTables, *reference);
    referenceNote = "Rows marked (published), in grey, are not measured here: they are the thesis's own numbers (J. Alanko, Dynamic "
                    "benchmark for graphics rendering, Tampere University 2021, Tables 6.1-6.7). Table 6.5's are converted to the full "
                    "angle (mean and max doubled, variance times four); Table 6.4's are in each dataset's own units; Table 6.7's come from "
                    "the thesis's Cycles renders at 1920x1080 and 1024 spp.";
  }
  // Markdown twin.
  std::string md = fmt::format("# {}\n\n", options.title);
  if (!referenceNote.empty()) md += referenceNote + "\n\n";
  const std::string losesNote = losesToNoneNote(runs);
  for (const auto& t : allTables) md += markdownTable(t);
  if (!losesNote.empty()) md += losesNote + "\n\n";
  for (const auto& f : comparison) md += figureMarkdown(f, files.assets);
  for (const auto& [name, sampling, list] : figures) {
    md += fmt::format("## {}\n\n", name);
    if (!sampling.empty()) md += sampling + "\n\n";
    for (const auto& f : list) md += figureMarkdown(f, files.assets);
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
tr.published {{ color: #777; font-style: italic; }}
figure.wide {{ display: block; }}
figure.wide img, figure.wide figcaption, figure.wide video {{ max-width: min(100%, 1200px); height: auto; }}
p.reference {{ max-width: 60em; }}
video {{ image-rendering: pixelated; background: #000; }}
img.pixels {{ image-rendering: pixelated; }}
figure:has(img.pixels) figcaption {{ max-width: 400px; }}
</style></head><body>
<h1>{0}</h1>
)",
                                 escapeHtml(options.title));
  if (!referenceNote.empty()) html += "<p class=\"reference\">" + escapeHtml(referenceNote) + "</p>\n";
  for (const auto& t : allTables) html += htmlTable(t);
  if (!losesNote.empty()) html += "<p class=\"reference\">" + escapeHtml(losesNote) + "</p>\n";
  for (const auto& f : comparison) {
    auto figure = figureHtml(f);
    if (!figure) return std::unexpected(figure.error());
    html += *figure;
  }
  for (const auto& [name, sampling, list] : figures) {
    html += fmt::format("<section class=\"run\"><h2>{}</h2>\n", escapeHtml(name));
    if (!sampling.empty()) html += "<p class=\"sampling\">" + escapeHtml(sampling) + "</p>\n";
    for (const auto& f : list) {
      auto figure = figureHtml(f);
      if (!figure) return std::unexpected(figure.error());
      html += *figure;
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
  files.htmlBytes = html.size();
  for (const auto& [name, sampling, list] : figures)
    for (const auto& f : list) ++(f.video ? files.videos : files.images);
  files.images += static_cast<int>(comparison.size());
  return files;
}

}  // namespace dynbench::report
