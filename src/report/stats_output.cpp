#include "report/stats_output.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "core/json_fields.h"
#include "dynbench/version.h"
#include "report/tables.h"

namespace dynbench::report {
namespace {


std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

nlohmann::json summaryJson(const metrics::Summary& s) {
  return {{"mean", s.mean}, {"variance", s.variance}, {"max", s.max}};
}

}  // namespace

std::string formatBytes(std::uint64_t bytes) {
  const double b = static_cast<double>(bytes);
  if (bytes < 1024) return fmt::format("{} B", bytes);
  if (b < 1024.0 * 1024) return fmt::format("{:.1f} KiB", b / 1024);
  if (b < 1024.0 * 1024 * 1024) return fmt::format("{:.2f} MiB", b / (1024.0 * 1024));
  return fmt::format("{:.2f} GiB", b / (1024.0 * 1024 * 1024));
}

std::string markdownTable(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::vector<std::size_t> width(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    width[c] = std::max<std::size_t>(3, header[c].size());
    for (const auto& row : rows) width[c] = std::max(width[c], row[c].size());
  }
  // Columns whose every cell is a number (or "-") are right-aligned, text columns left-aligned.
  std::vector<char> numeric(header.size(), 1);
  for (const auto& row : rows)
    for (std::size_t c = 0; c < row.size(); ++c)
      if (row[c].empty() || !(std::isdigit(static_cast<unsigned char>(row[c][0])) || row[c] == "-")) numeric[c] = 0;
  numeric[0] = 0;
  auto line = [&](const std::vector<std::string>& cells, bool body) {
    std::string out = "|";
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const bool right = body && numeric[c];
      out += right ? fmt::format(" {:>{}} |", cells[c], width[c]) : fmt::format(" {:<{}} |", cells[c], width[c]);
    }
    return out + "\n";
  };
  std::string out = line(header, false);
  out += "|";
  for (std::size_t c = 0; c < header.size(); ++c) out += !numeric[c] ? fmt::format(" {} |", std::string(width[c], '-'))
                                                                      : fmt::format(" {}: |", std::string(width[c] - 1, '-'));
  out += "\n";
  for (const auto& row : rows) out += line(row, true);
  return out;
}

std::string statsMarkdown(const std::vector<StatsRow>& rows) {
  std::string out;
  for (const auto& t : statsTables(rows)) out += markdownTable(t);
  return out;
}

