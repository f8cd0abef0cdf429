#pragma once
// `--engine cycles`: the thesis's own renderer (Blender Cycles, §6.3) as a second backend. dynbench
// evaluates every frame's camera and punctual lights itself, hands them to Blender with
// tools/blender/render_cycles.py, and turns Cycles' passes into the feature-buffer contract:
//   P, N      Position and Normal passes (Blender's Z-up world turned back to glTF's Y-up)
//   direct    DiffCol x DiffDir + GlossCol x GlossDir + TransCol x TransDir + Emit + Env
//   indirect  DiffCol x DiffInd + GlossCol x GlossInd + TransCol x TransInd
//   albedo    DiffCol;  Z from P and the camera;  hit where Cycles' depth is finite
// Cycles frames carry no id, motion or variance channels (docs/feature-buffers.md).
#include <filesystem>
#include <vector>

#include "core/error.h"
#include "core/image_io.h"
#include "frames/feature_frame.h"
#include "render/render_job.h"

namespace dynbench::render {

// Finds the Blender executable: a path, or a name looked up on PATH.
Expected<std::filesystem::path> findBlender(const std::string& blender);

// The backend itself: createCyclesBackend (render/backend.h).

// One Cycles multilayer EXR (Blender's pass names) to the contract's channels: the radiance from
// `passes`, the geometry (P, N, Z, hit, albedo) from `geometryPasses` when given (a render of the
// same frame at the pixel centres, when the radiance went through a pixel filter), else from `passes`.
Expected<frames::FeatureFrame> cyclesPassesToContract(const FloatImage& passes, const std::filesystem::path& source, const RenderCamera& camera,
                                                      const FloatImage* geometryPasses = nullptr);

}  // namespace dynbench::render
