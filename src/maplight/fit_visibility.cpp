#include "maplight/fit_visibility.h"

namespace dynbench::maplight {

bool drawn(const Bsp& bsp, const ShaderScripts& scripts, const BspSurface& s, bool& sky) {
  if (s.type == BspSurfaceType::kBad || s.type == BspSurfaceType::kFlare) return false;
  const BspShader& shader = bsp.shaders[static_cast<std::size_t>(s.shader)];
  const ShaderLighting* script = scripts.find(shader.name);
  sky = (shader.surfaceFlags & kSurfaceSky) != 0 || (script && script->sky);
  if ((shader.surfaceFlags & kSurfaceNoDraw) != 0 || (script && script->noDraw)) return false;
  return !(script && script->translucent) || sky;
}

Occluders buildOccluders(const Bsp& bsp, const ShaderScripts& scripts) {
  std::vector<BvhTriangle> all, solid;
  const BspModel& world = bsp.models[0];
  for (int i = world.firstSurface; i < world.firstSurface + world.surfaceCount; ++i) {
    bool sky = false;
    if (!drawn(bsp, scripts, bsp.surfaces[static_cast<std::size_t>(i)], sky)) continue;
    for (const SurfaceTriangle& t : surfaceTriangles(bsp, i)) {
      const BvhTriangle triangle{t.position, t.normal, sky ? 1 : 0};
      all.push_back(triangle);
      if (!sky) solid.push_back(triangle);
    }
  }
  return Occluders{TriangleBvh(std::move(all)), TriangleBvh(std::move(solid))};
}

}  // namespace dynbench::maplight