nlohmann::json statsJson(const std::vector<StatsRow>& rows, double fps) {
  nlohmann::json datasets = nlohmann::json::array();
  for (const auto& r : rows) {
    const auto& p = r.properties;
    const auto& m = r.motion;
    nlohmann::json files = nlohmann::json::array();
    nlohmann::json properties = {
        {"file_format", p.fileFormat},
        {"total_bytes", p.totalBytes},
        {"file_count", p.fileCount},
        {"faces", p.faces},
        {"unique_faces", p.uniqueFaces},
        {"animated_camera", p.animatedCamera},
        {"morph_targets", p.morphTargets},
        {"material_count", p.materialCount},
        {"texture_count", p.textureCount},
        {"texture_bytes", p.textureBytes},
        {"material_workflow", p.materialWorkflow},
        {"workflow_counts", p.workflowCounts},
        {"animation_frames", p.animationFrames},
        {"start_time_s", p.startTime},
        {"end_time_s", p.endTime},
        {"static_objects", p.staticObjects},
        {"dynamic_rigid_objects", p.dynamicRigidObjects},
        {"armatures", p.armatures},
        {"static_point_lights", p.staticPointLights},
        {"dynamic_point_lights", p.dynamicPointLights},
        {"spot_lights", p.spotLights},
        {"directional_lights", p.directionalLights},
        {"nodes", p.nodes},
        {"meshes", p.meshes},
        {"skins", p.skins},
        {"joints", p.joints},
        {"cameras", p.cameras},
        {"lights", p.lights},
        {"animations", p.animations},
        {"channels", p.channels},
        {"morph_animated_objects", p.morphAnimatedObjects},
    };
    nlohmann::json motion = {{"camera", m.hasCamera ? nlohmann::json(m.cameraName) : nlohmann::json(nullptr)},
                             {"camera_node", m.cameraNode},
                             {"frames", m.frames.size()}};
    if (m.hasCamera) {
      motion["position"] = summaryJson(m.position);
      motion["rotation_degrees"] = summaryJson(m.rotation);
      // Eq. 2.4 evaluated literally, ||ln(q_{i-1}^-1 q_i)||, is half the rotation angle: the thesis's
      // Table 6.5 convention (docs/metrics.md). Mean and max halve, the variance quarters.
      motion["rotation_eq24"] = summaryJson({m.rotation.mean / 2, m.rotation.variance / 4, m.rotation.max / 2});
      motion["pitch_degrees"] = summaryJson(m.pitch);
      motion["yaw_degrees"] = summaryJson(m.yaw);
      motion["roll_degrees"] = summaryJson(m.roll);
      // The summaries above leave cut frames out (docs/metrics.md); these keep them.
      motion["cuts"] = m.cuts;
      const auto& all = m.includingCuts;
      motion["with_cuts"] = {{"position", summaryJson(all.position)}, {"rotation_degrees", summaryJson(all.rotation)},
                                  {"pitch_degrees", summaryJson(all.pitch)}, {"yaw_degrees", summaryJson(all.yaw)},
                                  {"roll_degrees", summaryJson(all.roll)}};
    }
    datasets.push_back({{"name", r.name}, {"path", r.path}, {"properties", properties}, {"camera_motion", motion},
                        {"warnings", p.warnings}});
  }
  nlohmann::json root = {{"tool", "dynbench"}, {"version", kVersion}, {"command", "stats"},
                         {"fps", fps}, {"datasets", datasets}};
  return root;
}

std::string statsCsv(const std::vector<StatsRow>& rows) {
  std::string out =
      "name,path,file_format,total_bytes,faces,animated_camera,morph_targets,material_count,texture_count,texture_bytes,"
      "material_workflow,animation_frames,static_objects,dynamic_rigid_objects,armatures,static_point_lights,"
      "dynamic_point_lights,camera,position_mean,position_variance,position_max,rotation_mean_deg,rotation_variance_deg,"
      "rotation_max_deg,pitch_mean_deg,pitch_variance_deg,yaw_mean_deg,yaw_variance_deg,roll_mean_deg,roll_variance_deg,cuts\n";
  for (const auto& r : rows) {
    const auto& p = r.properties;
    const auto& m = r.motion;
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csvField(r.name), csvField(r.path),
                       csvField(p.fileFormat), p.totalBytes, p.faces, p.animatedCamera ? 1 : 0, p.morphTargets ? 1 : 0,
                       p.materialCount, p.textureCount, p.textureBytes, csvField(p.materialWorkflow), p.animationFrames,
                       p.staticObjects, p.dynamicRigidObjects, p.armatures, p.staticPointLights, p.dynamicPointLights,
                       csvField(m.hasCamera ? m.cameraName : ""));
    if (m.hasCamera) {
      out += fmt::format(",{},{},{},{},{},{},{},{},{},{},{},{},{}", m.position.mean, m.position.variance, m.position.max,
                         m.rotation.mean, m.rotation.variance, m.rotation.max, m.pitch.mean, m.pitch.variance, m.yaw.mean,
                         m.yaw.variance, m.roll.mean, m.roll.variance, m.cuts);
    } else {
      out += ",,,,,,,,,,,,,";
    }
    out += "\n";
  }
  return out;
}

std::string cameraSeriesCsv(const metrics::CameraMotion& motion) {
  std::string out =
      "frame,time_s,x,y,z,yaw_deg,pitch_deg,roll_deg,position_delta,rotation_delta_deg,yaw_delta_deg,pitch_delta_deg,"
      "roll_delta_deg,cut\n";
  for (const auto& f : motion.frames)
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", f.frame, f.time, f.position.x, f.position.y, f.position.z,
                       f.yawDegrees, f.pitchDegrees, f.rollDegrees, f.positionDelta, f.rotationDelta, f.yawDelta,
                       f.pitchDelta, f.rollDelta, f.cut ? 1 : 0);
  return out;
}

