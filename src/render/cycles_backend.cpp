#include "render/cycles_backend.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <string_view>

#include <fmt/format.h>

#include "core/files.h"
#include "core/math.h"
#include "core/process.h"
#include "core/runtime_files.h"
#include "frames/frame_io.h"
#include "render/backend.h"
#include "scene/pose.h"

namespace dynbench::render {
namespace {

namespace fs = std::filesystem;

// The Blender side of the backend, found as every run-time file (core/runtime_files.h).
Expected<fs::path> renderScript() {
  return findRuntimeFile({"the Blender script render_cycles.py", "DYNBENCH_BLENDER_SCRIPT", "share/dynbench/blender/render_cycles.py",
                          fs::path(DYNBENCH_SOURCE_DIR) / "tools" / "blender" / "render_cycles.py"});
}

// Channel lookup by Blender's names ("ViewLayer.DiffDir.R" or "DiffDir.R").
struct Passes {
  const FloatImage& image;
  std::map<std::string, int> index;
  explicit Passes(const FloatImage& i) : image(i) {
    for (std::size_t c = 0; c < i.channelNames.size(); ++c) {
      std::string name = i.channelNames[c];
      // Drop the view layer's name: everything before the second-to-last dot.
      const auto last = name.rfind('.');
      const auto before = last == std::string::npos || last == 0 ? std::string::npos : name.rfind('.', last - 1);
      if (before != std::string::npos) name = name.substr(before + 1);
      index[name] = static_cast<int>(c);
    }
  }
  int find(const std::string& name) const {
    const auto it = index.find(name);
    return it == index.end() ? -1 : it->second;
  }
  float at(std::size_t pixel, int channel) const {
    return channel < 0 ? 0.0f : image.pixels[pixel * static_cast<std::size_t>(image.channels) + static_cast<std::size_t>(channel)];
  }
};

}  // namespace

Expected<fs::path> findBlender(const std::string& blender) {
  if (blender.find('/') != std::string::npos) {
    if (isExecutable(blender)) return fs::path(blender);
    return fail(ErrorCode::kExternalTool, "--blender {}: not an executable file", blender);
  }
  if (auto found = findOnPath(blender); !found.empty()) return found;
  return fail(ErrorCode::kExternalTool,
              "--engine cycles needs Blender, and '{}' is not on PATH: install Debian's blender package "
              "(apt-get install blender) or pass --blender PATH",
              blender);
}

Expected<frames::FeatureFrame> cyclesPassesToContract(const FloatImage& passes, const fs::path& source, const RenderCamera& camera,
                                                      const FloatImage* geometryPasses) {
  const Passes p(passes);
  const Passes g(geometryPasses ? *geometryPasses : passes);
  for (const char* required : {"Position.X", "Normal.X", "DiffDir.R", "DiffInd.R", "DiffCol.R", "Depth.Z"})
    if (p.find(required) < 0 || g.find(required) < 0)
      return fail(ErrorCode::kParse, "{}: Cycles output lacks the {} pass", source.string(), required);
  if (geometryPasses && (geometryPasses->width != passes.width || geometryPasses->height != passes.height))
    return fail(ErrorCode::kParse, "{}: Cycles' geometry render is {}x{}, its radiance render {}x{}", source.string(), geometryPasses->width,
                geometryPasses->height, passes.width, passes.height);
  frames::FeatureFrame out;
  out.width = passes.width;
  out.height = passes.height;
  out.camera = camera.frameCamera();
  const auto n = out.pixelCount();
  // Cycles has no id, motion or variance passes: those buffers stay empty (absent from the EXR).
  for (auto* b : {&out.position, &out.normal, &out.direct, &out.indirect, &out.albedo}) b->assign(3 * n, 0.0f);
  for (auto* b : {&out.depth, &out.hit}) b->assign(n, 0.0f);
  const char* rgb = "RGB";
  const glm::dvec3 forward = -glm::dvec3(camera.world()[2]);
  for (std::size_t i = 0; i < n; ++i) {
    // The geometry passes from the centre's render (the radiance render's own without a filter).
    const bool hit = g.at(i, g.find("Depth.Z")) < 1e9f;
    // Blender world (x, y, z) is glTF (x, z, -y).
    auto toGltf = [](glm::dvec3 b) { return glm::dvec3(b.x, b.z, -b.y); };
    const glm::dvec3 position = toGltf({g.at(i, g.find("Position.X")), g.at(i, g.find("Position.Y")), g.at(i, g.find("Position.Z"))});
    const glm::dvec3 normal = toGltf({g.at(i, g.find("Normal.X")), g.at(i, g.find("Normal.Y")), g.at(i, g.find("Normal.Z"))});
    for (int c = 0; c < 3; ++c) {
      const std::size_t k = 3 * i + static_cast<std::size_t>(c);
      out.position[k] = hit ? static_cast<float>(position[c]) : 0.0f;
      out.normal[k] = hit ? static_cast<float>(normal[c]) : 0.0f;
      const std::string ch(1, rgb[c]);
      double direct = p.at(i, p.find("Emit." + ch)) + p.at(i, p.find("Env." + ch)), indirect = 0.0;
      for (const char* kind : {"Diff", "Gloss", "Trans"}) {
        const double colour = p.at(i, p.find(std::string(kind) + "Col." + ch));
        direct += colour * p.at(i, p.find(std::string(kind) + "Dir." + ch));
        indirect += colour * p.at(i, p.find(std::string(kind) + "Ind." + ch));
      }
      out.direct[k] = static_cast<float>(direct);
      out.indirect[k] = static_cast<float>(indirect);
      out.albedo[k] = g.at(i, g.find("DiffCol." + ch));
    }
    out.depth[i] = hit ? static_cast<float>(glm::dot(position - camera.position(), forward)) : 0.0f;
    out.hit[i] = hit ? 1.0f : 0.0f;
  }
  return out;
}

namespace {

class CyclesBackend final : public RenderBackend {
 public:
  CyclesBackend(const scene::Scene& scene, const RenderJob& job, fs::path blender, fs::path script)
      : scene_(scene), job_(job), blender_(std::move(blender)), script_(std::move(script)) {}
  Expected<void> render(const std::vector<FrameRequest>& requests, const FrameSink& done, const RowProgress& rows) override;

