#pragma once
// The scene as Embree 3 sees it (src/render/raytracing_scene.cpp is the only file that includes
// Embree). Two levels, as the thesis's StaticObjects / DynamicObjects split intends: geometry that
// never moves is built into one BVH once; animated, skinned and morphing geometry is rebuilt into a
// second BVH for each frame; a top-level scene instances both.
#include <memory>
#include <vector>

#include "core/error.h"
#include "render/camera.h"
#include "scene/evaluate.h"

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
  unsigned triangle = 0;
};

struct RayTracingStats {
  std::size_t staticTriangles = 0, dynamicTriangles = 0;
};

class RayTracingScene {
 public:
  static Expected<std::unique_ptr<RayTracingScene>> create(const scene::Scene& scene);
  ~RayTracingScene();

  // Rebuilds the dynamic part for time t (node transforms, skinning, morph targets, visibility).
  void update(double t);
  SurfaceHit intersect(const Ray& ray, double tMin = 0.0, double tMax = 1e30) const;
  bool occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMax) const;
  RayTracingStats stats() const;

  struct Impl;

 private:
  explicit RayTracingScene(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynbench::render
