#include "maplight/known_emitters.h"

#include <algorithm>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "core/files.h"

namespace dynbench::maplight {

namespace {

// A winding's axis-aligned bounds: {lowest, highest} corner.
std::pair<glm::dvec3, glm::dvec3> bounds(const std::vector<glm::dvec3>& w) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dvec3& p : w) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

void subdivideInto(const std::vector<glm::dvec3>& w, double size, std::vector<std::vector<glm::dvec3>>& out, bool& split, int depth) {
  const auto [lo, hi] = bounds(w);
  for (int axis = 0; axis < 3 && depth < 24; ++axis) {
    if (hi[axis] - lo[axis] <= size) continue;
    const double mid = 0.5 * (hi[axis] + lo[axis]);
    std::vector<glm::dvec3> front, back;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const glm::dvec3& a = w[i];
      const glm::dvec3& b = w[(i + 1) % w.size()];
      const double da = a[axis] - mid, db = b[axis] - mid;
      if (da >= 0) front.push_back(a);
      if (da <= 0) back.push_back(a);
      if ((da > 0 && db < 0) || (da < 0 && db > 0)) {
        const glm::dvec3 m = a + (b - a) * (da / (da - db));
        front.push_back(m);
        back.push_back(m);
      }
    }
    split = true;
    if (front.size() >= 3) subdivideInto(front, size, out, split, depth + 1);
    if (back.size() >= 3) subdivideInto(back, size, out, split, depth + 1);
    return;
  }
  out.push_back(w);
}

}  // namespace

double polygonArea(const std::vector<glm::dvec3>& w) {
  glm::dvec3 sum(0.0);
  for (std::size_t i = 2; i < w.size(); ++i) sum += glm::cross(w[i - 1] - w[0], w[i] - w[0]);
  return 0.5 * glm::length(sum);
}

std::vector<std::vector<glm::dvec3>> subdivideWinding(const std::vector<glm::dvec3>& winding, double size, bool* split) {
  std::vector<std::vector<glm::dvec3>> pieces;
  bool halved = false;
  subdivideInto(winding, size, pieces, halved, 0);
  if (split) *split = halved;
  return pieces;
}

std::vector<SurfaceEmitter> surfaceEmitters(const Bsp& bsp, const ShaderScripts& scripts, const GameFiles& files) {
  std::vector<SurfaceEmitter> emitters;
  std::map<int, glm::dvec3> colors;
  const BspModel& world = bsp.models[0];
  for (int i = world.firstSurface; i < world.firstSurface + world.surfaceCount; ++i) {
    const BspSurface& s = bsp.surfaces[static_cast<std::size_t>(i)];
    const ShaderLighting* script = scripts.find(bsp.shaders[static_cast<std::size_t>(s.shader)].name);
    if (!script || script->surfaceLight <= 0) continue;
    if (!colors.contains(s.shader)) colors[s.shader] = surfaceLightColor(*script, files);
    const double subdivide = script->lightSubdivide > 0 ? script->lightSubdivide : kDefaultLightSubdivide;
    // q3map2 makes area lights of each triangle (RadLightForTriangles; a patch's quads, here its
    // triangles), as its light stage reads them
    for (const SurfaceTriangle& t : surfaceTriangles(bsp, i)) {
      bool split = false;
      std::vector<std::vector<glm::dvec3>> pieces = subdivideWinding({t.position.begin(), t.position.end()}, subdivide, &split);
      const glm::dvec3 facing = t.normal[0] + t.normal[1] + t.normal[2];  // the side the BSP's normals give it
      if (glm::length(facing) <= 0) continue;
      for (auto& piece : pieces) {
        const double area = polygonArea(piece);
        if (area < 1.0 || area > 20000000.0) continue;  // q3map2's bounds
        const glm::dvec3 cross = glm::cross(piece[1] - piece[0], piece[2] - piece[0]);
        if (glm::length(cross) <= 1e-9) continue;
        SurfaceEmitter e;
        e.normal = glm::normalize(facing);
        const auto [lo, hi] = bounds(piece);
        e.origin = 0.5 * (lo + hi) + e.normal;
        e.winding = std::move(piece);
        e.color = colors[s.shader];
        e.value = script->surfaceLight;
        e.twoSided = script->twoSided;
        if (!split) {
          e.backsplashFraction = script->backsplashFraction;
          e.backsplashDistance = script->backsplashDistance;
        }
        e.shader = s.shader;
        e.shaderName = bsp.shaders[static_cast<std::size_t>(s.shader)].name;
        emitters.push_back(std::move(e));
      }
    }
  }
  return emitters;
}

