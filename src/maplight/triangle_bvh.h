#pragma once
// The map's surfaces for the light fit's visibility tests: a bounding volume hierarchy over its
// triangles, traced in double precision with IEEE operations alone.
//
// Why not Embree (render/raytracing_scene.h) here: the fit must be a property of the map, the same
// lights on every machine, and a greedy fit turns one visibility test that differs at a grazing
// edge into another set of lights. Embree's kernels compute reciprocals from RCPPS/RCP14 estimates
// refined by a Newton step, whose last bits differ between Intel and AMD CPUs: fit version 7 gave
// oa_dm1 other lights on an AMD EPYC than on an Intel Xeon (held out 0.934 against 0.935, so v2's
// OpenArena pins failed there; 2026-11-28). Every operation below is an IEEE addition,
// multiplication, division or comparison (no estimates, no FMA contraction without an FMA target),
// so the same build gives the same bits on every x86-64 CPU; the build is deterministic too
// (ties broken by triangle index).
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

namespace dynbench::maplight {

struct BvhTriangle {
  std::array<glm::dvec3, 3> position;
  std::array<glm::dvec3, 3> normal;  // vertex normals: the shading normal interpolates them
  int group = 0;                     // what the caller tells apart (the sky from solid surfaces)
};

struct BvhHit {
  bool hit = false;
  double distance = 0.0;            // along the ray's direction, in its units
  int group = -1;
  glm::dvec3 shadingNormal{0.0};    // unit: the vertex normals interpolated (the face's where they vanish)
};

class TriangleBvh {
 public:
  explicit TriangleBvh(std::vector<BvhTriangle> triangles);

  // Whether some triangle (either side) crosses the ray at a distance in [tMin, tMax]. A tMin above
  // 0 keeps a ray that starts on a surface (within rounding) from being blocked by it.
  bool occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax) const;
  // The same, trying first the triangle that blocked the caller's previous ray (`lastBlocker`,
  // kNoBlocker at first; set to this ray's blocker when it is blocked): a shadow cache for rays
  // that run side by side, as a candidate light's rays to neighbouring texels do. The answer is
  // the same bits as without it (any crossing triangle blocks, and the triangle test is the one
  // the traversal runs); only the work differs.
  static constexpr std::uint32_t kNoBlocker = 0xffffffffu;
  bool occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, std::uint32_t& lastBlocker) const;
  // occluded() as it was before its two-lane traversal, one node's box at a time: the same answer
  // for every ray (tests compare the two).
  bool occludedOneBoxAtATime(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax) const;
  // The nearest triangle the ray crosses at a distance of at least tMin; of two at the same
  // distance (within 1e-9 relative), the one whose shading normal faces the ray.
  BvhHit intersect(const glm::dvec3& origin, const glm::dvec3& direction, double tMin) const;

  std::size_t triangleCount() const { return triangles_.size(); }

 private:
  struct Node {
    glm::dvec3 lo{0.0}, hi{0.0};
    std::uint32_t first = 0;  // a leaf's first triangle; an inner node's second child (the first follows it)
    std::uint32_t count = 0;  // triangles in a leaf, 0 for an inner node
    std::uint8_t axis = 0;    // an inner node's split axis (which child a ray meets first)
  };
  // Möller-Trumbore with the edges stored: e1 = p1 - p0, e2 = p2 - p0.
  struct Prepared {
    glm::dvec3 p0, e1, e2;
  };
  std::uint32_t build(std::vector<std::uint32_t>& order, std::size_t begin, std::size_t end, const std::vector<glm::dvec3>& centroids,
                      const std::vector<BvhTriangle>& triangles, std::size_t depth);
  // Whether the ray crosses prepared triangle k at a distance in [tMin, tMax] (Möller-Trumbore),
  // with the crossing's barycentrics and distance.
  bool crosses(std::uint32_t k, const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, double& u, double& v,
               double& t) const;
  glm::dvec3 shadingNormal(std::uint32_t triangle, double u, double v) const;
  bool facesRay(std::uint32_t triangle, double u, double v, const glm::dvec3& direction) const;
  // Whether any triangle crosses the ray in [tMin, tMax], with one that does. A node's two
  // children's boxes are tested at once in two SSE2 lanes, each lane the slab test trace() makes
  // operation for operation, so the same boxes are culled and the answer is trace<true>'s; only the
  // order in which leaves are visited (and so which blocker is reported) may differ.
  bool anyHit(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, std::uint32_t& triangle) const;
  template <bool kAnyHit>
  bool trace(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, double tMax, double& distance, std::uint32_t& triangle,
             double& u, double& v) const;

  std::vector<BvhTriangle> triangles_;  // in the hierarchy's leaf order
  std::vector<Prepared> prepared_;
  std::vector<Node> nodes_;
};

}  // namespace dynbench::maplight
