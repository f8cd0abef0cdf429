// Render benchmark (run by hand; not part of the test suite):
//   build/release/bench/bench_render [DATASET] [--frames A:B] [--res WxH] [--spp N] [--bounces N] [--repeat N] [--no-cycles]
// For the same dataset and frames, in one run:
//  1. the path tracer's rays per second on one thread and on two, and the 2-thread speedup (over
//     the frames, and over the whole job with loading);
//  2. Embree's raw ray throughput on the same scene and camera (bench/raw_rays.h: primary rays
//     through the render camera, random incoherent rays around it), and the path tracer's share;
//     1 and 2 are repeated (--repeat, default 3) and summarised as median and range;
//  3. bytes per pixel of the frames on disk;
//  4. unless --no-cycles, Cycles (Blender) against the path tracer: each renders twice with two
//     seeds; wall times, their ratio, each engine's noise (the variance of one render, estimated
//     as mean((Y1 - Y2)^2) / 2 over pixels, Y = luminance of direct + indirect) and the
//     time-to-equal-noise ratio (time x variance is constant as samples grow).
// Without DATASET it builds a test arena: a floor, walls and 40 pillars (static), 12 moving
// spheres of mixed materials, 6 point lights and the Preetham sky, seen by a fast-turning camera.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "convert/sky.h"
#include "core/image_io.h"
#include "core/math.h"
#include "raw_rays.h"
#include "gltf_builder.h"
#include "frames/frame_io.h"
#include "render/render_job.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace fs = std::filesystem;
using namespace dynbench;
using nlohmann::json;

namespace {

int box(test::GltfBuilder& b, glm::vec3 lo, glm::vec3 hi, int material) {
  std::vector<float> p;
  std::vector<std::uint32_t> idx;
  const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}};
  for (const auto& f : faces) {
    const auto base = static_cast<std::uint32_t>(p.size() / 3);
    for (int k : f) p.insert(p.end(), {c[k].x, c[k].y, c[k].z});
    idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  json prim = {{"attributes", {{"POSITION", b.accessor(p, "VEC3")}}}, {"indices", b.indices(idx)}, {"material", material}};
  b.doc["meshes"].push_back({{"primitives", json::array({prim})}});
  return static_cast<int>(b.doc["meshes"].size()) - 1;
}

int sphere(test::GltfBuilder& b, float radius, int material) {
  std::vector<float> p, n;
  std::vector<std::uint32_t> idx;
  const int rings = 32, segments = 64;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const double th = M_PI * r / rings, ph = 2 * M_PI * s / segments;
      const glm::vec3 d(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      p.insert(p.end(), {radius * d.x, radius * d.y, radius * d.z});
      n.insert(n.end(), {d.x, d.y, d.z});
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const auto a = static_cast<std::uint32_t>(r * (segments + 1) + s), c = a + static_cast<std::uint32_t>(segments + 1);
      idx.insert(idx.end(), {a, a + 1, c, a + 1, c + 1, c});
    }
  json prim = {{"attributes", {{"POSITION", b.accessor(p, "VEC3")}, {"NORMAL", b.accessor(n, "VEC3")}}}, {"indices", b.indices(idx)}, {"material", material}};
  b.doc["meshes"].push_back({{"primitives", json::array({prim})}});
  return static_cast<int>(b.doc["meshes"].size()) - 1;
}