std::vector<MapLight> entityLights(const Bsp& bsp) {
  std::vector<MapLight> lights;
  for (std::size_t i = 0; i < bsp.entities.size(); ++i) {
    const BspEntity& e = bsp.entities[i];
    const std::string classname = asciiLowercase(entityValue(e, "classname"));
    if (!classname.starts_with("light") || classname.starts_with("lightjunior")) continue;
    if (entityValue(e, "noradiosity") == "1") continue;
    MapLight l;
    l.source = fmt::format("entity {}", i);
    const int spawnflags = std::atoi(entityValue(e, "spawnflags").c_str());
    l.linear = (spawnflags & 1) != 0;
    l.angleAttenuation = (spawnflags & 3) == 0;
    if (l.linear) {
      l.fade = std::atof(entityValue(e, "fade").c_str());
      if (l.fade == 0) l.fade = 1.0;
    }
    l.position = entityVector(e, "origin");
    double intensity = std::atof(entityValue(e, "_light").c_str());
    if (intensity == 0) intensity = std::atof(entityValue(e, "light").c_str());
    if (intensity == 0) intensity = 300.0;
    if (const double scale = std::atof(entityValue(e, "scale").c_str()); scale != 0) intensity *= scale;
    l.value = intensity;
    if (const std::string color = entityValue(e, "_color"); !color.empty()) {
      std::istringstream in(color);
      glm::dvec3 c(0.0);
      in >> c.r >> c.g >> c.b;
      const double peak = std::max({c.r, c.g, c.b});
      l.color = peak > 0 ? c / peak : glm::dvec3(1.0);
    }
    if (const std::string target = entityValue(e, "target"); !target.empty()) {
      const auto found = std::find_if(bsp.entities.begin(), bsp.entities.end(), [&](const BspEntity& o) { return entityValue(o, "targetname") == target; });
      if (found != bsp.entities.end()) {
        glm::dvec3 axis = entityVector(*found, "origin") - l.position;
        double dist = glm::length(axis);
        axis = dist > 0 ? axis / dist : glm::dvec3(0, 0, -1);
        double radius = std::atof(entityValue(e, "radius").c_str());
        if (radius == 0) radius = 64.0;
        if (dist == 0) dist = 64.0;
        if (entityValue(e, "_sun") == "1") {
          l.kind = MapLightKind::kSun;
          l.towardsSun = -axis;
          l.color = glm::length(l.color) > 0 ? glm::normalize(l.color) : l.color;
        } else {
          l.kind = MapLightKind::kSpot;
          l.spotAxis = axis;
          l.spotRadiusByDist = (radius + 16.0) / dist;
          l.linear = false;  // spots: inverse square with angle attenuation always
          l.angleAttenuation = true;
          l.fade = 1.0;
        }
      }
    }
    lights.push_back(l);
  }
  return lights;
}

std::vector<EmitterGroup> knownEmitters(const Bsp& bsp, const ShaderScripts& scripts, const GameFiles& files, bool hideEntityLights,
                                        MapLighting& lighting) {
  std::vector<EmitterGroup> groups;
  if (!hideEntityLights) lighting.lights = entityLights(bsp);
  lighting.report.entityLights = lighting.lights.size();
  for (std::size_t i = 0; i < lighting.lights.size(); ++i) groups.push_back({lighting.lights[i].source, lighting.lights[i].color, {i}, {}});
  std::set<int> usedShaders;
  for (const BspSurface& s : bsp.surfaces) usedShaders.insert(s.shader);
  for (int shader : usedShaders) {
    const ShaderLighting* script = scripts.find(bsp.shaders[static_cast<std::size_t>(shader)].name);
    if (!script) continue;
    lighting.report.skyLightShaders += script->skyLight > 0;
    for (const ShaderSun& sun : script->suns) {
      MapLight l;
      l.kind = MapLightKind::kSun;
      l.color = sun.color;
      l.value = sun.intensity;
      l.towardsSun = sun.towardsSun;
      l.source = "sun of " + script->name;
      groups.push_back({l.source, l.color, {lighting.lights.size()}, {}});
      lighting.lights.push_back(l);
      ++lighting.report.suns;
    }
  }
  lighting.surfaceLights = surfaceEmitters(bsp, scripts, files);
  lighting.report.surfaceEmitters = lighting.surfaceLights.size();
  {
    std::map<std::pair<int, EmitterSide>, std::size_t> byShader;
    for (std::size_t i = 0; i < lighting.surfaceLights.size(); ++i) {
      const SurfaceEmitter& e = lighting.surfaceLights[i];
      for (const EmitterSide side : e.twoSided ? std::vector{EmitterSide::kFront, EmitterSide::kBack} : std::vector{EmitterSide::kBoth}) {
        auto [it, fresh] = byShader.emplace(std::pair{e.shader, side}, groups.size());
        if (fresh) {
          groups.push_back({"surface light " + e.shaderName + (side == EmitterSide::kBack ? " (its back)" : ""), e.color, {}, {}, side});
          if (side == EmitterSide::kBack) groups[byShader.at({e.shader, EmitterSide::kFront})].backGroup = it->second;
        }
        groups[it->second].surfaces.push_back(i);
      }
    }
  }
  return groups;
}

}  // namespace dynbench::maplight
