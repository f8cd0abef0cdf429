// Raw Embree ray throughput on a dataset, no shading (run by hand; the render benchmark's ceiling):
//   build/release/bench/bench_raytrace DATASET [TIME_SECONDS]
// Prints the BVH build times (static once, dynamic per frame) and single-thread rays per second for
// primary rays (640x360) and random incoherent rays (random origins in the scene's bounds,
// uniformly random directions).
#include <chrono>
#include <cstdio>

#include "raw_rays.h"
#include "render/camera.h"
#include "render/raytracing_scene.h"
#include "scene/queries.h"
#include "scene/load.h"

using namespace dynbench;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_raytrace DATASET [TIME_SECONDS]\n");
    return 2;
  }
  auto scene = scene::loadScene(argv[1]);
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.error().message.c_str());
    return 1;
  }
  const double t = argc > 2 ? std::atof(argv[2]) : scene->timeRange().start;
  auto start = Clock::now();
  auto rt = render::RayTracingScene::create(*scene);
  if (!rt) {
    std::fprintf(stderr, "%s\n", rt.error().message.c_str());
    return 1;
  }
  const double staticBuild = std::chrono::duration<double>(Clock::now() - start).count();
  start = Clock::now();
  constexpr int kUpdates = 10;
  for (int i = 0; i < kUpdates; ++i)
    if (auto ok = (*rt)->update(t + i / 60.0); !ok) std::fprintf(stderr, "%s\n", ok.error().message.c_str());
  const double dynamicBuild = std::chrono::duration<double>(Clock::now() - start).count() / kUpdates;
  const auto stats = (*rt)->stats();
  {
    const scene::Evaluator evaluator(*scene);
    scene::ScenePose pose;
    const auto s0 = Clock::now();
    for (int i = 0; i < kUpdates; ++i) evaluator.evaluate(t + i / 60.0, pose);
    std::printf("scene pose (%zu nodes): %.2f ms per frame\n", scene->nodes.size(),
                std::chrono::duration<double>(Clock::now() - s0).count() * 1e3 / kUpdates);
  }
  std::printf("%s at t = %.3f s: %zu static triangles (BVH %.1f ms, once), %zu dynamic triangles (update %.2f ms per frame)\n", argv[1],
              t, stats.staticTriangles, staticBuild * 1e3, stats.dynamicTriangles, dynamicBuild * 1e3);

  // Primary rays through the dataset's camera (or a default view of the origin).
  auto node = scene::selectCameraNode(*scene, std::nullopt);
  const scene::Evaluator evaluator(*scene);
  scene::Camera lens;
  lens.yfov = 1.0;
  lens.znear = 0.1;
  glm::dmat4 world(1.0);
  world[3] = glm::dvec4(0, 2, 10, 1);
  if (node && *node >= 0) {
    lens = scene->cameras[static_cast<std::size_t>(scene->nodes[static_cast<std::size_t>(*node)].camera)];
    world = evaluator.worldMatrix(*node, t);
  }
  const render::RenderCamera camera(world, lens, 640, 360);
  const auto raw = bench::measureRawRays(**rt, camera);
  std::printf("primary rays:  %.2f Mrays/s (one thread, %.0f %% hit)\n", raw.primaryRaysPerSecond / 1e6, 100.0 * raw.primaryHitShare);
  std::printf("random rays:   %.2f Mrays/s (one thread, %.0f %% hit)\n", raw.randomRaysPerSecond / 1e6, 100.0 * raw.randomHitShare);
  return 0;
}
