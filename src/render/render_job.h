#pragma once
// A render job: which frames of a dataset to render, with which backend, into which folder.
// Frames already complete with the same settings are skipped (resumable); each file is written
// to a temporary name and renamed.
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rates.h"
#include <nlohmann/json.hpp>

#include "render/path_tracer.h"
#include "scene/pose.h"
#include "scene/scene.h"

namespace dynbench::render {

// Frames first..last (inclusive) every `step`; last < 0 means the animation's last frame.
struct FrameRange {
  long first = 0, last = -1, step = 1;
};
// "A:B[:STEP]", "A:" (to the end) or "A" (one frame).
Expected<FrameRange> parseFrameRange(const std::string& text);

struct RenderJob {
  std::filesystem::path dataset;  // as given (recorded in sidecars)
  std::filesystem::path output;
  RenderSettings settings;
  std::string engine = "embree";  // a backend name (render/backend.h)
  double fps = kDefaultFrameRate;
  FrameRange frames;
  // The frame the scene is stepped from: every frame of the range from here (at its step) is set in
  // turn before the first frame rendered, those already complete too. The scene keeps state from
  // frame to frame (a moving mesh's BVH is built where it first appears and refitted after,
  // raytracing_scene.cpp), so a frame's bytes depend on where the stepping began; this makes a
  // resumed job, and a Slurm task that renders part of a range from its first frame, give the
  // whole job's bytes. Unset: the range's first frame.
  std::optional<long> stepFrom;
  std::optional<std::string> camera;
  // The animation played (index or name), when the scene was reduced to one with
  // scene::keepOnlyAnimation; recorded so that frames of another animation are not reused.
  std::optional<std::string> animation;
  int threads = 0;  // 0: all cores
  bool float32 = false;  // store every channel as 32-bit float (frames::WriteOptions)
  std::string blender = "blender";  // the Blender executable for --engine cycles
};

struct RenderSummary {
  std::vector<long> rendered, skipped;
  double seconds = 0.0;      // the whole job: loading the renderer (textures, BVH) and its frames
  double loadSeconds = 0.0;  // of which creating the renderer
  std::uint64_t cameraSamples = 0, rays = 0;
  std::uint64_t pixels = 0;      // of the frames rendered (with a sampling summary)
  long cappedPixels = 0;         // --converge: pixels that reached --max-spp before their target
  double pairs = 0.0;            // --pairs: radiance-change pairs taken, over the frames' pixels
  long undecidedPixels = 0;      // --pairs: pixels undecided at --max-pairs
  RenderStatistics light;        // the backend's counters (shading points, lights evaluated)
  std::vector<std::string> warnings;
};

// Progress callback: (rows done, rows total, frames done, frames total).
using RenderProgress = std::function<void(std::size_t, std::size_t, std::size_t, std::size_t)>;

// The frame indices the job covers for `scene` (every frame of the animation by default).
Expected<std::vector<long>> jobFrames(const scene::Scene& scene, const RenderJob& job);

Expected<RenderSummary> renderDataset(const scene::Scene& scene, const RenderJob& job, const RenderProgress& progress = {});

// The cameras of a frame and the frame before it (t - 1/fps), as the job renders them.
struct FrameCameras {
  double time = 0.0, previousTime = 0.0;
  RenderCamera camera, previous;
  bool cut = false;  // the dataset marks a camera cut between previousTime and time (scene::cameraCutBetween)
};
Expected<FrameCameras> frameCameras(const scene::Evaluator& evaluator, int cameraNode, const RenderJob& job, long frame);

// The frames' light reach (PathTracer::lightReach) at the job's size and camera and each frame's
// time, from one path tracer: per pixel, 1 where some light reaches the surface seen through the
// pixel's centre. No sampling, so no seed or sample count changes it (`dynbench fidelity`'s share
// without direct light).
Expected<std::map<long, std::vector<std::uint8_t>>> frameLightReach(const scene::Scene& scene, const RenderJob& job,
                                                                    const std::vector<long>& frames);

// The settings a frame's sidecar records (`render` object), compared when resuming.
nlohmann::json renderRecord(const RenderJob& job);

}  // namespace dynbench::render
