#include "report/video.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/files.h"
#include "core/image_io.h"
#include "core/process.h"
#include "core/progress.h"
#include "core/rates.h"

namespace dynbench::report {
namespace {

namespace fs = std::filesystem;

// Removes the folder of PNG frames fed to ffmpeg however writeRunVideo ends.
struct FolderGuard {
  fs::path dir;
  ~FolderGuard() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

Expected<frames::PreviewToneMap> clipToneMap(const std::vector<frames::FrameEntry>& frames, int sampleFrames) {
  if (frames.empty()) return fail(ErrorCode::kUsage, "clipToneMap: no frames");
  const std::size_t n = std::min<std::size_t>(frames.size(), static_cast<std::size_t>(std::max(1, sampleFrames)));
  std::vector<double> exposures;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& entry = frames[n == 1 ? 0 : k * (frames.size() - 1) / (n - 1)];
    auto frame = frames::readFrame(entry);
    if (!frame) return std::unexpected(frame.error());
    exposures.push_back(frames::PreviewToneMap(*frame).exposure());
  }
  return frames::PreviewToneMap(median(std::move(exposures)));
}

Expected<std::string> samplingNote(const std::vector<frames::FrameEntry>& frames) {
  if (frames.empty()) return std::string("no frames");
  // Over every frame: the adaptive renders' smallest and largest counts and the mean of their means.
  int adaptive = 0, low = 0, high = 0;
  double meanSum = 0.0, tolerance = 0.0;
  std::set<long> fixedCounts;
  for (const auto& entry : frames) {
    auto sidecar = frames::readSidecar(entry.sidecar);
    if (!sidecar) return std::unexpected(sidecar.error());
    if (sidecar->sampling && sidecar->sampling->adaptive) {
      const auto& s = *sidecar->sampling;
      low = adaptive ? std::min(low, s.minSamples) : s.minSamples;
      high = adaptive ? std::max(high, s.maxSamples) : s.maxSamples;
      meanSum += s.meanSamples;
      tolerance = s.tolerance;
      ++adaptive;
      continue;
    }
    const auto& render = sidecar->render;
    if (render.is_object() && render.contains("samples_per_pixel") && render["samples_per_pixel"].is_number_integer())
      fixedCounts.insert(render["samples_per_pixel"].get<long>());
  }
  std::vector<std::string> parts;
  if (adaptive)
    parts.push_back(fmt::format("converged (render --converge, tolerance {:g}): {} spp per pixel, mean {:.0f}", tolerance,
                                low == high ? std::to_string(low) : fmt::format("{}-{}", low, high), meanSum / adaptive));
  for (long spp : fixedCounts) parts.push_back(fmt::format("{} spp", spp));
  if (parts.empty()) return std::string("samples per pixel not recorded");
  return fmt::format("{}", fmt::join(parts, "; "));
}

void videoSize(int width, int height, bool masks, const VideoOptions& options, int& outWidth, int& outHeight) {
  double w = masks ? 2.0 * width : width, h = height;
  if (w > options.maxWidth) {
    h = std::round(h * options.maxWidth / w);
    w = options.maxWidth;
  }
  outWidth = static_cast<int>(w);
  outHeight = std::max(1, static_cast<int>(h));
}

Expected<Video> writeRunVideo(const std::vector<frames::FrameEntry>& frames, const fs::path& masksDir, const frames::PreviewToneMap& toneMap,
                              const fs::path& out, const VideoOptions& options) {
  if (frames.empty()) return fail(ErrorCode::kUsage, "{}: no frames for a video", out.string());
  const std::size_t count = std::min<std::size_t>(frames.size(), static_cast<std::size_t>(std::max(1, options.maxFrames)));
  std::error_code ec;
  const bool masks = !masksDir.empty() && fs::is_directory(masksDir, ec);

  Video video;
  video.file = out;
  video.masks = masks;
  video.frames = static_cast<int>(count);
  video.firstFrame = frames.front().frame;
  video.lastFrame = frames[count - 1].frame;

  FolderGuard pngs{temporarySibling(out)};
  fs::create_directories(pngs.dir, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create: {}", pngs.dir.string(), ec.message());
  std::vector<double> steps;
  double previousTime = 0.0;
  int width = 0, height = 0;
  Progress progress("report video", count, "frames");
  for (std::size_t k = 0; k < count; ++k) {
    progress.update(k, frames[k].image.filename().string());
    auto frame = frames::readFrame(frames[k]);
    if (!frame) return std::unexpected(frame.error());
    if (k == 0) {
      width = frame->width;
      height = frame->height;
    } else if (frame->width != width || frame->height != height) {
      return fail(ErrorCode::kInvalidData, "{}: {}x{} pixels, but the frames before it are {}x{}", frames[k].image.string(), frame->width,
                  frame->height, width, height);
    } else if (frame->time > previousTime) {
      steps.push_back(frame->time - previousTime);
    }
    previousTime = frame->time;
    const auto rgb = frames::previewImage(*frame, toneMap);
    const int panels = masks ? 2 : 1;
    FloatImage image{width * panels, height, 3, std::vector<float>(static_cast<std::size_t>(width * panels * height * 3), 0.2f), {}, {}, {}};
    for (int y = 0; y < height; ++y)
      std::copy_n(rgb.begin() + static_cast<std::ptrdiff_t>(y) * width * 3, width * 3,
                  image.pixels.begin() + static_cast<std::ptrdiff_t>(y) * width * panels * 3);
    if (masks) {
      const fs::path maskFile = masksDir / fmt::format("discard_{:05d}.png", frames[k].frame);
      if (fs::is_regular_file(maskFile, ec)) {
        auto mask = readImage(maskFile);
        if (!mask) return std::unexpected(mask.error());
        if (mask->width != width || mask->height != height || mask->channels < 3)
          return fail(ErrorCode::kInvalidData, "{}: {}x{} with {} channels, but its frame is {}x{} RGB", maskFile.string(), mask->width,
                      mask->height, mask->channels, width, height);
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c)
              image.pixels[static_cast<std::size_t>(((y * width * 2) + width + x) * 3 + c)] =
                  mask->pixels[static_cast<std::size_t>((y * width + x) * mask->channels + c)];
      }
    }
    if (auto ok = writeImage(pngs.dir / fmt::format("{:05d}.png", k), image); !ok) return std::unexpected(ok.error());
  }
  progress.update(count);
  video.fps = steps.empty() ? kDefaultFrameRate : 1.0 / median(steps);
  videoSize(width, height, masks, options, video.width, video.height);

  const fs::path temporary = temporarySibling(out).string() + ".webm";  // ffmpeg picks the container by extension
  ProcessOptions ffmpeg;
  ffmpeg.argv = {"ffmpeg", "-hide_banner", "-loglevel", "error", "-nostdin", "-y",
                 // the PNG frames at the frames' own rate
                 "-framerate", fmt::format("{:.6f}", video.fps), "-i", (pngs.dir / "%05d.png").string(),
                 "-vf", fmt::format("scale={}:{}:flags=area", video.width, video.height),
                 // VP9 at constant quality (-b:v 0), no audio, in 4:4:4 (VP9 profile 1, which Chromium
                 // plays). 4:2:0 halves colour resolution and smears the masks' colours, which are
                 // categories, across pixel borders; on the demo's 96x54 frames 4:4:4 costs 1.8x the
                 // bytes (286 against 159 kB for 48 frames), and a higher crf at equal bytes blurs the
                 // radiance instead.
                 "-c:v", "libvpx-vp9", "-pix_fmt", "yuv444p", "-crf", std::to_string(options.crf), "-b:v", "0",
                 "-deadline", "good", "-cpu-used", "4", "-row-mt", "1", "-an", temporary.string()};
  auto run = runProcess(ffmpeg);
  if (!run)
    return fail(ErrorCode::kExternalTool, "{}; install Debian's ffmpeg (scripts/setup.sh does), or leave the videos out with --video-frames 0",
                run.error().message);
  if (!run->succeeded()) {
    fs::remove(temporary, ec);
    return fail(ErrorCode::kExternalTool, "ffmpeg failed on {}: {}", out.string(), run->tail.empty() ? "(no output)" : run->tail);
  }
  if (auto ok = commitTemporary(temporary, out); !ok) return std::unexpected(ok.error());
  return video;
}

}  // namespace dynbench::report
