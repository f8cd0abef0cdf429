#pragma once
// The feature-buffer contract on disk (ARCHITECTURE §3, docs/feature-buffers.md): per frame
// `frame_NNNNN.exr` with the named channels and `frame_NNNNN.json`, the camera sidecar.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "render/camera.h"

namespace dynbench::render {

std::filesystem::path frameImagePath(const std::filesystem::path& dir, long frame);
std::filesystem::path frameSidecarPath(const std::filesystem::path& dir, long frame);

// A matrix as 16 numbers, column-major (glTF's order).
nlohmann::json matrixJson(const glm::dmat4& m);

// The sidecar's JSON: frame, time, resolution, camera matrices (column-major, glTF's order),
// lens and conventions; `render` records the engine and settings that made the frame.
nlohmann::json frameSidecar(long frame, double time, const RenderCamera& camera, const nlohmann::json& render);

// A frame is complete when its image exists and its sidecar (written last) records the same
// `render` settings; anything else is rendered again.
bool frameComplete(const std::filesystem::path& dir, long frame, const nlohmann::json& render);

}  // namespace dynbench::render
