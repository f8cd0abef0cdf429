#pragma once
// Embree's raw ray throughput on a dataset, one thread, no shading: the ceiling bench_raytrace and
// bench_render compare the path tracer against. Rays go through RayTracingScene::intersect, the
// same call (and hit bookkeeping) the path tracer uses.
#include <chrono>
#include <random>
#include <vector>

#include "render/camera.h"
#include "render/raytracing_scene.h"

namespace dynbench::bench {

struct RawRayThroughput {
  double primaryRaysPerSecond = 0, randomRaysPerSecond = 0;
  double primaryHitShare = 0, randomHitShare = 0;
};

// Primary rays: 640x360 through `camera`'s pixel centres, four times. Random (incoherent) rays:
// one million, origins uniform in a 40-unit cube around the camera, directions uniform.
inline RawRayThroughput measureRawRays(const render::RayTracingScene& scene, const render::RenderCamera& camera) {
  using Clock = std::chrono::steady_clock;
  RawRayThroughput out;
  const int width = camera.width(), height = camera.height(), repeats = 4;
  std::size_t hits = 0;
  auto start = Clock::now();
  for (int repeat = 0; repeat < repeats; ++repeat)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) hits += scene.intersect(camera.ray(x + 0.5, y + 0.5)).hit;
  const double primaryRays = static_cast<double>(repeats) * width * height;
  out.primaryRaysPerSecond = primaryRays / std::chrono::duration<double>(Clock::now() - start).count();
  out.primaryHitShare = static_cast<double>(hits) / primaryRays;

  std::mt19937 random(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr int kRays = 1'000'000;
  std::vector<render::Ray> rays(kRays);
  for (auto& r : rays) {
    r.origin = camera.position() + 20.0 * glm::dvec3(u(random), u(random), u(random));
    glm::dvec3 d;
    do d = {u(random), u(random), u(random)};
    while (glm::length(d) > 1.0 || glm::length(d) < 1e-3);
    r.direction = glm::normalize(d);
  }
  hits = 0;
  start = Clock::now();
  for (const auto& r : rays) hits += scene.intersect(r).hit;
  out.randomRaysPerSecond = kRays / std::chrono::duration<double>(Clock::now() - start).count();
  out.randomHitShare = static_cast<double>(hits) / kRays;
  return out;
}

}  // namespace dynbench::bench
