#include "core/json_fields.h"
#include "pipeline/stages.h"

#include <cctype>
#include <map>

#include <fmt/format.h>

#include "core/files.h"
#include "core/image_io.h"
#include "metrics/camera_motion.h"
#include "metrics/properties.h"
#include "report/plots.h"
#include "report/tables.h"
#include "scene/load.h"

namespace dynbench::pipeline {
namespace {

namespace fs = std::filesystem;

// "scene.gltf", or "scene.gltf (2)" when two inputs share a file name.
std::vector<std::string> uniqueNames(const std::vector<fs::path>& inputs) {
  std::vector<std::string> names;
  std::map<std::string, int> seen;
  for (const auto& p : inputs) {
    std::string name = p.filename().string();
    if (name.empty()) name = p.parent_path().filename().string();
    const int n = ++seen[name];
    names.push_back(n == 1 ? name : fmt::format("{} ({})", name, n));
  }
  return names;
}

}  // namespace

std::string fileStem(const std::string& label) {
  std::string stem;
  for (char c : label) stem += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return stem;
}

Expected<StatsOutcome> runStats(const StatsStage& stage, const StatsProgress& progress) {
  if (!(stage.fps > 0)) return fail(ErrorCode::kUsage, "--fps must be positive (got {})", stage.fps);
  if (!(stage.sequenceRate > 0)) return fail(ErrorCode::kUsage, "--sequence-rate must be positive (got {})", stage.sequenceRate);
  StatsOutcome out;
  const auto names = uniqueNames(stage.inputs);
  for (std::size_t i = 0; i < stage.inputs.size(); ++i) {
    const fs::path& input = stage.inputs[i];
    if (progress) progress(i, input);
    scene::LoadOptions loadOptions;
    loadOptions.sequenceRate = stage.sequenceRate;
    auto scene = scene::loadScene(input, loadOptions);
    if (!scene) return std::unexpected(scene.error());
    if (stage.animation && !scene::keepOnlyAnimation(*scene, *stage.animation)) {
      std::string list;
      for (std::size_t a = 0; a < scene->animations.size(); ++a) list += fmt::format("{}{} '{}'", a ? ", " : "", a, scene->animations[a].name);
      return fail(ErrorCode::kUsage, "{}: --animation '{}' names no animation (animations in the file: {})", input.string(),
                  *stage.animation, list.empty() ? "none" : list);
    }
    report::StatsRow row;
    row.properties = metrics::measureProperties(*scene, stage.fps);
    out.warnings.insert(out.warnings.end(), row.properties.warnings.begin(), row.properties.warnings.end());
    row.name = names[i];
    row.path = input.string();
    auto motion = metrics::measureCameraMotion(*scene, stage.fps, stage.camera);
    if (!motion) return std::unexpected(motion.error());
    row.motion = std::move(*motion);
    out.rows.push_back(std::move(row));
  }
  out.markdown = report::statsMarkdown(out.rows);
  if (!stage.json.empty())
    if (auto ok = writeFileAtomic(stage.json, jsonFileText(report::statsJson(out.rows, stage.fps))); !ok) return std::unexpected(ok.error());
  if (!stage.csv.empty())
    if (auto ok = writeFileAtomic(stage.csv, report::statsCsv(out.rows)); !ok) return std::unexpected(ok.error());
  for (const auto& row : out.rows) {
    if (!row.motion.hasCamera) {
      if (!stage.seriesDir.empty() || !stage.plotsDir.empty()) out.warnings.push_back(row.path + ": no camera, so no series or plots");
      continue;
    }
    const std::string stem = fileStem(row.name);
    if (!stage.seriesDir.empty())
      if (auto ok = writeFileAtomic(stage.seriesDir / (stem + "_camera.csv"), report::cameraSeriesCsv(row.motion)); !ok)
        return std::unexpected(ok.error());
    if (!stage.plotsDir.empty())
      if (auto written = report::writeRotationPlots(row.motion, row.name, stage.plotsDir, stem); !written)
        return std::unexpected(written.error());
  }
  return out;
}

namespace {

// The render job's scene: the dataset, reduced to --animation when one is named.
Expected<scene::Scene> renderScene(const render::RenderJob& job) {
  auto scene = scene::loadScene(job.dataset);
  if (!scene) return std::unexpected(scene.error());
  if (job.animation && !scene::keepOnlyAnimation(*scene, *job.animation))
    return fail(ErrorCode::kUsage, "{}: --animation '{}' names no animation", job.dataset.string(), *job.animation);
  return scene;
}

}  // namespace

Expected<render::RenderSummary> runRender(const RenderStage& stage, const render::RenderProgress& progress,
                                          std::vector<std::string>* sceneWarnings) {
  auto scene = renderScene(stage.job);
  if (!scene) return std::unexpected(scene.error());
  if (sceneWarnings) sceneWarnings->insert(sceneWarnings->end(), scene->warnings.begin(), scene->warnings.end());
  return render::renderDataset(*scene, stage.job, progress);
}

Expected<std::vector<long>> renderFrames(const RenderStage& stage) {
  auto scene = renderScene(stage.job);
  if (!scene) return std::unexpected(scene.error());
  return render::jobFrames(*scene, stage.job);
}

Expected<DiscardOutcome> runDiscard(const DiscardStage& stage, const discard::DiscardProgress& progress) {
  const auto& t = stage.thresholds;
  for (const auto& [name, value] : {std::pair{"--threshold-position", t.position}, {"--threshold-normal", t.normal},
                                    {"--threshold-direct", t.direct}, {"--threshold-indirect", t.indirect}})
    if (!(value >= 0)) return fail(ErrorCode::kUsage, "{} must be 0 or more (got {})", name, value);
  discard::MaskSink masks;
  if (!stage.masks.empty())
    masks = [&](const discard::FeatureFrame& frame, const discard::DiscardResult& r) -> Expected<void> {
      return writeImage(stage.masks / fmt::format("discard_{:05d}.png", frame.frame),
                        FloatImage{frame.width, frame.height, 3, discard::maskImage(frame, r.mask), {}, {}, {}});
    };
  auto run = discard::discardFolder(stage.frames, t, masks, progress, stage.includeCuts);
  if (!run) return std::unexpected(run.error());
  DiscardOutcome out;
  const std::string name = stage.frames.filename().empty() ? stage.frames.parent_path().filename().string() : stage.frames.filename().string();
  out.markdown = report::markdownTable(
      report::discardTable({{name, run->mean, run->thresholds.radianceTest}}, fmt::format("{} frame pairs{}, {}x{}", run->frames.size(),
                                                            run->cutPairs == 0 ? ""
                                                            : run->cutsInMean ? fmt::format(", {} of them camera cuts", run->cutPairs)
                                                                              : fmt::format(" of which {} camera cuts are left out", run->cutPairs),
                                                            run->width, run->height)));
  if (!stage.json.empty())
    if (auto ok = writeFileAtomic(stage.json, jsonFileText(discard::discardJson(*run, stage.frames.string()))); !ok) return std::unexpected(ok.error());
  if (!stage.csv.empty()) {
    std::string csv = "frame,time";
    for (const auto& column : discard::kTable67Columns) csv += fmt::format(",{}", column.key);
    csv += ",direct_low,direct_high,indirect_low,indirect_high,cut\n";
    // Interval columns are empty for the tests that give none.
    auto bound = [](const std::optional<discard::Interval>& i, bool high) { return i ? fmt::format("{}", high ? i->high : i->low) : std::string(); };
    for (const auto& f : run->frames)
      csv += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", f.frame, f.time, f.frustum, f.position, f.normal, f.direct, f.indirect,
                         bound(f.directInterval, false), bound(f.directInterval, true), bound(f.indirectInterval, false),
                         bound(f.indirectInterval, true), f.cut ? 1 : 0);
    if (auto ok = writeFileAtomic(stage.csv, csv); !ok) return std::unexpected(ok.error());
  }
  if (!stage.plots.empty())
    if (auto written = report::writeDiscardPlot(run->frames, name, stage.plots, name.empty() ? "frames" : name); !written)
      return std::unexpected(written.error());
  out.run = std::move(*run);
  return out;
}

Expected<report::ReportFiles> runReport(const report::ReportOptions& options) {
  if (options.output.extension() != ".html")
    return fail(ErrorCode::kUsage, "-o {}: the report is an .html file (its Markdown twin is written beside it)", options.output.string());
  return report::writeReport(options);
}

}  // namespace dynbench::pipeline
