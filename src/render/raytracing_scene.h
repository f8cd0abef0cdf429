#pragma once
// The scene as Embree 3 sees it (src/render/raytracing_scene.cpp is the only file that includes
// Embree). Two levels, as the thesis's StaticObjects / DynamicObjects split intends: geometry that
// never moves is built into one BVH once; animated, skinned and morphing geometry is rebuilt into a
// second BVH for each frame; a top-level scene instances both.
#include <array>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "core/error.h"
#include "render/camera.h"
#include "scene/pose.h"

namespace dynbench::render {

struct SurfaceHit {
  bool hit = false;
  double distance = 0.0;
  glm::dvec3 position{0.0};        // world, interpolated from the triangle's vertices
  glm::dvec3 geometricNormal{0.0};  // unit, facing as the triangle winds (counter-clockwise front)
  glm::dvec3 shadingNormal{0.0};    // unit, interpolated vertex normals (geometric when none)
  glm::dvec2 barycentric{0.0};      // (u, v) of Embree: p = (1 - u - v) p0 + u p1 + v p2
  int node = -1;
  int primitive = -1;
  // scene.meshes[scene.nodes[node].mesh].primitives[primitive], resolved once per hit: the
  // shading reads its texture coordinates and material several times.
  const scene::Primitive* source = nullptr;
  unsigned triangle = 0;
  std::array<std::uint32_t, 3> vertices{};  // the triangle's vertex indices in its primitive
  bool dynamicGeometry = false;  // which Embree geometry it was (for previousPosition)
  unsigned geometry = 0;
};

// Decides whether a hit on an alpha-masked surface counts (glTF alphaMode MASK). Called by Embree's
// filter functions, from any thread; installed only on primitives for which `needed` says so.
struct AlphaTest {
  std::function<bool(int node, int primitive)> needed;
  std::function<bool(int node, int primitive, unsigned triangle, glm::dvec2 barycentric)> opaque;
};

// One triangle primitive of a mesh node as it is at the last update (world space).
struct PrimitiveView {
  int node = -1, primitive = -1;
  const std::vector<glm::dvec3>* positions = nullptr;
  const std::vector<std::uint32_t>* indices = nullptr;
};

struct RayTracingStats {
  std::size_t staticTriangles = 0, dynamicTriangles = 0;
};

class RayTracingScene {
 public:
  // Embree's kernels compute reciprocals from RCPPS/RCP14 estimates, whose bits differ between
  // Intel and AMD: the same kernels give the same hits only on one vendor's CPUs (a hit at a grazing
  // edge can differ). maplight's fit, which must be the same everywhere, traces its own hierarchy.
  static Expected<std::unique_ptr<RayTracingScene>> create(const scene::Scene& scene, AlphaTest alphaTest = {});
  ~RayTracingScene();

  // Refits the dynamic part to time t (node transforms, skinning, morph targets, visibility). The
  // positions of the update before are kept for previousPosition().
  // Errors from Embree (device errors after the refit and commits) come back as kExternalTool.
  [[nodiscard]] Expected<void> update(double t);
  // Where the surface point of `hit` was at the previous update: the same barycentric point of the
  // same triangle, moved with its node, skin and morph targets (the hit position itself for static
  // geometry, and for geometry that was hidden then).
  glm::dvec3 previousPosition(const SurfaceHit& hit) const;
  // Every visible triangle primitive, static and dynamic, as of the last update.
  void forEachPrimitive(const std::function<void(const PrimitiveView&)>& visit) const;
  const scene::ScenePose& pose() const;
  // The world positions of the hit's triangle at the last update (tangent frames for normal maps).
  std::array<glm::dvec3, 3> trianglePositions(const SurfaceHit& hit) const;  // every node at the last update's time
  SurfaceHit intersect(const Ray& ray, double tMin = 0.0, double tMax = 1e30) const;
  // The surface point `other` names (the same barycentric point of the same triangle of the same
  // node and primitive), as this scene has it at its last update: position and normals moved with
  // its node, skin and morph targets; `distance` copied. No hit where that geometry is hidden now.
  // `other` may come from another RayTracingScene of the same scene::Scene (their geometries are
  // created in the same order): how a radiance-change pair rebuilds frame t's first hit in frame
  // t - 1 (PathTracer::renderChanges).
  SurfaceHit surfaceAt(const SurfaceHit& other) const;
  // Many rays at once, through Embree's stream API: hits[k] is intersect(rays[k]).
  void intersect(std::span<const Ray> rays, std::span<SurfaceHit> hits) const;
  bool occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMax) const;
  RayTracingStats stats() const;

  struct Impl;

 private:
  explicit RayTracingScene(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// A bounding volume hierarchy over spheres (Embree's BVH over user primitives, searched with
// rtcPointQuery): which spheres contain a point. The lights' spheres of influence use it so that
// the cost of direct light follows the lights that can reach a point, not every light of the frame.
class SphereIndex {
 public:
  SphereIndex();
  ~SphereIndex();
  SphereIndex(const SphereIndex&) = delete;
  SphereIndex& operator=(const SphereIndex&) = delete;

  // Rebuilds the hierarchy over these spheres (xyz centre, w radius > 0 and finite).
  [[nodiscard]] Expected<void> build(const std::vector<glm::dvec4>& spheres);
  // Appends to `found` (cleared first) the index of every sphere containing p, exactly
  // (|p - centre| < radius; the hierarchy's float boxes only prune).
  void query(const glm::dvec3& p, std::vector<std::uint32_t>& found) const;
  std::size_t size() const { return spheres_.size(); }

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
  std::vector<glm::dvec4> spheres_;
};

// The scene's static geometry alone (nodes no animation moves; players and projectiles are left
// out), built once and asked about many camera paths: which segments points[k] -> points[k+1] pass
// through it (the check that a camera never goes through a wall). Alpha-masked surfaces block where
// they are opaque.
class StaticGeometry {
 public:
  static Expected<StaticGeometry> create(const scene::Scene& scene);
  std::vector<std::size_t> segmentsThrough(const std::vector<glm::dvec3>& points) const;
  // The first static surface from `origin` along the unit `direction` within tMax: its distance
  // (infinity when none) and its unit geometric normal; how far a camera can move that way before
  // it enters a wall.
  struct Obstacle {
    double distance = 0;
    glm::dvec3 normal{0.0};
  };
  Obstacle firstObstacle(const glm::dvec3& origin, const glm::dvec3& direction, double tMax) const;

 private:
  explicit StaticGeometry(std::unique_ptr<RayTracingScene> tracer) : tracer_(std::move(tracer)) {}
  std::unique_ptr<RayTracingScene> tracer_;
};

// StaticGeometry::create, then segmentsThrough: for a single path.
Expected<std::vector<std::size_t>> segmentsThroughStaticGeometry(const scene::Scene& scene, const std::vector<glm::dvec3>& points);

}  // namespace dynbench::render