fs::path buildArena(const fs::path& dir) {
  fs::create_directories(dir);
  test::GltfBuilder b;
  auto material = [&](glm::vec3 base, double metallic, double roughness) {
    b.doc["materials"].push_back({{"pbrMetallicRoughness", {{"baseColorFactor", {base.r, base.g, base.b, 1}}, {"metallicFactor", metallic}, {"roughnessFactor", roughness}}}});
    return static_cast<int>(b.doc["materials"].size()) - 1;
  };
  const int stone = material({0.55f, 0.5f, 0.45f}, 0, 0.9), brick = material({0.6f, 0.3f, 0.2f}, 0, 0.8);
  const int gold = material({1.0f, 0.77f, 0.34f}, 1, 0.3), plastic = material({0.1f, 0.3f, 0.8f}, 0, 0.4), steel = material({0.6f, 0.6f, 0.62f}, 1, 0.15);
  b.node({{"name", "floor"}, {"mesh", box(b, {-30, -1, -30}, {30, 0, 30}, stone)}});
  b.node({{"name", "wall_n"}, {"mesh", box(b, {-30, 0, -30}, {30, 8, -29}, brick)}});
  b.node({{"name", "wall_s"}, {"mesh", box(b, {-30, 0, 29}, {30, 8, 30}, brick)}});
  b.node({{"name", "wall_w"}, {"mesh", box(b, {-30, 0, -30}, {-29, 8, 30}, brick)}});
  for (int i = 0; i < 40; ++i) {
    const float x = -24.0f + 12.0f * static_cast<float>(i % 5), z = -24.0f + 6.5f * static_cast<float>(i / 5);
    b.node({{"name", fmt::format("pillar_{}", i)}, {"mesh", box(b, {x - 0.6f, 0, z - 0.6f}, {x + 0.6f, 3.0f + static_cast<float>(i % 3), z + 0.6f}, i % 2 ? stone : brick)}});
  }
  const int materials[3] = {gold, plastic, steel};
  int meshes[3];
  for (int k = 0; k < 3; ++k) meshes[k] = sphere(b, 0.8f, materials[k]);
  for (int i = 0; i < 12; ++i) {
    const int node = b.node({{"name", fmt::format("ball_{}", i)}, {"mesh", meshes[i % 3]}});
    std::vector<float> times, values;
    for (int k = 0; k <= 40; ++k) {
      const double t = k * 0.25, a = 0.6 * t + i * 0.52;
      times.push_back(static_cast<float>(t));
      values.insert(values.end(), {static_cast<float>((8 + i % 4 * 3) * std::cos(a)), static_cast<float>(0.8 + std::abs(std::sin(3 * t + i)) * 2),
                                   static_cast<float>((8 + i % 4 * 3) * std::sin(a))});
    }
    b.channel(node, "translation", times, values);
  }
  json lights = json::array();
  for (int i = 0; i < 6; ++i) {
    lights.push_back({{"type", "point"}, {"intensity", 300.0}, {"color", {1.0, 0.8 + 0.04 * i, 0.6 + 0.06 * i}}});
    b.node({{"translation", {-20.0 + 8 * i, 5.0, (i % 2 ? 10.0 : -10.0)}}, {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}}});
  }
  b.doc["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  // A fast first-person-like camera: circling the arena at 1.7 m and turning 6 degrees per frame.
  const int eye = b.node({{"name", "eye"}, {"camera", b.perspectiveCamera(1.0)}});
  std::vector<float> times, position, rotation;
  for (int k = 0; k <= 240; ++k) {
    const double t = k / 24.0, a = 0.5 * t;
    times.push_back(static_cast<float>(t));
    position.insert(position.end(), {static_cast<float>(18 * std::cos(a)), 1.7f, static_cast<float>(18 * std::sin(a))});
    for (float v : test::yawQuat(6.0 * k + 20 * std::sin(t * 3))) rotation.push_back(v);
  }
  b.channel(eye, "translation", times, position);
  b.channel(eye, "rotation", times, rotation);
  const auto sky = convert::preethamSky({});
  FloatImage image{sky.width, sky.height, 3, sky.rgb, {}};
  if (!writeImage(dir / "arena_sky.hdr", image)) std::fprintf(stderr, "cannot write the sky\n");
  b.doc["extensions"]["DYNBENCH_environment"] = {{"uri", "arena_sky.hdr"}};
  b.doc["extensionsUsed"] = {"KHR_lights_punctual", "DYNBENCH_environment"};
  return b.write(dir, "arena");
}

