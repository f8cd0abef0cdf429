#include "render/render_job.h"

#include <charconv>
#include <chrono>
#include <mutex>
#include <thread>
#include <set>

#include <tbb/global_control.h>

#include "core/files.h"
#include "core/image_io.h"
#include "frames/radiance_change.h"
#include "render/backend.h"
#include "scene/queries.h"
#include "frames/frame_io.h"
#include "scene/pose.h"
#include "scene/dataset_digest.h"

namespace dynbench::render {
namespace {

namespace fs = std::filesystem;

std::optional<long> parseLong(std::string_view s) {
  long v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

}  // namespace

Expected<FrameRange> parseFrameRange(const std::string& text) {
  auto bad = [&] {
    return fail(ErrorCode::kUsage, "--frames '{}': expected A:B[:STEP], A: or A with whole numbers A >= 0, B >= A, STEP >= 1", text);
  };
  FrameRange r;
  const auto first = text.find(':');
  if (first == std::string::npos) {
    const auto v = parseLong(text);
    if (!v || *v < 0) return bad();
    r.first = r.last = *v;
    return r;
  }
  const auto a = parseLong(std::string_view(text).substr(0, first));
  if (!a || *a < 0) return bad();
  r.first = *a;
  std::string_view rest = std::string_view(text).substr(first + 1);
  const auto second = rest.find(':');
  const std::string_view last = rest.substr(0, second);
  if (!last.empty()) {
    const auto b = parseLong(last);
    if (!b || *b < r.first) return bad();
    r.last = *b;
  }
  if (second != std::string_view::npos) {
    const auto step = parseLong(rest.substr(second + 1));
    if (!step || *step < 1) return bad();
    r.step = *step;
  }
  return r;
}

Expected<std::vector<long>> jobFrames(const scene::Scene& scene, const RenderJob& job) {
  if (!(job.fps > 0)) return fail(ErrorCode::kUsage, "--fps must be positive (got {})", job.fps);
  const long count = static_cast<long>(std::max<std::size_t>(1, scene::frameCount(scene, job.fps)));
  const long last = job.frames.last < 0 ? count - 1 : job.frames.last;
  if (job.frames.first > last || job.frames.first >= count)
    return fail(ErrorCode::kUsage, "--frames {}:{}: the animation has frames 0 to {} at {} fps", job.frames.first, last, count - 1,
                job.fps);
  std::vector<long> frames;
  for (long f = job.frames.first; f <= std::min(last, count - 1); f += job.frames.step) frames.push_back(f);
  return frames;
}

Expected<FrameCameras> frameCameras(const scene::Evaluator& evaluator, int cameraNode, const RenderJob& job, long frame) {
  const scene::Scene& scene = evaluator.scene();
  const auto& node = scene.nodes[static_cast<std::size_t>(cameraNode)];
  const scene::Camera& lens = scene.cameras[static_cast<std::size_t>(node.camera)];
  if (lens.type == scene::Camera::Type::kPerspective && !(lens.yfov > 0 && lens.yfov < 3.14159))
    return fail(ErrorCode::kInvalidData, "{}: camera '{}' has yfov {} (expected 0 < yfov < pi)", job.dataset.string(), lens.name, lens.yfov);
  const double start = scene.timeRange().start;
  const double t = start + static_cast<double>(frame) / job.fps;
  const double previous = t - 1.0 / job.fps;
  return FrameCameras{t, previous,
                      RenderCamera(evaluator.worldMatrix(cameraNode, t), lens, job.settings.width, job.settings.height),
                      RenderCamera(evaluator.worldMatrix(cameraNode, previous), lens, job.settings.width, job.settings.height),
                      scene::cameraCutBetween(node, previous, t)};
}

nlohmann::json renderRecord(const RenderJob& job) {
  const auto& s = job.settings;
  nlohmann::json r = {{"engine", job.engine},
                      {"dataset", job.dataset.filename().string()},
                      {"fps", job.fps},
                      {"samples_per_pixel", s.samplesPerPixel},
                      {"bounces", s.bounces},
                      {"seed", s.seed},
                      {"width", s.width},
                      {"height", s.height},
                      {"environment", s.constantEnvironment ? "constant" : (s.useEnvironment ? "dataset" : "none")},
                      // Radiance through the pixel filter, or at the pixel centre's hit
                      // (docs/feature-buffers.md): frames of another kind are not reused.
                      {"radiance_at", s.pixelFilter.type == PixelFilterType::kCentre ? "pixel_centre" : "pixel_filter"}};
  if (s.pixelFilter.type != PixelFilterType::kCentre)
    r["pixel_filter"] = {{"type", pixelFilterName(s.pixelFilter.type)}, {"width", s.pixelFilter.width},
                         {"points", "sobol02_shifted"}};  // stratifiedPoint (frames of independent points not reused)
  if (s.converge) r["converge"] = {{"tolerance", s.tolerance}, {"max_spp", s.maxSamplesPerPixel},
                                   {"direct_threshold", s.directThresholdFraction}, {"indirect_threshold", s.indirectThresholdFraction}};
  // Radiance-change pairs (frames without them are not complete for a job that wants them).
  // Their lights (PairLights): the frames' shared lights through one tree, pairLightsPerPoint a
  // point; pairs that evaluated every light in reach are not reused.
  if (s.pairs) r["pairs"] = {{"max_pairs", s.maxPairs}, {"first_pairs", frames::kFirstPairs}, {"z", frames::kChangeZ},
                             {"direct_threshold", s.directThresholdFraction}, {"indirect_threshold", s.indirectThresholdFraction},
                             {"lights", {{"sampler", "shared_tree"}, {"per_point", pairLightsPerPoint(s.lightsPerPoint)}}}};
  if (s.pairs && s.everyLightUpTo > 0 && s.lightsPerPoint > 0) r["pairs"]["lights"]["every_light_up_to"] = s.everyLightUpTo;
  // Point and spot lights through the light tree (frames of the earlier cut-off are not reused), its
  // importance weighted by the learned visibility (render/light_visibility.h) and its parameters,
  // or not (frames of the tree alone are not taken for learned ones, nor the other way round).
  r["lights"] = {{"sampler", "tree"}, {"per_point", s.lightsPerPoint}};
  // Every light in reach where few reach (frames that always sampled are not taken for these).
  if (s.everyLightUpTo > 0 && s.lightsPerPoint > 0) r["lights"]["every_light_up_to"] = s.everyLightUpTo;
  if (s.learnedLightSelection)
    r["lights"]["learned_visibility"] = {{"pilot_stride", kPilotStride}, {"cells_across", kVisibilityCellsAcross},
                                         {"defensive_share", LightVisibility::kDefensiveShare},
                                         {"seen_lights", "summed at the first vertex"}, {"unseen_per_point", kUnseenLightsPerPoint}};
  // Where every light in reach is evaluated, the cell's occluded lights traced by roulette
  // (LightGuide::keepFactors; frames that traced every one are not taken for these).
  if (s.learnedLightSelection && s.everyLightUpTo > 0 && s.lightsPerPoint > 0)
    r["lights"]["learned_visibility"]["occluded_in_reach"] = "traced with probability defensive_share";
  if (s.jitter) r["jitter"] = "halton23x8";
  // --float32 is recorded, so such a job does not take half-stored frames as complete.
  if (job.float32) r["storage"] = "float32";
  // The dataset by content (scene/dataset_digest.h): frames of another version of a dataset at the
  // same path are not complete for it, and the same dataset in another folder gives the same record
  // (its path, and the file times that depended on the clock's epoch, are not recorded).
  if (auto digest = scene::datasetDigest(job.dataset)) r["dataset_sha256"] = *digest;
  if (job.camera) r["camera"] = *job.camera;
  if (job.animation) r["animation"] = *job.animation;
  if (s.constantEnvironment) r["environment_radiance"] = {s.constantEnvironment->r, s.constantEnvironment->g, s.constantEnvironment->b};
  return r;
}

Expected<std::map<long, std::vector<std::uint8_t>>> frameLightReach(const scene::Scene& scene, const RenderJob& job,
                                                                    const std::vector<long>& frames) {
  auto cameraNode = scene::selectCameraNode(scene, job.camera);
  if (!cameraNode) return std::unexpected(cameraNode.error());
  const scene::Evaluator evaluator(scene);
  std::optional<tbb::global_control> limit;
  if (job.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));
  std::vector<std::string> warnings;
  auto tracer = PathTracer::create(scene, job.settings, warnings);
  if (!tracer) return std::unexpected(tracer.error());
  std::map<long, std::vector<std::uint8_t>> reach;
  for (const long frame : frames) {
    auto cameras = frameCameras(evaluator, *cameraNode, job, frame);
    if (!cameras) return std::unexpected(cameras.error());
    if (auto ok = (*tracer)->setTime(cameras->time, cameras->previousTime); !ok) return std::unexpected(ok.error());
    reach[frame] = (*tracer)->lightReach(cameras->camera);
  }
  return reach;
}

Expected<RenderSummary> renderDataset(const scene::Scene& scene, const RenderJob& job, const RenderProgress& progress) {
  if (job.threads < 0) return fail(ErrorCode::kUsage, "--threads must be 0 (all cores) or more (got {})", job.threads);
  const auto backend = findBackend(job.engine);
  if (!backend) return std::unexpected(backend.error());
  auto frames = jobFrames(scene, job);
  if (!frames) return std::unexpected(frames.error());
  auto cameraNode = scene::selectCameraNode(scene, job.camera);
  if (!cameraNode) return std::unexpected(cameraNode.error());
  std::error_code ec;
  fs::create_directories(job.output, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create the output folder: {}", job.output.string(), ec.message());

  const nlohmann::json record = renderRecord(job);
  RenderSummary summary;
  std::vector<long> todo;
  for (long f : *frames) (frames::frameComplete(job.output, f, record) ? summary.skipped : todo).push_back(f);
  if (todo.empty()) return summary;

  std::vector<FrameRequest> requests;
  std::set<long> cuts;
  const scene::Evaluator evaluator(scene);
  // Every frame from where the stepping begins to the last one rendered, in order; those not
  // rendered are steps before the next that is (RenderJob::stepFrom).
  std::vector<long> stepping;
  if (job.stepFrom)
    for (long f = *job.stepFrom; f < frames->front(); f += std::max<long>(1, job.frames.step)) stepping.push_back(f);
  stepping.insert(stepping.end(), frames->begin(), frames->end());
  const std::set<long> rendering(todo.begin(), todo.end());
  std::vector<SceneStep> steps;
  for (long f : stepping) {
    if (f > todo.back()) break;
    auto cameras = frameCameras(evaluator, *cameraNode, job, f);
    if (!cameras) return std::unexpected(cameras.error());
    if (!rendering.contains(f)) {
      steps.push_back({cameras->time, cameras->previousTime});
      continue;
    }
    if (cameras->cut) cuts.insert(f);
    requests.push_back({f, std::move(*cameras), std::move(steps)});
    steps.clear();
  }
  const auto started = std::chrono::steady_clock::now();
  // --threads holds for the whole job: loading (textures decode in parallel), rendering and
  // writing (OpenEXR compresses a frame's blocks on its own pool, one thread per core unless told).
  std::optional<tbb::global_control> limit;
  if (job.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(job.threads));
  setImageThreads(job.threads);  // the frames' ZIP compression too
  auto renderer = (*backend)->create({scene, job, *cameraNode, summary.warnings});
  if (!renderer) return std::unexpected(renderer.error());
  summary.loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  // Around every backend alike: frames written through the contract module, progress in rows.
  const std::size_t height = static_cast<std::size_t>(job.settings.height);
  const std::size_t rowsTotal = requests.size() * height;
  // A backend may write a frame while the next one reports its rows (backend.h): one lock for the
  // progress reports and the summary.
  std::mutex reporting;
  RowProgress rows;
  if (progress)
    rows = [&](std::size_t i, int done) {
      const std::lock_guard lock(reporting);
      progress(i * height + static_cast<std::size_t>(done), rowsTotal, i, requests.size());
    };
  const FrameSink write = [&](frames::FeatureFrame&& frame) -> Expected<void> {
    frame.cut = cuts.contains(frame.frame);  // the sidecar's `cut`: temporal methods and discard reset here
    if (auto ok = frames::writeFrame(job.output, frame, record, {.float32 = job.float32}); !ok) return ok;
    const std::lock_guard lock(reporting);
    summary.rendered.push_back(frame.frame);
    if (frame.sampling) {
      summary.cappedPixels += frame.sampling->cappedPixels;
      summary.pairs += frame.sampling->meanPairs * static_cast<double>(frame.pixelCount());
      summary.undecidedPixels += frame.sampling->undecidedPixels;
      summary.pixels += frame.pixelCount();
    }
    const std::size_t done = summary.rendered.size();
    if (progress) progress(done * height, rowsTotal, done, requests.size());
    return {};
  };
  if (auto ok = (*renderer)->render(requests, write, rows); !ok) return std::unexpected(ok.error());
  summary.cameraSamples = (*renderer)->statistics().cameraSamples;
  summary.rays = (*renderer)->statistics().rays;
  summary.light = (*renderer)->statistics();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return summary;
}

}  // namespace dynbench::render
