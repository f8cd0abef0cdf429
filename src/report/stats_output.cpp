#include "report/stats_output.h"

#include <algorithm>

#include <nlohmann/json.hpp>

#include "dynbench/version.h"

namespace dynbench::report {
namespace {

std::string fixed3(double v) { return fmt::format("{:.3f}", v); }
std::string yesNo(bool b) { return b ? "Yes" : "No"; }

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
  auto table = [&](const std::string& title, const std::vector<std::string>& header, auto cells) {
    std::vector<std::vector<std::string>> body;
    for (const auto& r : rows) {
      std::vector<std::string> row{r.name};
      for (auto& c : cells(r)) row.push_back(std::move(c));
      body.push_back(std::move(row));
    }
    out += fmt::format("{}\n\n{}\n", title, markdownTable(header, body));
  };
  table("Table 6.1. Dataset properties.", {"dataset", "file format", "file(s) size", "faces", "animated camera", "morph targets"},
        [](const StatsRow& r) {
          const auto& p = r.properties;
          return std::vector<std::string>{p.fileFormat, formatBytes(p.totalBytes), fmt::format("{}", p.faces),
                                          yesNo(p.animatedCamera), yesNo(p.morphTargets)};
        });
  table("Table 6.2. Texture details.", {"dataset", "material count", "texture count", "texture size", "material workflow"},
        [](const StatsRow& r) {
          const auto& p = r.properties;
          std::string workflow = p.materialWorkflow;
          if (p.workflowCounts.size() > 1)
            workflow += fmt::format(" (+{} other)", p.materialCount - p.workflowCounts.at(p.materialWorkflow));
          return std::vector<std::string>{fmt::format("{}", p.materialCount), fmt::format("{}", p.textureCount),
                                          formatBytes(p.textureBytes), workflow};
        });
  table(fmt::format("Table 6.3. Animation details (frames at {} fps).", rows.empty() ? 0.0 : rows[0].properties.fps),
        {"dataset", "animation frames", "static objects", "dynamic rigid objects", "armatures", "static point lights",
         "dynamic point lights"},
        [](const StatsRow& r) {
          const auto& p = r.properties;
          return std::vector<std::string>{fmt::format("{}", p.animationFrames), fmt::format("{}", p.staticObjects),
                                          fmt::format("{}", p.dynamicRigidObjects), fmt::format("{}", p.armatures),
                                          fmt::format("{}", p.staticPointLights), fmt::format("{}", p.dynamicPointLights)};
        });
  auto motionCells = [](const StatsRow& r, const metrics::Summary& s, bool withMax) {
    if (!r.motion.hasCamera) return std::vector<std::string>(withMax ? 3 : 2, "-");
    std::vector<std::string> cells{fixed3(s.mean), fixed3(s.variance)};
    if (withMax) cells.push_back(fixed3(s.max));
    return cells;
  };
  table("Table 6.4. Change in camera position per frame (scene units).", {"dataset", "mean", "variance", "max"},
        [&](const StatsRow& r) { return motionCells(r, r.motion.position, true); });
  table("Table 6.5. Change in camera rotation per frame (degrees, geodesic).", {"dataset", "mean", "variance", "max"},
        [&](const StatsRow& r) { return motionCells(r, r.motion.rotation, true); });
  table("Table 6.6. Change in camera rotation per axis (degrees / frame).",
        {"dataset", "pitch mean", "pitch variance", "yaw mean", "yaw variance", "roll mean", "roll variance"},
        [&](const StatsRow& r) {
          auto cells = motionCells(r, r.motion.pitch, false);
          for (const auto* s : {&r.motion.yaw, &r.motion.roll})
            for (auto& c : motionCells(r, *s, false)) cells.push_back(std::move(c));
          return cells;
        });
  return out;
}

std::string statsJson(const std::vector<StatsRow>& rows, double fps) {
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
      motion["pitch_degrees"] = summaryJson(m.pitch);
      motion["yaw_degrees"] = summaryJson(m.yaw);
      motion["roll_degrees"] = summaryJson(m.roll);
    }
    datasets.push_back({{"name", r.name}, {"path", r.path}, {"properties", properties}, {"camera_motion", motion},
                        {"warnings", p.warnings}});
  }
  nlohmann::json root = {{"tool", "dynbench"}, {"version", kVersion}, {"command", "stats"},
                         {"fps", fps}, {"datasets", datasets}};
  return root.dump(2) + "\n";
}

std::string statsCsv(const std::vector<StatsRow>& rows) {
  std::string out =
      "name,path,file_format,total_bytes,faces,animated_camera,morph_targets,material_count,texture_count,texture_bytes,"
      "material_workflow,animation_frames,static_objects,dynamic_rigid_objects,armatures,static_point_lights,"
      "dynamic_point_lights,camera,position_mean,position_variance,position_max,rotation_mean_deg,rotation_variance_deg,"
      "rotation_max_deg,pitch_mean_deg,pitch_variance_deg,yaw_mean_deg,yaw_variance_deg,roll_mean_deg,roll_variance_deg\n";
  for (const auto& r : rows) {
    const auto& p = r.properties;
    const auto& m = r.motion;
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csvField(r.name), csvField(r.path),
                       csvField(p.fileFormat), p.totalBytes, p.faces, p.animatedCamera ? 1 : 0, p.morphTargets ? 1 : 0,
                       p.materialCount, p.textureCount, p.textureBytes, csvField(p.materialWorkflow), p.animationFrames,
                       p.staticObjects, p.dynamicRigidObjects, p.armatures, p.staticPointLights, p.dynamicPointLights,
                       csvField(m.hasCamera ? m.cameraName : ""));
    if (m.hasCamera) {
      out += fmt::format(",{},{},{},{},{},{},{},{},{},{},{},{}", m.position.mean, m.position.variance, m.position.max,
                         m.rotation.mean, m.rotation.variance, m.rotation.max, m.pitch.mean, m.pitch.variance, m.yaw.mean,
                         m.yaw.variance, m.roll.mean, m.roll.variance);
    } else {
      out += ",,,,,,,,,,,,";
    }
    out += "\n";
  }
  return out;
}

std::string cameraSeriesCsv(const metrics::CameraMotion& motion) {
  std::string out =
      "frame,time_s,x,y,z,yaw_deg,pitch_deg,roll_deg,position_delta,rotation_delta_deg,yaw_delta_deg,pitch_delta_deg,"
      "roll_delta_deg\n";
  for (const auto& f : motion.frames)
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{}\n", f.frame, f.time, f.position.x, f.position.y, f.position.z,
                       f.yawDegrees, f.pitchDegrees, f.rollDegrees, f.positionDelta, f.rotationDelta, f.yawDelta,
                       f.pitchDelta, f.rollDelta);
  return out;
}

}  // namespace dynbench::report