Expected<StatsRow> readStatsRow(const nlohmann::json& document, const std::filesystem::path& file, std::size_t index) {
  const JsonFields f(document, file);
  const std::string base = fmt::format("/datasets/{}", index);
  StatsRow row;
  auto name = f.string(base + "/name");
  if (!name) return std::unexpected(name.error());
  row.name = *name;
  if (f.has(base + "/path")) {
    auto path = f.string(base + "/path");
    if (!path) return std::unexpected(path.error());
    row.path = *path;
  }
  auto fps = f.number("/fps");
  if (!fps) return std::unexpected(fps.error());
  auto& p = row.properties;
  p.fps = *fps;
  const std::string props = base + "/properties/";
  for (auto [key, target] : {std::pair{"file_format", &p.fileFormat}, {"material_workflow", &p.materialWorkflow}}) {
    auto v = f.string(props + key);
    if (!v) return std::unexpected(v.error());
    *target = *v;
  }
  for (auto [key, target] : {std::pair{"animated_camera", &p.animatedCamera}, {"morph_targets", &p.morphTargets}}) {
    auto v = f.boolean(props + key);
    if (!v) return std::unexpected(v.error());
    *target = *v;
  }
  for (auto [key, target] : {std::pair{"total_bytes", &p.totalBytes}, {"faces", &p.faces}, {"texture_bytes", &p.textureBytes}}) {
    auto v = f.count(props + key);
    if (!v) return std::unexpected(v.error());
    *target = *v;
  }
  for (auto [key, target] : {std::pair{"material_count", &p.materialCount}, {"texture_count", &p.textureCount},
                             {"animation_frames", &p.animationFrames}, {"static_objects", &p.staticObjects},
                             {"dynamic_rigid_objects", &p.dynamicRigidObjects}, {"armatures", &p.armatures},
                             {"static_point_lights", &p.staticPointLights}, {"dynamic_point_lights", &p.dynamicPointLights}}) {
    auto v = f.count(props + key);
    if (!v) return std::unexpected(v.error());
    *target = static_cast<std::size_t>(*v);
  }
  if (f.has(props + "workflow_counts")) {
    auto counts = f.value(props + "workflow_counts");
    if (!counts) return std::unexpected(counts.error());
    if (!(*counts)->is_object()) return fail(ErrorCode::kInvalidData, "{}: {}workflow_counts: expected an object", file.string(), props);
    for (const auto& [workflow, n] : (*counts)->items()) {
      auto v = f.count(props + "workflow_counts/" + workflow);
      if (!v) return std::unexpected(v.error());
      p.workflowCounts[workflow] = static_cast<std::size_t>(*v);
    }
  }
  const std::string motion = base + "/camera_motion/";
  auto camera = f.value(motion + "camera");
  if (!camera) return std::unexpected(camera.error());
  auto& m = row.motion;
  m.hasCamera = !(*camera)->is_null();
  if (m.hasCamera) {
    auto cameraName = f.string(motion + "camera");
    if (!cameraName) return std::unexpected(cameraName.error());
    m.cameraName = *cameraName;
    for (auto [key, target] : {std::pair{"position", &m.position}, {"rotation_degrees", &m.rotation}, {"pitch_degrees", &m.pitch},
                               {"yaw_degrees", &m.yaw}, {"roll_degrees", &m.roll}})
      for (auto [field, value] : {std::pair{"mean", &target->mean}, {"variance", &target->variance}, {"max", &target->max}}) {
        auto v = f.number(motion + key + "/" + field);
        if (!v) return std::unexpected(v.error());
        *value = *v;
      }
    if (f.has(motion + "cuts")) {  // older stats files have no cuts
      auto cuts = f.count(motion + "cuts");
      if (!cuts) return std::unexpected(cuts.error());
      m.cuts = static_cast<std::size_t>(*cuts);
    }
  }
  return row;
}

}  // namespace dynbench::report