 private:
  const scene::Scene& scene_;
  const RenderJob& job_;
  fs::path blender_, script_;
};

Expected<void> CyclesBackend::render(const std::vector<FrameRequest>& requests, const FrameSink& done, const RowProgress& rows) {
  const RenderJob& job = job_;
  const scene::Scene& scene = scene_;
  const fs::path work = job.output / fmt::format(".cycles-{}", ::getpid());
  std::error_code ec;
  fs::create_directories(work, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: {}", work.string(), ec.message());

  nlohmann::json j;
  j["dataset"] = fs::absolute(job.dataset).string();
  j["fps"] = job.fps;
  j["width"] = job.settings.width;
  j["height"] = job.settings.height;
  j["samples_per_pixel"] = job.settings.samplesPerPixel;
  j["bounces"] = job.settings.bounces;
  j["seed"] = job.settings.seed;
  j["threads"] = job.threads;
  const bool filtered = job.settings.pixelFilter.type != PixelFilterType::kCentre;
  j["pixel_filter"] = {{"type", pixelFilterName(job.settings.pixelFilter.type)}, {"width", job.settings.pixelFilter.width}};
  if (job.settings.constantEnvironment)
    j["environment"] = {{"kind", "constant"},
                        {"radiance", {job.settings.constantEnvironment->r, job.settings.constantEnvironment->g, job.settings.constantEnvironment->b}}};
  else if (job.settings.useEnvironment && scene.environment)
    j["environment"] = {{"kind", "image"}, {"file", fs::absolute(scene.environment->file).string()}, {"intensity", scene.environment->intensity}};
  else
    j["environment"] = {{"kind", "none"}};
  const scene::Evaluator evaluator(scene);
  scene::ScenePose pose;
  for (const auto& request : requests) {
    const FrameCameras& c = request.cameras;
    nlohmann::json frame = {{"frame", request.frame},
                            {"time", c.time},
                            {"output", fs::absolute(work / fmt::format("cycles_{:05d}.exr", request.frame)).string()},
                            {"camera", {{"world", frames::matrixJson(c.camera.world())}, {"yfov", c.camera.yfov()}, {"znear", c.camera.znear()}, {"zfar", c.camera.zfar()}}}};
    if (filtered) frame["geometry_output"] = fs::absolute(work / fmt::format("cycles_{:05d}_geometry.exr", request.frame)).string();
    evaluator.evaluate(c.time, pose);
    frame["lights"] = nlohmann::json::array();
    for (std::size_t n = 0; n < scene.nodes.size(); ++n) {
      if (scene.nodes[n].light < 0) continue;
      const auto& l = pose.lights[static_cast<std::size_t>(scene.nodes[n].light)];  // colour and intensity as animated
      const RigidPose rigid = decomposeRigid(pose.world[n]);
      glm::dmat4 world = glm::mat4_cast(rigid.rotation);
      world[3] = glm::dvec4(rigid.position, 1.0);
      frame["lights"].push_back({{"type", toString(l.type)},
                                 {"world", frames::matrixJson(world)},
                                 {"color", {l.color.r, l.color.g, l.color.b}},
                                 {"intensity", l.intensity},
                                 {"inner_cone", l.innerConeAngle},
                                 {"outer_cone", l.outerConeAngle},
                                 {"range", l.range},
                                 {"visible", pose.visible[n] != 0}});
    }
    j["frames"].push_back(frame);
  }
  const fs::path jobFile = work / "job.json";
  if (auto w = writeFileAtomic(jobFile, j.dump(1)); !w) return std::unexpected(w.error());

  std::size_t finished = 0;
  std::string error;
  std::optional<Error> handOver;  // a finished frame that could not be read or written
  auto onLine = [&](std::string_view line) {
    if (line.starts_with("DYNBENCH_ERROR ")) error = line.substr(15);
    if (!line.starts_with("DYNBENCH_FRAME_DONE ")) return true;
    // Hand the finished frame over right away, so an interrupted run keeps it.
    const std::size_t k = finished++;
    const fs::path raw = j["frames"][k]["output"].get<std::string>();
    const fs::path rawGeometry = filtered ? j["frames"][k]["geometry_output"].get<std::string>() : std::string();
    auto frame = [&]() -> Expected<void> {
      auto passes = readImage(raw);
      if (!passes) return std::unexpected(passes.error());
      std::optional<FloatImage> geometry;
      if (filtered) {
        auto g = readImage(rawGeometry);
        if (!g) return std::unexpected(g.error());
        geometry = std::move(*g);
      }
      auto image = cyclesPassesToContract(*passes, raw, requests[k].cameras.camera, geometry ? &*geometry : nullptr);
      if (!image) return std::unexpected(image.error());
      image->frame = requests[k].frame;
      image->time = requests[k].cameras.time;
      return done(std::move(*image));
    }();
    if (!frame) {
      handOver = frame.error();
      return false;  // stop Blender: the job has failed
    }
    std::error_code removeError;
    fs::remove(raw, removeError);
    if (filtered) fs::remove(rawGeometry, removeError);
    if (rows && finished < requests.size()) rows(finished, 0);
    return true;
  };
  ProcessOptions blender;
  blender.argv = {blender_.string(), "--background", "--factory-startup", "--python", script_.string(), "--", jobFile.string()};
  blender.onLine = onLine;
  auto run = runProcess(blender);
  if (!run) return std::unexpected(run.error());
  if (handOver) return std::unexpected(*handOver);
  if (!run->succeeded() || finished != requests.size())
    return fail(ErrorCode::kExternalTool, "Blender (Cycles) failed after {} of {} frames{}; its last output:\n{}", finished, requests.size(),
                error.empty() ? "" : ": " + error, run->tail);
  fs::remove_all(work, ec);
  return {};
}

}  // namespace

Expected<std::unique_ptr<RenderBackend>> createCyclesBackend(const BackendContext& context) {
  if (context.job.settings.jitter)
    return fail(ErrorCode::kUnsupported, "--jitter is implemented by the embree engine only (Cycles renders pixel centres)");
  // Correlated re-shading needs each sample's first hit rebuilt in another frame and both shaded
  // with the same random numbers: Cycles cannot be asked for that from a script.
  if (context.job.settings.pairs)
    return fail(ErrorCode::kUnsupported,
                "--pairs (radiance-change pairs for Table 6.7's radiance columns) is implemented by the embree engine only; render with "
                "--no-pairs and run discard with --radiance-test expected (the image-against-image test)");
  auto blender = findBlender(context.job.blender);
  if (!blender) return std::unexpected(blender.error());
  auto script = renderScript();
  if (!script) return std::unexpected(script.error());
  return std::make_unique<CyclesBackend>(context.scene, context.job, std::move(*blender), std::move(*script));
}

}  // namespace dynbench::render
