#include "pipeline/fidelity.h"

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

namespace dynbench::pipeline {
namespace fs = std::filesystem;

namespace {

// Separable Gaussian blur of a one-channel image (sigma in pixels, kernel to 3 sigma, edges clamped).
std::vector<double> blur(const std::vector<double>& image, int w, int h, double sigma) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<double> kernel(static_cast<std::size_t>(2 * radius + 1));
  for (int k = -radius; k <= radius; ++k) kernel[static_cast<std::size_t>(k + radius)] = std::exp(-0.5 * k * k / (sigma * sigma));
  const double sum = std::accumulate(kernel.begin(), kernel.end(), 0.0);
  for (double& k : kernel) k /= sum;
  std::vector<double> tmp(image.size()), out(image.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 0;
      for (int k = -radius; k <= radius; ++k) v += kernel[static_cast<std::size_t>(k + radius)] * image[static_cast<std::size_t>(y * w + std::clamp(x + k, 0, w - 1))];
      tmp[static_cast<std::size_t>(y * w + x)] = v;
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double v = 0;
      for (int k = -radius; k <= radius; ++k) v += kernel[static_cast<std::size_t>(k + radius)] * tmp[static_cast<std::size_t>(std::clamp(y + k, 0, h - 1) * w + x)];
      out[static_cast<std::size_t>(y * w + x)] = v;
    }
  return out;
}

// Reinhard's L / (L + mean L) over the pixels in `mask`: the same for any exposure of the image.
std::vector<double> toneMapped(const std::vector<double>& luminance, const std::vector<bool>& mask) {
  double mean = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < luminance.size(); ++i)
    if (mask[i]) mean += luminance[i], ++n;
  mean = n ? mean / static_cast<double>(n) : 0.0;
  std::vector<double> out(luminance.size(), 0.0);
  if (!(mean > 0)) return out;
  for (std::size_t i = 0; i < luminance.size(); ++i) out[i] = luminance[i] / (luminance[i] + mean);
  return out;
}

// Whether a rendered depth agrees with the game's view depth z (> 0): within four steps of a 24-bit
// depth buffer at z, plus 1 % (fidelity.h).
bool depthAgrees(double rendered, double z, double near, double far) {
  const double step = std::ldexp(1.0, -24) * (far - near) / (far * near) * z * z;
  return std::abs(rendered - z) <= 4.0 * step + 0.01 * z;
}

}  // namespace

Expected<double> windowDepthNear(const fs::path& file) {
  std::ifstream in(file);
  std::string word;
  double near = 0.0;
  if (!(in >> word >> near) || word != "near" || !(near > 0))
    return fail(ErrorCode::kInvalidData, "{}:1: expected 'near Z' with the game's near plane Z > 0", file.string());
  return near;
}

WindowDepthView viewDepthFromWindow(const std::vector<float>& window, const std::vector<float>& renderDepth, const std::vector<float>& renderHit,
                                    double near) {
  // A perspective depth buffer holds d = (1/n - 1/z) / (1/n - 1/f), so 1/f = 1/n - (1/n - 1/z) / d.
  // Each pixel where the render has a surface gives one value for it; the median is the game's far
  // plane (one number per frame: pixels whose geometry differs are outliers of it).
  std::vector<double> inverseFar;
  for (std::size_t i = 0; i < window.size(); ++i)
    if (renderHit[i] > 0 && window[i] > 0.01 && window[i] < 0.999999 && renderDepth[i] > near)
      inverseFar.push_back(1.0 / near - (1.0 / near - 1.0 / renderDepth[i]) / window[i]);
  WindowDepthView view;
  double inverse = 0.0;
  if (!inverseFar.empty()) {
    std::nth_element(inverseFar.begin(), inverseFar.begin() + static_cast<std::ptrdiff_t>(inverseFar.size() / 2), inverseFar.end());
    inverse = std::max(inverseFar[inverseFar.size() / 2], 1e-9);
  }
  view.far = inverse > 0 ? 1.0 / inverse : 1e9;
  view.depth.resize(window.size());
  for (std::size_t i = 0; i < window.size(); ++i)
    view.depth[i] = window[i] >= 0.999999 ? 0.0f : static_cast<float>(1.0 / (1.0 / near - window[i] * (1.0 / near - inverse)));
  return view;
}

