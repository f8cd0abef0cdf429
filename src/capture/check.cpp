#include "capture/check.h"

#include <set>

#include <nlohmann/json.hpp>

#include "dynbench/version.h"

namespace dynbench::capture {

Expected<CaptureSummary> checkCapture(const std::filesystem::path& directory, const std::function<void(std::size_t)>& onFrame) {
  auto reader = CaptureReader::open(directory);
  if (!reader) return std::unexpected(reader.error());
  CaptureSummary s;
  s.settings = (*reader)->settings();
  for (const auto& m : (*reader)->models()) {
    ++s.models;
    s.skinnedModelFiles += m.joints.empty() ? 0 : 1;
    s.joints += m.joints.size();
    s.vertexAnimatedModelFiles += m.keyFrames > 0 ? 1 : 0;
    s.keyFrames += m.keyFrames;
    for (const auto& mesh : m.meshes) {
      ++s.meshes;
      s.vertices += mesh.positions.size();
      s.triangles += mesh.indices.size() / 3;
    }
  }
  std::set<std::uint64_t> cameras, staticModels, models, skinned, vertexAnimated, staticLights, dynamicLights;
  std::map<std::uint64_t, std::string> lightType;
  CaptureFrame frame;
  while (true) {
    auto more = (*reader)->next(frame);
    if (!more) return std::unexpected(more.error());
    if (!*more) break;
    if (s.frames == 0) {
      s.firstFrame = frame.number;
      s.startTime = frame.time;
    }
    ++s.frames;
    s.lastFrame = frame.number;
    s.endTime = frame.time;
    for (const auto& c : frame.cameras) cameras.insert(c.id);
    for (const auto& m : frame.staticModels) staticModels.insert(m.id);
    for (const auto& m : frame.models) models.insert(m.id);
    for (const auto& j : frame.joints) skinned.insert(j.id);
    for (const auto& v : frame.vertexFrames) vertexAnimated.insert(v.id);
    for (const auto& l : frame.lights) {
      (l.dynamic ? dynamicLights : staticLights).insert(l.id);
      lightType[l.id] = l.modelType;
    }
    s.cameraRecords += frame.cameras.size();
    s.modelRecords += frame.models.size() + frame.staticModels.size();
    s.jointRecords += frame.joints.size();
    s.vertexFrameRecords += frame.vertexFrames.size();
    s.lightRecords += frame.lights.size();
    for (const auto& c : frame.cuts) ++s.cutsByReason[c.reason];
    if (onFrame) onFrame(s.frames);
  }
  s.closed = (*reader)->closed();
  s.warnings = (*reader)->warnings();
  s.cameras = cameras.size();
  s.staticModels = staticModels.size();
  s.skinnedModels = skinned.size();
  s.vertexAnimatedModels = vertexAnimated.size();
  s.rigidModels = models.size() - skinned.size() - vertexAnimated.size();
  s.staticLights = staticLights.size();
  s.dynamicLights = dynamicLights.size();
  s.capturables = s.cameras + s.staticModels + models.size() + lightType.size();
  for (const auto& [id, type] : lightType) ++s.lightsByModelType[type];
  return s;
}

std::string summaryText(const std::filesystem::path& directory, const CaptureSummary& s) {
  std::string out = fmt::format("capture:     {}\n", directory.string());
  out += fmt::format("source:      {}\n", s.settings.source.empty() ? "-" : s.settings.source);
  out += fmt::format("map:         {} (offset {}, {}, {})\n", s.settings.mapName.empty() ? "-" : s.settings.mapName,
                     s.settings.mapOffset.x, s.settings.mapOffset.y, s.settings.mapOffset.z);
  if (s.settings.camera)
    out += fmt::format("camera:      aspect {:.4g}, vertical fov {:.4g} deg, near {:.4g}, far {:.4g}\n", s.settings.camera->aspect,
                       s.settings.camera->yfovDegrees, s.settings.camera->znear, s.settings.camera->zfar);
  const double span = s.endTime - s.startTime;
  out += fmt::format("frames:      {} (numbers {}..{}), {:.3f} s to {:.3f} s, span {:.3f} s", s.frames, s.firstFrame, s.lastFrame,
                     s.startTime, s.endTime, span);
  if (s.frames > 1 && span > 0) out += fmt::format(", {:.2f} frames/s", static_cast<double>(s.frames - 1) / span);
  out += fmt::format("\ncapturables: {} ({} cameras, {} static map models, {} rigid models, {} skinned models, {} vertex-animated models, "
                     "{} lights)\n",
                     s.capturables, s.cameras, s.staticModels, s.rigidModels, s.skinnedModels, s.vertexAnimatedModels,
                     s.staticLights + s.dynamicLights);
  std::string types;
  for (const auto& [type, n] : s.lightsByModelType) types += fmt::format("{}{} {}", types.empty() ? "" : ", ", n, type);
  out += fmt::format("lights:      {} static, {} dynamic{}\n", s.staticLights, s.dynamicLights, types.empty() ? "" : " (" + types + ")");
  std::size_t cuts = 0;
  std::string reasons;
  for (const auto& [reason, n] : s.cutsByReason) cuts += n, reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", n, reason);
  out += fmt::format("camera cuts: {}{}\n", cuts, reasons.empty() ? "" : " (" + reasons + ")");
  out += fmt::format("models:      {} ({} skinned, {} vertex-animated), {} meshes, {} vertices, {} triangles, {} joints, {} key frames\n",
                     s.models, s.skinnedModelFiles, s.vertexAnimatedModelFiles, s.meshes, s.vertices, s.triangles, s.joints, s.keyFrames);
  out += fmt::format("closed:      {}\n", s.closed ? "yes" : "no (the host stopped before closing the session)");
  return out;
}

nlohmann::json summaryJson(const std::filesystem::path& directory, const CaptureSummary& s) {
  nlohmann::json camera = nullptr;
  if (s.settings.camera)
    camera = {{"aspect", s.settings.camera->aspect}, {"yfov_degrees", s.settings.camera->yfovDegrees},
              {"znear", s.settings.camera->znear}, {"zfar", s.settings.camera->zfar}};
  const nlohmann::json j = {
      {"tool", "dynbench"}, {"version", kVersion}, {"command", "capture-check"}, {"capture", directory.string()},
      {"source", s.settings.source}, {"map", s.settings.mapName},
      {"map_offset", {s.settings.mapOffset.x, s.settings.mapOffset.y, s.settings.mapOffset.z}},
      {"metres_per_unit", s.settings.metresPerUnit}, {"camera_settings", camera}, {"closed", s.closed},
      {"frames", s.frames}, {"first_frame", s.firstFrame}, {"last_frame", s.lastFrame},
      {"start_time_s", s.startTime}, {"end_time_s", s.endTime},
      {"capturables", {{"total", s.capturables}, {"cameras", s.cameras}, {"static_models", s.staticModels},
                       {"rigid_models", s.rigidModels}, {"skinned_models", s.skinnedModels},
                       {"vertex_animated_models", s.vertexAnimatedModels},
                       {"static_lights", s.staticLights}, {"dynamic_lights", s.dynamicLights},
                       {"lights_by_model_type", s.lightsByModelType}}},
      {"models", {{"files", s.models}, {"skinned", s.skinnedModelFiles}, {"vertex_animated", s.vertexAnimatedModelFiles},
                  {"meshes", s.meshes}, {"vertices", s.vertices}, {"triangles", s.triangles}, {"joints", s.joints},
                  {"key_frames", s.keyFrames}}},
      {"records", {{"camera", s.cameraRecords}, {"model", s.modelRecords}, {"joints", s.jointRecords},
                   {"vertex_frames", s.vertexFrameRecords}, {"light", s.lightRecords}}},
      {"camera_cuts", s.cutsByReason},
      {"warnings", s.warnings}};
  return j;
}

}  // namespace dynbench::capture
