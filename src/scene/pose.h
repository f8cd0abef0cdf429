#pragma once
// The pose of a scene at any time t (scene::Evaluator): animation sampling (glTF 2.0 Appendix C), local and world
// transforms, morph weights and visibility. All animations play together on one clock; when two
// channels drive the same node property, the one listed later wins.
#include <span>
#include <vector>

#include "scene/scene.h"

namespace dynbench::scene {

// Samples `sampler` at time t into out (sampler.components values). Before the first key the first
// value holds, after the last key the last one (glTF: clamp). LINEAR rotations are not handled here
// (see sampleRotation); everything else interpolates componentwise.
void sampleValues(const Sampler& sampler, double t, std::span<double> out);

// Rotation keys: LINEAR uses spherical linear interpolation on the shortest arc, STEP holds,
// CUBICSPLINE is the Hermite spline of the quaternion components, normalised (glTF Appendix C).
glm::dquat sampleRotation(const Sampler& sampler, double t);

struct ScenePose {
  std::vector<glm::dmat4> world;  // world matrix of every node
  std::vector<char> visible;      // 1 when the node is shown (see Evaluator::visible)
  std::vector<Light> lights;      // every light of Scene::lights, colour and intensity animated
};

class Evaluator {
 public:
  explicit Evaluator(const Scene& scene);

  glm::dmat4 localMatrix(int node, double t) const;
  Transform localTransform(int node, double t) const;  // nodes with a static matrix: decomposed
  // World matrix of one node, walking only its ancestors (cheap for a camera).
  glm::dmat4 worldMatrix(int node, double t) const;
  // The node's own KHR_node_visibility value at t.
  bool ownVisibility(int node, double t) const;
  // Shown at t: neither the node nor an ancestor is switched off by KHR_node_visibility, and its
  // world scale is not zero on any axis.
  bool visible(int node, double t) const;
  std::vector<double> morphWeights(int node, double t) const;
  // Scene::lights[light] with its KHR_animation_pointer colour and intensity at t.
  Light light(int light, double t) const;
  // Every node at once, parents before children.
  void evaluate(double t, ScenePose& pose) const;

  // World-space vertex positions of one primitive of a mesh node at t: morph targets, then either
  // linear blend skinning (thesis §2.2: p' = sum_i w_i B_i M_i^-1 p, with B_i the joint's world
  // matrix and M_i^-1 its inverse bind matrix; the node's own transform is ignored, as glTF says)
  // or the node's world matrix.
  std::vector<glm::dvec3> worldPositions(int node, std::size_t primitive, double t) const;
  // Positions and (unit) normals together; normals go through the same morph and skinning, with
  // the inverse transpose of each blended matrix. `normals` is empty when the mesh has none.
  void worldGeometry(int node, std::size_t primitive, double t, std::vector<glm::dvec3>& positions,
                     std::vector<glm::dvec3>& normals) const;
  // The same from a pose evaluate() computed for time t: every world matrix is looked up, not
  // recomputed (a renderer evaluates the pose once per frame).
  void worldGeometry(int node, std::size_t primitive, double t, const ScenePose& pose, std::vector<glm::dvec3>& positions,
                     std::vector<glm::dvec3>& normals) const;

  const Scene& scene() const { return scene_; }

 private:
  struct Drivers {
    const Sampler* translation = nullptr;
    const Sampler* rotation = nullptr;
    const Sampler* scale = nullptr;
    const Sampler* weights = nullptr;
    const Sampler* visibility = nullptr;
  };
  struct LightDrivers {
    const Sampler* color = nullptr;
    const Sampler* intensity = nullptr;
    const Sampler* range = nullptr;
  };
  const Scene& scene_;
  std::vector<Drivers> drivers_;
  std::vector<LightDrivers> lightDrivers_;
  std::vector<int> order_;  // nodes in parent-before-child order
};

// True when a world matrix scales some axis to (numerically) zero: the scale-0 visibility fallback.
bool hasZeroScale(const glm::dmat4& world);

}  // namespace dynbench::scene
