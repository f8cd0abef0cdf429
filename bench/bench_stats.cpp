// Load + stats benchmarks (run by hand; not part of the test suite):
//   build/release/bench/bench_stats [--benchmark_filter=...]
// - the largest real scenes at hand (Khronos RiggedFigure, assimp's duck.dae and an FBX skeleton);
// - a generated glTF with 5,000 animated nodes whose animation spans 10,000 frames at 24 fps
//   (camera keyed every frame; each node 100 translation + 100 rotation keys), written once to a
//   temporary folder;
// - reference: assimp's own glTF 2.0 importer reading the same generated file, so the glTF reader
//   is compared with a well-kept library in the same run (ratio = assimp time / dynbench time).
#include <benchmark/benchmark.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "gltf_builder.h"
#include "metrics/camera_motion.h"
#include "metrics/properties.h"
#include "scene/pose.h"
#include "scene/load.h"

namespace {

namespace fs = std::filesystem;
using namespace dynbench;

constexpr int kNodes = 5000;
constexpr int kFrames = 10000;
constexpr double kFps = 24.0;

const fs::path& generatedScene() {
  static const fs::path path = [] {
    const fs::path dir = fs::temp_directory_path() / "dynbench_bench";
    fs::create_directories(dir);
    const fs::path file = dir / "nodes5000_frames10000.gltf";
    if (fs::exists(file)) return file;
    test::GltfBuilder b;
    const double duration = (kFrames - 1) / kFps;
    // The camera: keyed every frame, yaw and position varying.
    std::vector<float> times, translation, rotation;
    for (int k = 0; k < kFrames; ++k) {
      times.push_back(static_cast<float>(k / kFps));
      translation.insert(translation.end(), {static_cast<float>(0.1 * k), 1.7f, static_cast<float>(std::sin(k * 0.01))});
      for (float v : test::yawQuat(3.0 * k)) rotation.push_back(v);
    }
    const int cam = b.node({{"name", "camera"}, {"camera", b.perspectiveCamera()}});
    b.channel(cam, "translation", times, translation);
    b.channel(cam, "rotation", times, rotation);
    const int pos = b.accessor({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
    b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}}}}}};
    std::vector<float> nodeTimes;
    for (int k = 0; k < 100; ++k) nodeTimes.push_back(static_cast<float>(duration * k / 99));
    for (int n = 0; n < kNodes; ++n) {
      const int node = b.node({{"name", "node" + std::to_string(n)}, {"mesh", 0}});
      std::vector<float> t, r;
      for (int k = 0; k < 100; ++k) {
        t.insert(t.end(), {static_cast<float>(n), static_cast<float>(k), 0.0f});
        for (float v : test::yawQuat(n + 10.0 * k)) r.push_back(v);
      }
      b.channel(node, "translation", nodeTimes, t);
      b.channel(node, "rotation", nodeTimes, r);
    }
    return b.write(dir, "nodes5000_frames10000");
  }();
  return path;
}

void BM_Load(benchmark::State& state, fs::path file) {
  for (auto _ : state) {
    auto scene = scene::loadScene(file);
    if (!scene) state.SkipWithError(scene.error().message.c_str());
    benchmark::DoNotOptimize(scene);
  }
  auto bin = file;
  bin.replace_extension(".bin");
  const auto bytes = fs::file_size(file) + (fs::exists(bin) ? fs::file_size(bin) : 0);
  state.counters["MiB"] = static_cast<double>(bytes) / (1024.0 * 1024.0);
}

void BM_LoadAndStats(benchmark::State& state, fs::path file) {
  std::size_t frames = 0;
  for (auto _ : state) {
    auto scene = scene::loadScene(file);
    if (!scene) {
      state.SkipWithError(scene.error().message.c_str());
      break;
    }
    const auto properties = metrics::measureProperties(*scene, kFps);
    auto motion = metrics::measureCameraMotion(*scene, kFps, std::nullopt);
    frames = properties.animationFrames;
    benchmark::DoNotOptimize(motion);
  }
  state.counters["frames"] = static_cast<double>(frames);
}

void BM_StatsOnly(benchmark::State& state) {
  auto scene = scene::loadScene(generatedScene());
  for (auto _ : state) {
    const auto properties = metrics::measureProperties(*scene, kFps);
    auto motion = metrics::measureCameraMotion(*scene, kFps, std::nullopt);
    benchmark::DoNotOptimize(properties);
    benchmark::DoNotOptimize(motion);
  }
  state.counters["frames/s"] = benchmark::Counter(kFrames, benchmark::Counter::kIsIterationInvariantRate);
}

// Every node's world matrix at 100 frames: the per-frame work `render` will need.
void BM_EvaluateAllNodes(benchmark::State& state) {
  auto scene = scene::loadScene(generatedScene());
  const scene::Evaluator evaluator(*scene);
  scene::ScenePose pose;
  for (auto _ : state)
    for (int f = 0; f < 100; ++f) {
      evaluator.evaluate(f * 100 / kFps, pose);
      benchmark::DoNotOptimize(pose.world.data());
    }
  state.counters["node evals/s"] =
      benchmark::Counter(100.0 * static_cast<double>(scene->nodes.size()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_ReferenceAssimpGltf(benchmark::State& state, fs::path file) {
  for (auto _ : state) {
    Assimp::Importer importer;
    const aiScene* s = importer.ReadFile(file.string(), aiProcess_ValidateDataStructure);
    if (!s) state.SkipWithError(importer.GetErrorString());
    benchmark::DoNotOptimize(s);
  }
}

const fs::path kTestData = DYNBENCH_TESTDATA_DIR;
const fs::path kModels = DYNBENCH_ASSIMP_MODELS_DIR;

BENCHMARK_CAPTURE(BM_LoadAndStats, RiggedFigure_gltf, kTestData / "RiggedFigure/RiggedFigure.gltf")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadAndStats, duck_dae, kModels / "Collada/duck.dae")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadAndStats, animation_with_skeleton_fbx, kModels / "FBX/animation_with_skeleton.fbx")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Load, generated_5000_nodes, generatedScene())->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_ReferenceAssimpGltf, generated_5000_nodes, generatedScene())->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_StatsOnly)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LoadAndStats, generated_5000_nodes, generatedScene())->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EvaluateAllNodes)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