// Luminance of direct + indirect per pixel, for every rendered frame, concatenated.
std::vector<double> radiance(const fs::path& dir, const std::vector<long>& frames) {
  std::vector<double> out;
  for (long f : frames) {
    auto image = readImage(frames::frameImagePath(dir, f));
    if (!image) {
      std::fprintf(stderr, "%s\n", image.error().message.c_str());
      std::exit(1);
    }
    std::vector<std::size_t> at;
    for (const char* name : {"direct.R", "direct.G", "direct.B", "indirect.R", "indirect.G", "indirect.B"})
      at.push_back(static_cast<std::size_t>(std::find(image->channelNames.begin(), image->channelNames.end(), name) - image->channelNames.begin()));
    for (std::size_t i = 0; i < static_cast<std::size_t>(image->width) * image->height; ++i) {
      const float* p = &image->pixels[i * static_cast<std::size_t>(image->channels)];
      out.push_back(luminance(glm::dvec3(p[at[0]] + p[at[3]], p[at[1]] + p[at[4]], p[at[2]] + p[at[5]])));
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dataset, frames = "0:3", res = "480x270";
  int spp = 16, bounces = 4, repeats = 3;
  bool cycles = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) frames = argv[++i];
    else if (a == "--res" && i + 1 < argc) res = argv[++i];
    else if (a == "--spp" && i + 1 < argc) spp = std::atoi(argv[++i]);
    else if (a == "--bounces" && i + 1 < argc) bounces = std::atoi(argv[++i]);
    else if (a == "--repeat" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    else if (a == "--no-cycles") cycles = false;
    else dataset = a;
  }
  const fs::path work = fs::temp_directory_path() / "dynbench_bench_render";
  if (dataset.empty()) dataset = buildArena(work / "arena").string();
  auto scene = scene::loadScene(dataset);
  if (!scene) {
    std::fprintf(stderr, "%s\n", scene.error().message.c_str());
    return 1;
  }
  render::RenderJob job;
  job.dataset = dataset;
  int w = 0, h = 0;
  std::sscanf(res.c_str(), "%dx%d", &w, &h);
  job.settings.width = w;
  job.settings.height = h;
  job.settings.samplesPerPixel = spp;
  job.settings.bounces = bounces;
  auto range = render::parseFrameRange(frames);
  if (!range) {
    std::fprintf(stderr, "%s\n", range.error().message.c_str());
    return 1;
  }
  job.frames = *range;
  auto list = render::jobFrames(*scene, job);
  if (!list) {
    std::fprintf(stderr, "%s\n", list.error().message.c_str());
    return 1;
  }
  std::printf("%s: frames %s (%zu), %dx%d, %d spp, %d bounces\n", dataset.c_str(), frames.c_str(), list->size(), w, h, spp, bounces);
  auto run = [&](const std::string& engine, int threads, std::uint64_t seed, const fs::path& out) {
    job.engine = engine;
    job.threads = threads;
    job.settings.seed = seed;
    job.output = out;
    fs::remove_all(out);
    auto summary = render::renderDataset(*scene, job);
    if (!summary) {
      std::fprintf(stderr, "%s: %s\n", engine.c_str(), summary.error().message.c_str());
      std::exit(1);
    }
    return *summary;
  };

  // A warm-up render (one frame, one sample), so neither measurement below pays for cold caches
  // and first-time library loading.
  {
    const auto saved = job.frames;
    const int savedSpp = job.settings.samplesPerPixel;
    job.frames = {list->front(), list->front(), 1};
    job.settings.samplesPerPixel = 1;
    run("embree", 0, 1, work / "warm_up");
    job.frames = saved;
    job.settings.samplesPerPixel = savedSpp;
  }

  // Embree's ceiling on the same scene (the first frame's time) and camera.
  auto rt = render::RayTracingScene::create(*scene);
  auto node = scene::selectCameraNode(*scene, job.camera);
  if (!rt || !node) {
    std::fprintf(stderr, "cannot build the ray-tracing scene or find the camera\n");
    return 1;
  }
  const scene::Evaluator evaluator(*scene);
  auto cameras = render::frameCameras(evaluator, *node, job, list->front());
  if (!cameras || !(*rt)->update(cameras->time)) {
    std::fprintf(stderr, "cannot place the scene at the first frame\n");
    return 1;
  }

  // 1 and 2, `repeats` times: the path tracer on one thread and on two, then Embree's raw rays,
  // so that each ratio compares measurements taken moments apart; the summary gives the median and
  // the range, since one run on a shared machine can be off by several per cent.
  std::vector<double> oneThread, speedup, jobSpeedup, random, primary, shareRandom, sharePrimary;
  for (int r = 0; r < repeats; ++r) {
    double framesSeconds[2] = {0, 0}, jobSeconds[2] = {0, 0}, raysPerSecond[2] = {0, 0};
    for (int t = 1; t <= 2; ++t) {
      const auto s = run("embree", t, 1, work / fmt::format("embree_{}thread", t));
      framesSeconds[t - 1] = s.seconds - s.loadSeconds;
      jobSeconds[t - 1] = s.seconds;
      raysPerSecond[t - 1] = static_cast<double>(s.rays) / framesSeconds[t - 1];
      std::printf("[%d/%d] path tracer, %d thread(s): %.2f M rays/s (%.2f M rays/s per thread) over %.2f s of frames; whole job %.2f s "
                  "(loading %.2f s)\n",
                  r + 1, repeats, t, raysPerSecond[t - 1] / 1e6, raysPerSecond[t - 1] / t / 1e6, framesSeconds[t - 1], s.seconds,
                  s.loadSeconds);
      if (t == 1 && r == 0) {
        // What a ray costs depends on the mix: shadow rays (any hit) per shading point, bounce rays.
        const double points = static_cast<double>(std::max<std::uint64_t>(1, s.light.shadingPoints));
        std::printf("  per shading point: %.2f rays, %.2f punctual lights in reach (of %.1f in the frame); %.0f ns of frame time\n",
                    static_cast<double>(s.rays) / points, static_cast<double>(s.light.punctualEvaluated) / points,
                    static_cast<double>(s.light.punctualInFrame) / static_cast<double>(list->size()), 1e9 * framesSeconds[0] / points);
      }
    }
    const auto raw = bench::measureRawRays(**rt, cameras->camera);
    std::printf("[%d/%d] Embree raw, one thread: primary %.2f M rays/s (%.0f %% hit), random %.2f M rays/s (%.0f %% hit)\n", r + 1,
                repeats, raw.primaryRaysPerSecond / 1e6, 100 * raw.primaryHitShare, raw.randomRaysPerSecond / 1e6,
                100 * raw.randomHitShare);
    oneThread.push_back(raysPerSecond[0] / 1e6);
    speedup.push_back(framesSeconds[0] / framesSeconds[1]);
    jobSpeedup.push_back(jobSeconds[0] / jobSeconds[1]);
    random.push_back(raw.randomRaysPerSecond / 1e6);
    primary.push_back(raw.primaryRaysPerSecond / 1e6);
    shareRandom.push_back(100 * raysPerSecond[0] / raw.randomRaysPerSecond);
    sharePrimary.push_back(100 * raysPerSecond[0] / raw.primaryRaysPerSecond);
  }
  // "median (min-max)" of a figure over the repeats.
  auto spread = [](std::vector<double> v, const char* format) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return fmt::format(fmt::runtime(format), median) + " (" + fmt::format(fmt::runtime(format), v.front()) + "-" +
           fmt::format(fmt::runtime(format), v.back()) + ")";
  };
  std::printf("summary over %d run(s), median (min-max):\n", repeats);
  std::printf("  path tracer, one thread: %s M rays/s\n", spread(oneThread, "{:.2f}").c_str());
  std::printf("  2-thread speedup: %sx over the frames, %sx over the whole job\n", spread(speedup, "{:.2f}").c_str(),
              spread(jobSpeedup, "{:.2f}").c_str());
  std::printf("  Embree raw, one thread: random %s M rays/s, primary %s M rays/s\n", spread(random, "{:.2f}").c_str(),
              spread(primary, "{:.2f}").c_str());
  std::printf("  path tracer (one thread) / Embree raw: %s %% of random-ray, %s %% of primary-ray throughput\n",
              spread(shareRandom, "{:.1f}").c_str(), spread(sharePrimary, "{:.1f}").c_str());

  // 3. Bytes per pixel on disk.
  {
    std::uintmax_t bytes = 0;
    for (long f : *list) bytes += fs::file_size(frames::frameImagePath(work / "embree_1thread", f));
    std::printf("frames on disk: %.2f bytes per pixel\n", static_cast<double>(bytes) / (static_cast<double>(list->size()) * w * h));
  }
  if (!cycles) return 0;

  // 4. Cycles at equal noise.
  double seconds[2] = {0, 0}, variance[2] = {0, 0};
  const char* names[2] = {"embree", "cycles"};
  for (int e = 0; e < 2; ++e) {
    std::vector<double> y[2];
    for (int r = 0; r < 2; ++r) {
      const auto s = run(names[e], 0, static_cast<std::uint64_t>(r + 1), work / fmt::format("{}_{}", names[e], r));
      seconds[e] += s.seconds / 2;
      y[r] = radiance(job.output, *list);
    }
    double sum = 0, mean = 0;
    for (std::size_t i = 0; i < y[0].size(); ++i) {
      sum += (y[0][i] - y[1][i]) * (y[0][i] - y[1][i]) / 2;
      mean += (y[0][i] + y[1][i]) / 2;
    }
    variance[e] = sum / static_cast<double>(y[0].size());
    std::printf("%-7s %8.2f s per run (%.2f s per frame), mean luminance %.4g, noise variance %.4g\n", names[e], seconds[e],
                seconds[e] / list->size(), mean / static_cast<double>(y[0].size()), variance[e]);
  }
  std::printf("cycles / embree time: %.2fx; time to equal noise (time x variance): %.2fx\n", seconds[1] / seconds[0],
              seconds[1] * variance[1] / (seconds[0] * variance[0]));
  return 0;
}
