#pragma once
// The light fit's first tool: the map's geometry as q3map2's light traces see it, traced by the
// fit's own hierarchy (maplight/triangle_bvh.h says why not Embree). Internal to maplight.
#include <glm/glm.hpp>

#include "maplight/bsp.h"
#include "maplight/shaders.h"
#include "maplight/triangle_bvh.h"

namespace dynbench::maplight {

// Units a visibility trace leaves out at either end: its ends lie on surfaces (a texel nudged onto
// another face, an emitter's own face), which rounding would otherwise put in front of or behind
// them (Embree's tnear = 0 and float rounding did the same at the near end).
constexpr double kTraceMargin = 1e-3;

// The map's geometry as the fit's traces see it (maplight/triangle_bvh.h: why not Embree): `all`
// holds the solid surfaces (group 0) and the sky's (group 1); `solid` the solid ones alone, as
// q3map2's light traces see the map (light_trace.c ignores sky surfaces: light passes through them).
struct Occluders {
  TriangleBvh all, solid;
  // Surfaces nearer `from` than `inhibit` are passed through (q3map2's inhibitRadius: a grid
  // point's traces ignore what lies within half a grid step of it).
  bool visible(const glm::dvec3& from, const glm::dvec3& to, double inhibit = 0.0) const {
    std::uint32_t noCache = TriangleBvh::kNoBlocker;
    return visible(from, to, inhibit, noCache);
  }
  // The same with a shadow cache (TriangleBvh::occluded): for the rays of one light, in order.
  bool visible(const glm::dvec3& from, const glm::dvec3& to, double inhibit, std::uint32_t& lastBlocker) const {
    const glm::dvec3 d = to - from;
    const double length = glm::length(d);
    if (length <= inhibit + 1e-6) return true;
    return !solid.occluded(from + inhibit * (d / length), d / length, kTraceMargin, length - inhibit - kTraceMargin, lastBlocker);
  }
  // Whether a ray from `from` towards `direction` reaches the sky (or leaves the map).
  bool seesSky(const glm::dvec3& from, const glm::dvec3& direction, double inhibit = 0.0) const {
    const BvhHit hit = all.intersect(from + inhibit * direction, direction, kTraceMargin);
    return !hit.hit || hit.group == 1;
  }
};

// Whether a surface is drawn (`sky` says whether it is the sky's): flares, nodraw and translucent
// surfaces are not, except a translucent sky.
bool drawn(const Bsp& bsp, const ShaderScripts& scripts, const BspSurface& s, bool& sky);
Occluders buildOccluders(const Bsp& bsp, const ShaderScripts& scripts);

}  // namespace dynbench::maplight
