#include "render/render_job_json.h"

#include <algorithm>
#include <array>
#include <climits>

#include <fmt/format.h>

#include "core/files.h"
#include "core/json_fields.h"
#include "frames/radiance_change.h"
#include "render/backend.h"

namespace dynbench::render {
namespace {

namespace fs = std::filesystem;

constexpr std::array kKeys = {"dynbench_render_job", "dataset", "output", "engine", "fps", "frames", "camera", "animation", "threads", "float32",
                              "blender", "width", "height", "samples_per_pixel", "bounces", "seed", "environment", "jitter", "pixel_filter",
                              "converge", "tolerance", "max_spp", "pairs", "max_pairs", "lights_per_point", "every_light_up_to", "light_selection",
                              "direct_threshold", "indirect_threshold"};

}  // namespace

nlohmann::json renderJobJson(const RenderJob& job) {
  const auto& s = job.settings;
  nlohmann::json j = {{"dynbench_render_job", kRenderJobVersion},
                      {"dataset", job.dataset.string()},
                      {"output", job.output.string()},
                      {"engine", job.engine},
                      {"fps", job.fps},
                      {"frames", {{"first", job.frames.first}, {"last", job.frames.last}, {"step", job.frames.step}}},
                      {"threads", job.threads},
                      {"float32", job.float32},
                      {"blender", job.blender},
                      {"width", s.width},
                      {"height", s.height},
                      {"samples_per_pixel", s.samplesPerPixel},
                      {"bounces", s.bounces},
                      {"seed", s.seed},
                      {"jitter", s.jitter},
                      {"pixel_filter", {{"type", pixelFilterName(s.pixelFilter.type)}, {"width", s.pixelFilter.width}}},
                      {"converge", s.converge},
                      {"tolerance", s.tolerance},
                      {"max_spp", s.maxSamplesPerPixel},
                      {"pairs", s.pairs},
                      {"max_pairs", s.maxPairs},
                      {"lights_per_point", s.lightsPerPoint},
                      {"every_light_up_to", s.everyLightUpTo},
                      {"light_selection", lightSelectionName(s.learnedLightSelection)},
                      {"direct_threshold", s.directThresholdFraction},
                      {"indirect_threshold", s.indirectThresholdFraction}};
  if (s.constantEnvironment) j["environment"] = {s.constantEnvironment->r, s.constantEnvironment->g, s.constantEnvironment->b};
  else j["environment"] = s.useEnvironment ? "dataset" : "none";
  if (job.camera) j["camera"] = *job.camera;
  if (job.animation) j["animation"] = *job.animation;
  return j;
}

Expected<RenderJob> parseRenderJob(const nlohmann::json& document, const fs::path& source) {
  const JsonSettingsReader r(document, source);
  if (auto ok = r.jobDocument("the render job", kKeys, "dynbench_render_job", kRenderJobVersion); !ok) return std::unexpected(ok.error());

  RenderJob job;
  RenderSettings& s = job.settings;
  for (const char* required : {"/dataset", "/output"})
    if (!r.has(required)) return r.bad(required, "a path, missing");
  std::string dataset, output;
  std::optional<std::string> camera, animation;
  std::string pixelFilter = pixelFilterName(s.pixelFilter.type);
  std::string lightSelection = lightSelectionName(s.learnedLightSelection);
  bool widthGiven = r.has("/pixel_filter/width");
  for (auto ok : {r.string("/dataset", dataset), r.string("/output", output), r.string("/engine", job.engine), r.number("/fps", job.fps, 0.0, 1e6, true),
                  r.integer("/frames/first", job.frames.first, 0, INT_MAX), r.integer("/frames/last", job.frames.last, -1, INT_MAX),
                  r.integer("/frames/step", job.frames.step, 1, INT_MAX), r.string("/camera", camera), r.string("/animation", animation),
                  r.integer("/threads", job.threads, 0, 4096), r.boolean("/float32", job.float32), r.string("/blender", job.blender),
                  r.integer("/width", s.width, 1, 65536), r.integer("/height", s.height, 1, 65536),
                  r.integer("/samples_per_pixel", s.samplesPerPixel, 1, INT_MAX), r.integer("/bounces", s.bounces, 0, INT_MAX),
                  r.boolean("/jitter", s.jitter), r.string("/pixel_filter/type", pixelFilter),
                  r.number("/pixel_filter/width", s.pixelFilter.width, 1e-3, 8.0), r.boolean("/converge", s.converge),
                  r.number("/tolerance", s.tolerance, 1e-4, 10.0), r.integer("/max_spp", s.maxSamplesPerPixel, 1, INT_MAX),
                  r.boolean("/pairs", s.pairs), r.integer("/max_pairs", s.maxPairs, frames::kFirstPairs, 1 << 20),
                  r.integer("/lights_per_point", s.lightsPerPoint, 0, 64),
                  r.integer("/every_light_up_to", s.everyLightUpTo, 0, 4096), r.string("/light_selection", lightSelection), r.number("/direct_threshold", s.directThresholdFraction, 0.0, 10.0, true),
                  r.number("/indirect_threshold", s.indirectThresholdFraction, 0.0, 10.0, true)})
    if (!ok) return std::unexpected(ok.error());
  if (dataset.empty()) return r.bad("/dataset", "a path, found \"\"");
  if (output.empty()) return r.bad("/output", "a path, found \"\"");
  job.dataset = dataset;
  job.output = output;
  job.camera = camera;
  job.animation = animation;
  if (job.frames.last >= 0 && job.frames.last < job.frames.first)
    return r.bad("/frames/last", fmt::format("-1 (to the end) or at least /frames/first ({}), found {}", job.frames.first, job.frames.last));
  if (!findBackend(job.engine)) return r.bad("/engine", fmt::format("one of {}, found \"{}\"", fmt::join(backendNames(), ", "), job.engine));
  const auto learned = parseLightSelection(lightSelection);
  if (!learned) return r.bad("/light_selection", fmt::format("\"learned\" or \"tree\", found \"{}\"", lightSelection));
  s.learnedLightSelection = *learned;
  auto filter = parsePixelFilter(pixelFilter);
  if (!filter) return r.bad("/pixel_filter/type", fmt::format("a pixel filter ({})", filter.error().message));
  s.pixelFilter.type = *filter;
  if (!widthGiven) s.pixelFilter.width = defaultPixelFilterWidth(*filter);
  // As the command line: pairs unless said otherwise when converging on the embree engine.
  if (!r.has("/pairs")) s.pairs = s.converge && job.engine == "embree";
  if (auto ok = r.count("/seed", s.seed); !ok) return std::unexpected(ok.error());
  if (r.has("/environment")) {
    const auto& e = document.at("environment");
    if (e == "dataset") {
      s.useEnvironment = true;
    } else if (e == "none") {
      s.useEnvironment = false;
    } else if (e.is_array() && e.size() == 3 && std::all_of(e.begin(), e.end(), [](const auto& c) { return c.is_number() && c.template get<double>() >= 0; })) {
      s.constantEnvironment = glm::dvec3(e[0].get<double>(), e[1].get<double>(), e[2].get<double>());
    } else {
      return r.bad("/environment", fmt::format("\"dataset\", \"none\" or a radiance [R, G, B] >= 0, found {}", e.dump()));
    }
  }
  return job;
}

Expected<RenderJob> readRenderJob(const fs::path& path) { return readJsonDocument(path, parseRenderJob); }

Expected<void> writeRenderJob(const RenderJob& job, const fs::path& path) { return writeFileAtomic(path, jsonFileText(renderJobJson(job))); }

}  // namespace dynbench::render
