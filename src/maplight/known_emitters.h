#pragma once
// The light fit's step 2a (maplight/fit.h): the emitters the BSP still names, as q3map2 reads them:
// its light entities (spots aimed, suns made directional), its sky shaders' suns, and its
// light-emitting shaders' surfaces cut into q3map2's area lights; grouped so that the fit confirms
// each group's strength with one weight. Internal to maplight.
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "maplight/bsp.h"
#include "maplight/fit.h"
#include "maplight/pak.h"
#include "maplight/shaders.h"

namespace dynbench::maplight {

// A group of known emitters whose strength the fit confirms with one weight: one light entity, one
// sun, or every piece of one shader's surface light. Its colour is shared.
// A two-sided surface light's back is a group of its own: q3map2 lights both sides of a `cull none`
// shader's surfaces (LIGHT_TWOSIDED) since some version, and the stock maps were compiled by
// several; the lightmaps then say with the back's weight whether that map's compile did.
enum class EmitterSide { kBoth, kFront, kBack };
struct EmitterGroup {
  std::string name;
  glm::dvec3 color{1.0};
  std::vector<std::size_t> lights;    // indices into MapLighting::lights
  std::vector<std::size_t> surfaces;  // indices into MapLighting::surfaceLights
  EmitterSide side = EmitterSide::kBoth;  // the surfaces' light from which side
  std::size_t backGroup = 0;              // a kFront group's kBack partner (same surfaces)
};

// The known emitters in groups: each light entity (none with `hideEntityLights`), each sun, each
// surface-light shader (a two-sided one's back a group of its own). Their lights and surface
// emitters go into `lighting`, their counts into its report.
std::vector<EmitterGroup> knownEmitters(const Bsp& bsp, const ShaderScripts& scripts, const GameFiles& files, bool hideEntityLights,
                                        MapLighting& lighting);

// Every light-emitting shader's world surfaces as q3map2's area lights (RadLightForTriangles,
// RadSubdivideDiffuseLight).
std::vector<SurfaceEmitter> surfaceEmitters(const Bsp& bsp, const ShaderScripts& scripts, const GameFiles& files);

// A polygon's area, square units.
double polygonArea(const std::vector<glm::dvec3>& w);

}  // namespace dynbench::maplight
