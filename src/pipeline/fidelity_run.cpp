#include "core/json_fields.h"
#include "pipeline/fidelity_run.h"

#include <algorithm>
#include <fstream>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "capture/reader.h"
#include "core/files.h"
#include "core/image_io.h"
#include "core/math.h"
#include "frames/frame_io.h"
#include "frames/preview.h"
#include "pipeline/stages.h"
#include "render/render_job.h"
#include "scene/load.h"

namespace dynbench::pipeline {
namespace fs = std::filesystem;

Expected<double> windowDepthNear(const fs::path& file) {
  std::ifstream in(file);
  std::string word;
  double near = 0.0;
  if (!(in >> word >> near) || word != "near" || !(near > 0))
    return fail(ErrorCode::kInvalidData, "{}:1: expected 'near Z' with the game's near plane Z > 0", file.string());
  return near;
}

Expected<FidelityOutcome> runFidelity(const FidelityStage& stage) {
  auto reader = capture::CaptureReader::open(stage.capture);
  if (!reader) return std::unexpected(reader.error());
  const auto& settings = (*reader)->settings();
  if (!settings.camera) return fail(ErrorCode::kInvalidData, "{}: the capture has no camera settings (C record)", stage.capture.string());
  std::map<long, double> times;
  capture::CaptureFrame frame;
  while (true) {
    auto more = (*reader)->next(frame);
    if (!more) return std::unexpected(more.error());
    if (!*more) break;
    times[static_cast<long>(frame.number)] = frame.time;
  }
  if (times.size() < 2) return fail(ErrorCode::kInvalidData, "{}: fewer than two frames", stage.capture.string());
  const double fps = static_cast<double>(times.rbegin()->first - times.begin()->first) / (times.rbegin()->second - times.begin()->second);
  std::vector<long> gameFrames;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(stage.capture / "game", ec)) {
    long k = 0;
    if (e.path().extension() == ".ppm" && std::sscanf(e.path().filename().c_str(), "frame_%ld.ppm", &k) == 1) gameFrames.push_back(k);
  }
  if (gameFrames.empty())
    return fail(ErrorCode::kInvalidData, "{}: no game frames in game/ (capture with dynbench capture cube2 --game-frames LIST)",
                stage.capture.string());
  std::sort(gameFrames.begin(), gameFrames.end());
  fs::create_directories(stage.output, ec);
  auto scene = scene::loadScene(stage.dataset);
  if (!scene) return std::unexpected(scene.error());
  // Every game frame's light reach, from one path tracer, once the first frame gives the game's size.
  std::map<long, std::vector<std::uint8_t>> reaches;
  FidelityOutcome out;
  out.passed = true;
  for (const long k : gameFrames) {
    if (!times.count(k)) return fail(ErrorCode::kInvalidData, "{}: game frame {} is not a frame of the capture", stage.capture.string(), k);
    const fs::path colourPath = stage.capture / "game" / fmt::format("frame_{:05d}.ppm", k);
    const fs::path depthPath = stage.capture / "game" / fmt::format("frame_{:05d}_depth.pfm", k);
    auto colour = readImage(colourPath);
    if (!colour) return std::unexpected(colour.error());
    // Cube 2 keeps the view depth; id Tech 3 the window depth with a far plane it does not expose.
    const fs::path windowDepthPath = stage.capture / "game" / fmt::format("frame_{:05d}_window_depth.pfm", k);
    const bool windowDepth = !fs::exists(depthPath) && fs::exists(windowDepthPath);
    // A window-depth capture whose frame kept no depth (the engine's buffer read back empty):
    // measured without it.
    const bool noDepth = !fs::exists(depthPath) && !windowDepth && fs::exists(stage.capture / "game" / "window_depth.txt");
    auto depth = noDepth ? Expected<FloatImage>(FloatImage{colour->width, colour->height, 1, {}, {}, {}, {}})
                         : readImage(windowDepth ? windowDepthPath : depthPath);
    if (!depth) return std::unexpected(depth.error());
    if (noDepth) depth->pixels.assign(static_cast<std::size_t>(colour->width) * colour->height, 0.0f);
    if (colour->channels < 3 || depth->width != colour->width || depth->height != colour->height)
      return fail(ErrorCode::kInvalidData, "{}: expected an RGB image the size of {}", colourPath.string(), depthPath.string());
    RenderStage render;
    render.job.dataset = stage.dataset;
    render.job.output = stage.output / "render";
    render.job.settings.width = colour->width;
    render.job.settings.height = colour->height;
    render.job.settings.samplesPerPixel = stage.samplesPerPixel;
    render.job.fps = fps;
    render.job.frames = {k, k, 1};
    render.job.threads = stage.threads;
    auto summary = runRender(render);
    if (!summary) return std::unexpected(summary.error());
    auto entries = frames::listFrames(render.job.output);
    if (!entries) return std::unexpected(entries.error());
    const auto entry = std::find_if(entries->begin(), entries->end(), [&](const frames::FrameEntry& e) { return e.frame == k; });
    if (entry == entries->end()) return fail(ErrorCode::kIo, "{}: frame {} was not rendered", render.job.output.string(), k);
    auto rendered = frames::readFrame(*entry);
    if (!rendered) return std::unexpected(rendered.error());
    evaluate::GameImages m;
    m.width = colour->width;
    m.height = colour->height;
    const std::size_t n = rendered->pixelCount();
    m.gameColour.resize(3 * n);
    m.gameDepth.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) m.gameColour[3 * i + c] = colour->pixels[i * static_cast<std::size_t>(colour->channels) + c];
      m.gameDepth[i] = depth->pixels[i * static_cast<std::size_t>(depth->channels)];
    }
    m.renderRadiance.resize(3 * n);
    for (std::size_t i = 0; i < 3 * n; ++i) m.renderRadiance[i] = rendered->direct[i] + rendered->indirect[i];
    m.renderDepth = rendered->depth;
    m.renderHit = rendered->hit;
    // Sample-free (the share of pixels where none of the render's paths found direct light fell as
    // paths grew: 10.0 % at 16, 7.2 % at 64 on oa_dm2's frame 100).
    if (reaches.empty()) {
      auto computed = render::frameLightReach(*scene, render.job, gameFrames);
      if (!computed) return std::unexpected(computed.error());
      reaches = std::move(*computed);
    }
    const std::vector<std::uint8_t>& reach = reaches.at(k);
    if (reach.size() != n)
      return fail(ErrorCode::kInvalidData, "{}: game frame {} is {}x{}, unlike the capture's first game frame", colourPath.string(), k,
                  colour->width, colour->height);
    m.renderLightReach.assign(reach.begin(), reach.end());
    m.near = settings.camera->znear;
    m.far = settings.camera->zfar;
    if (windowDepth) {
      auto near = windowDepthNear(stage.capture / "game" / "window_depth.txt");
      if (!near) return std::unexpected(near.error());
      const evaluate::WindowDepthView view = evaluate::viewDepthFromWindow(m.gameDepth, m.renderDepth, m.renderHit, *near);
      m.gameDepth = view.depth;
      m.near = *near;
      m.far = view.far;
    }
    m.gameDepthKnown = !noDepth;
    if (noDepth) m.gameDepth = m.renderHit;  // the render's coverage stands in for the mask of pixels compared
    FidelityFrame f;
    static_cast<evaluate::GameAgreement&>(f) = evaluate::compareWithGame(m);
    f.frame = k;
    f.time = times[k];
    // Side by side: the game's frame, the render (preview tone map), where depth agrees (green),
    // disagrees (red), or both see sky (black), and where some light reaches the render's surface
    // (white), none does (black) or the render sees sky (dark blue).
    const int w = m.width, h = m.height;
    std::vector<float> side(static_cast<std::size_t>(4 * w) * h * 3, 0.0f);
    const auto preview = frames::previewImage(*rendered);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * w + x);
        float* row = &side[(static_cast<std::size_t>(y) * 4 * w) * 3];
        for (int c = 0; c < 3; ++c) {
          row[3 * x + c] = m.gameColour[3 * i + c];
          row[3 * (w + x) + c] = preview[3 * i + c];
        }
        const bool game = m.gameDepth[i] > 0, hit = m.renderHit[i] > 0;
        const bool ok = game && hit && evaluate::depthAgrees(m.renderDepth[i], m.gameDepth[i], m.near, m.far);
        if (!m.gameDepthKnown) {
          if (hit) row[3 * (2 * w + x) + 2] = 1.0f;  // blue: the game's depth was not read
        } else if (game || hit) {
          row[3 * (2 * w + x) + (ok ? 1 : 0)] = 1.0f;
        }
        float* reach = &row[3 * (3 * w + x)];
        if (!hit) reach[2] = 0.25f;
        else if (m.renderLightReach[i] > 0) reach[0] = reach[1] = reach[2] = 1.0f;
      }
    f.sideBySide = stage.output / fmt::format("fidelity_{:05d}.png", k);
    if (auto ok = writeImage(f.sideBySide, FloatImage{4 * w, h, 3, side, {}, {}, {}}); !ok) return std::unexpected(ok.error());
    out.passed = out.passed && f.passed;
    out.frames.push_back(f);
  }
  out.markdown = "| frame | time (s) | depth agreement | sky agreement | luminance correlation | no direct light | pass |\n"
                 "|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& f : out.frames)
    out.markdown += fmt::format("| {} | {:.3f} | {} | {} | {:.3f} | {:.1f} % | {} |\n", f.frame, f.time,
                                std::isnan(f.depthAgreement) ? std::string("not read") : fmt::format("{:.3f}", f.depthAgreement),
                                std::isnan(f.skyAgreement) ? std::string("not read") : fmt::format("{:.3f}", f.skyAgreement), f.correlation,
                                100 * f.unlitShare, f.passed ? "yes" : "no");
  if (auto ok = writeFileAtomic(stage.output / "fidelity.json", jsonFileText(fidelityJson(out, stage))); !ok) return std::unexpected(ok.error());
  return out;
}

nlohmann::json fidelityJson(const FidelityOutcome& outcome, const FidelityStage& stage) {
  const auto orNull = [](double v) { return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v); };
  nlohmann::json frames = nlohmann::json::array();
  for (const FidelityFrame& f : outcome.frames)
    frames.push_back({{"frame", f.frame}, {"time", f.time}, {"width", f.width}, {"height", f.height}, {"depth_agreement", orNull(f.depthAgreement)},
                      {"sky_agreement", orNull(f.skyAgreement)}, {"correlation", f.correlation}, {"unlit_share", f.unlitShare},
                      {"passed", f.passed}});
  return {{"capture", stage.capture.string()},
          {"dataset", stage.dataset.string()},
          {"thresholds", {{"depth_agreement", evaluate::kFidelityMinDepthAgreement}, {"correlation", evaluate::kFidelityMinCorrelation}}},
          {"frames", frames},
          {"passed", outcome.passed}};
}

}  // namespace dynbench::pipeline
