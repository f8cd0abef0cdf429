// Discard benchmark (run by hand; not part of the test suite):
//   build/release/bench/bench_discard [FRAMES=8]
// 1920x1080 feature buffers of a camera turning 2 degrees per frame inside a textured room (a
// position, normal and radiance pattern that changes per pixel), compared frame to frame:
// frame pairs per second from memory (discardFrame alone), then end to end from EXR files
// (read, compare, for FRAMES frames written to /tmp/dynbench_bench_discard).
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/files.h"
#include "core/image_io.h"
#include "core/math.h"
#include "discard/discard.h"
#include "render/camera.h"
#include "frames/frame_io.h"

namespace fs = std::filesystem;
using namespace dynbench;
using Clock = std::chrono::steady_clock;

namespace {

render::RenderCamera cameraAt(int k) {
  glm::dmat4 world = glm::mat4_cast(quatFromYawPitchRoll(radians(2.0 * k), radians(-5.0), 0.0));
  world[3] = glm::dvec4(0.1 * k, 1.7, 0, 1);
  scene::Camera lens;
  lens.yfov = radians(50.0);
  lens.znear = 0.1;
  return render::RenderCamera(world, lens, 1920, 1080);
}

// A box room 20 x 6 x 20 around the origin: P, N and a radiance pattern per wall.
discard::FeatureFrame frame(int k) {
  const auto cam = cameraAt(k);
  discard::FeatureFrame f;
  f.frame = k;
  f.width = 1920;
  f.height = 1080;
  f.camera = cam.frameCamera();
  const std::size_t n = 1920u * 1080u;
  for (auto* b : {&f.position, &f.normal, &f.direct, &f.indirect}) b->resize(3 * n);
  f.hit.assign(n, 1.0f);
  f.directVariance.assign(n, 1e-4f);
  f.indirectVariance.assign(n, 1e-4f);
  for (int y = 0; y < 1080; ++y)
    for (int x = 0; x < 1920; ++x) {
      const render::Ray r = cam.ray(x + 0.5, y + 0.5);
      double t = 1e30;
      int axis = 0;
      for (int a = 0; a < 3; ++a) {
        const double half = a == 1 ? 3.0 : 10.0, lo = a == 1 ? 0.0 : -half, hi = a == 1 ? 6.0 : half;
        if (r.direction[a] == 0) continue;
        const double ta = ((r.direction[a] > 0 ? hi : lo) - r.origin[a]) / r.direction[a];
        if (ta > 0 && ta < t) {
          t = ta;
          axis = a;
        }
      }
      const glm::dvec3 p = r.origin + t * r.direction;
      glm::dvec3 normal(0.0);
      normal[axis] = r.direction[axis] > 0 ? -1.0 : 1.0;
      const double pattern = 0.5 + 0.5 * std::sin(3 * p.x) * std::sin(3 * p.z + p.y);
      const std::size_t i = static_cast<std::size_t>(y) * 1920 + x;
      for (int c = 0; c < 3; ++c) {
        f.position[3 * i + c] = static_cast<float>(p[c]);
        f.normal[3 * i + c] = static_cast<float>(normal[c]);
        f.direct[3 * i + c] = static_cast<float>(pattern);
        f.indirect[3 * i + c] = static_cast<float>(0.2 * pattern);
      }
    }
  return f;
}

}  // namespace

int main(int argc, char** argv) {
  const int frames = argc > 1 ? std::max(2, std::atoi(argv[1])) : 8;
  const auto a = frame(0), b = frame(1);
  discard::Thresholds t;
  const auto absolute = discard::absoluteThresholds(t, b, discard::sceneSize(a));
  constexpr int kRepeats = 10;
  auto start = Clock::now();
  double frustum = 0;
  for (int k = 0; k < kRepeats; ++k) frustum += discard::discardFrame(b, a, absolute).percentages.frustum;
  const double memory = std::chrono::duration<double>(Clock::now() - start).count() / kRepeats;
  std::printf("from memory: %.1f ms per 1920x1080 frame pair, %.1f pairs/s (frustum %.2f %%)\n", memory * 1e3, 1 / memory,
              frustum / kRepeats);

  const fs::path dir = fs::temp_directory_path() / "dynbench_bench_discard";
  fs::remove_all(dir);
  for (int k = 0; k < frames; ++k) {
    const auto f = frame(k);
    FloatImage image{1920, 1080, 13, {}, {"P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z", "direct.R", "direct.G", "direct.B", "indirect.R", "indirect.G", "indirect.B", "hit"}};
    image.pixels.reserve(1920u * 1080u * 13u);
    for (std::size_t i = 0; i < f.hit.size(); ++i) {
      for (const auto* buf : {&f.position, &f.normal, &f.direct, &f.indirect})
        for (int c = 0; c < 3; ++c) image.pixels.push_back((*buf)[3 * i + c]);
      image.pixels.push_back(1.0f);
    }
    if (!writeImage(frames::frameImagePath(dir, k), image) ||
        !writeFileAtomic(frames::frameSidecarPath(dir, k), frames::sidecarJson(k, k / 24.0, cameraAt(k).frameCamera(), {}).dump())) {
      std::fprintf(stderr, "cannot write %s\n", dir.c_str());
      return 1;
    }
  }
  start = Clock::now();
  auto run = discard::discardFolder(dir, discard::Thresholds{});
  const double files = std::chrono::duration<double>(Clock::now() - start).count();
  if (!run) {
    std::fprintf(stderr, "%s\n", run.error().message.c_str());
    return 1;
  }
  std::printf("end to end from EXR: %d frames in %.2f s, %.2f pairs/s (%.0f ms per pair; EXR size %.1f MB each)\n", frames, files,
              (frames - 1) / files, files / (frames - 1) * 1e3, static_cast<double>(fs::file_size(frames::frameImagePath(dir, 0))) / 1e6);
  return 0;
}
