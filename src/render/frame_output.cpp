#include "render/frame_output.h"

#include <fmt/format.h>

#include "core/files.h"

namespace dynbench::render {
nlohmann::json matrixJson(const glm::dmat4& m) {
  nlohmann::json a = nlohmann::json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);
  return a;
}

std::filesystem::path frameImagePath(const std::filesystem::path& dir, long frame) {
  return dir / fmt::format("frame_{:05d}.exr", frame);
}
std::filesystem::path frameSidecarPath(const std::filesystem::path& dir, long frame) {
  return dir / fmt::format("frame_{:05d}.json", frame);
}

nlohmann::json frameSidecar(long frame, double time, const RenderCamera& camera, const nlohmann::json& render) {
  nlohmann::json j;
  j["format"] = "dynbench-frame";
  j["version"] = 1;
  j["frame"] = frame;
  j["time"] = time;
  j["width"] = camera.width();
  j["height"] = camera.height();
  j["camera"] = {
      {"world", matrixJson(camera.world())},
      {"view", matrixJson(camera.view())},
      {"projection", matrixJson(camera.projection())},
      {"position", {camera.position().x, camera.position().y, camera.position().z}},
      {"yfov", camera.yfov()},
      {"aspect", static_cast<double>(camera.width()) / camera.height()},
      {"znear", camera.znear()},
      {"zfar", camera.zfar()},
  };
  j["conventions"] = {
      {"matrices", "column-major, 16 numbers (glTF order); clip = projection * view * world_point"},
      {"view_space", "right-handed, camera looks down -Z, +Y up (glTF / OpenGL)"},
      {"clip_space", "OpenGL: NDC x, y, z in [-1, 1], depth -1 at znear"},
      {"pixels", "pixel (x, y) covers [x, x+1) x [y, y+1), row 0 at the top; x = (ndc.x + 1) / 2 * width, "
                 "y = (1 - ndc.y) / 2 * height"},
      {"motion", "previous-frame pixel position minus this pixel's centre, in pixels"},
      {"units", "lengths in the dataset's units; radiance in the dataset's photometric units (cd/m2)"},
  };
  j["render"] = render;
  return j;
}

bool frameComplete(const std::filesystem::path& dir, long frame, const nlohmann::json& render) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(frameImagePath(dir, frame), ec)) return false;
  auto text = readWholeFile(frameSidecarPath(dir, frame));
  if (!text) return false;
  const auto j = nlohmann::json::parse(*text, nullptr, false);
  return !j.is_discarded() && j.is_object() && j.contains("render") && j["render"] == render;
}

}  // namespace dynbench::render