FidelityFrame compareWithGame(const FidelityImages& m) {
  FidelityFrame f;
  f.width = m.width;
  f.height = m.height;
  const std::size_t n = static_cast<std::size_t>(m.width) * static_cast<std::size_t>(m.height);
  std::size_t either = 0, agree = 0, sameKind = 0, geometry = 0, unlit = 0;
  std::vector<bool> both(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const bool game = m.gameDepth[i] > 0, render = m.renderHit[i] > 0;
    sameKind += game == render;
    if (render) {
      ++geometry;
      unlit += luminance(glm::dvec3(m.renderDirect[3 * i], m.renderDirect[3 * i + 1], m.renderDirect[3 * i + 2])) <= 0;
    }
    if (!game && !render) continue;
    ++either;
    if (!(game && render)) continue;
    both[i] = true;
    agree += depthAgrees(m.renderDepth[i], m.gameDepth[i], m.near, m.far);
  }
  f.depthAgreement = either ? static_cast<double>(agree) / static_cast<double>(either) : 1.0;
  f.skyAgreement = n ? static_cast<double>(sameKind) / static_cast<double>(n) : 0.0;
  if (!m.gameDepthKnown) f.depthAgreement = f.skyAgreement = std::numeric_limits<double>::quiet_NaN();
  f.unlitShare = geometry ? static_cast<double>(unlit) / static_cast<double>(geometry) : 0.0;
  std::vector<double> game(n), render(n);
  for (std::size_t i = 0; i < n; ++i) {
    game[i] = luminance(glm::dvec3(srgbToLinear<double>(m.gameColour[3 * i]), srgbToLinear<double>(m.gameColour[3 * i + 1]),
                                   srgbToLinear<double>(m.gameColour[3 * i + 2])));
    render[i] = luminance(glm::dvec3(m.renderRadiance[3 * i], m.renderRadiance[3 * i + 1], m.renderRadiance[3 * i + 2]));
  }
  const double sigma = std::max(1.0, m.height / 90.0);
  const auto a = blur(toneMapped(game, both), m.width, m.height, sigma), b = blur(toneMapped(render, both), m.width, m.height, sigma);
  double ma = 0, mb = 0, count = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (both[i]) ma += a[i], mb += b[i], ++count;
  if (count > 1) {
    ma /= count;
    mb /= count;
    double sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (both[i]) sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma), sbb += (b[i] - mb) * (b[i] - mb);
    f.correlation = saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
  }
  f.passed = (!m.gameDepthKnown || f.depthAgreement >= kFidelityMinDepthAgreement) && f.correlation >= kFidelityMinCorrelation;
  return f;
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
  FidelityOutcome out;
  out.passed = true;
  nlohmann::json framesJson = nlohmann::json::array();
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
    FidelityImages m;
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
    m.renderDirect = rendered->direct;
    m.near = settings.camera->znear;
    m.far = settings.camera->zfar;
    if (windowDepth) {
      auto near = windowDepthNear(stage.capture / "game" / "window_depth.txt");
      if (!near) return std::unexpected(near.error());
      const WindowDepthView view = viewDepthFromWindow(m.gameDepth, m.renderDepth, m.renderHit, *near);
      m.gameDepth = view.depth;
      m.near = *near;
      m.far = view.far;
    }
    m.gameDepthKnown = !noDepth;
    if (noDepth) m.gameDepth = m.renderHit;  // the render's coverage stands in for the mask of pixels compared
    FidelityFrame f = compareWithGame(m);
    f.frame = k;
    f.time = times[k];
    // Side by side: the game's frame, the render (preview tone map), and where depth agrees (green),
    // disagrees (red), or both see sky (black).
    const int w = m.width, h = m.height;
    std::vector<float> side(static_cast<std::size_t>(3 * w) * h * 3, 0.0f);
    const auto preview = frames::previewImage(*rendered);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y * w + x);
        float* row = &side[(static_cast<std::size_t>(y) * 3 * w) * 3];
        for (int c = 0; c < 3; ++c) {
          row[3 * x + c] = m.gameColour[3 * i + c];
          row[3 * (w + x) + c] = preview[3 * i + c];
        }
        const bool game = m.gameDepth[i] > 0, hit = m.renderHit[i] > 0;
        const bool ok = game && hit && depthAgrees(m.renderDepth[i], m.gameDepth[i], m.near, m.far);
        if (!m.gameDepthKnown) {
          if (hit) row[3 * (2 * w + x) + 2] = 1.0f;  // blue: the game's depth was not read
        } else if (game || hit) {
          row[3 * (2 * w + x) + (ok ? 1 : 0)] = 1.0f;
        }
      }
    f.sideBySide = stage.output / fmt::format("fidelity_{:05d}.png", k);
    if (auto ok = writeImage(f.sideBySide, FloatImage{3 * w, h, 3, side, {}, {}, {}}); !ok) return std::unexpected(ok.error());
    out.passed = out.passed && f.passed;
    const auto orNull = [](double v) { return std::isnan(v) ? nlohmann::json(nullptr) : nlohmann::json(v); };
    framesJson.push_back({{"frame", f.frame}, {"time", f.time}, {"width", w}, {"height", h}, {"depth_agreement", orNull(f.depthAgreement)},
                          {"sky_agreement", orNull(f.skyAgreement)}, {"correlation", f.correlation}, {"unlit_share", f.unlitShare},
                          {"passed", f.passed}});
    out.frames.push_back(f);
  }
  out.markdown = "| frame | time (s) | depth agreement | sky agreement | luminance correlation | no direct light | pass |\n"
                 "|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& f : out.frames)
    out.markdown += fmt::format("| {} | {:.3f} | {} | {} | {:.3f} | {:.1f} % | {} |\n", f.frame, f.time,
                                std::isnan(f.depthAgreement) ? std::string("not read") : fmt::format("{:.3f}", f.depthAgreement),
                                std::isnan(f.skyAgreement) ? std::string("not read") : fmt::format("{:.3f}", f.skyAgreement), f.correlation,
                                100 * f.unlitShare, f.passed ? "yes" : "no");
  const nlohmann::json j = {{"capture", stage.capture.string()},
                            {"dataset", stage.dataset.string()},
                            {"thresholds", {{"depth_agreement", kFidelityMinDepthAgreement}, {"correlation", kFidelityMinCorrelation}}},
                            {"frames", framesJson},
                            {"passed", out.passed}};
  if (auto ok = writeFileAtomic(stage.output / "fidelity.json", j.dump(2) + "\n"); !ok) return std::unexpected(ok.error());
  return out;
}

}  // namespace dynbench::pipeline
