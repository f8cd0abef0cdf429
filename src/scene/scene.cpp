#include "scene/scene.h"

#include <algorithm>
#include <limits>

namespace dynbench::scene {

std::uint64_t SceneSource::totalBytes() const {
  std::uint64_t total = 0;
  for (const auto& f : files) total += f.bytes;
  return total;
}

std::size_t Mesh::triangleCount() const {
  std::size_t n = 0;
  for (const auto& p : primitives) n += p.triangleCount();
  return n;
}

std::size_t Mesh::morphTargetCount() const {
  std::size_t n = 0;
  for (const auto& p : primitives) n = std::max(n, p.targets.size());
  return n;
}

const char* toString(MaterialWorkflow workflow) {
  switch (workflow) {
    case MaterialWorkflow::kMetallicRoughness: return "PBR metallic-roughness";
    case MaterialWorkflow::kSpecularGlossiness: return "PBR specular-glossiness";
    case MaterialWorkflow::kPhongOrOther: return "Phong/other";
  }
  return "?";
}

const char* toString(Light::Type type) {
  switch (type) {
    case Light::Type::kPoint: return "point";
    case Light::Type::kSpot: return "spot";
    case Light::Type::kDirectional: return "directional";
  }
  return "?";
}

const char* toString(Interpolation interpolation) {
  switch (interpolation) {
    case Interpolation::kStep: return "STEP";
    case Interpolation::kLinear: return "LINEAR";
    case Interpolation::kCubicSpline: return "CUBICSPLINE";
  }
  return "?";
}

const char* toString(AnimationPath path) {
  switch (path) {
    case AnimationPath::kTranslation: return "translation";
    case AnimationPath::kRotation: return "rotation";
    case AnimationPath::kScale: return "scale";
    case AnimationPath::kWeights: return "weights";
    case AnimationPath::kVisibility: return "visibility";
    case AnimationPath::kLightColor: return "light color";
    case AnimationPath::kLightIntensity: return "light intensity";
    case AnimationPath::kLightRange: return "light range";
  }
  return "?";
}

glm::dmat4 Transform::matrix() const {
  // glTF §3.5.3: M = T * R * S.
  glm::dmat4 m = glm::mat4_cast(rotation);
  m[0] *= scale.x;
  m[1] *= scale.y;
  m[2] *= scale.z;
  m[3] = glm::dvec4(translation, 1.0);
  return m;
}

Scene::TimeRange Scene::timeRange() const {
  double start = std::numeric_limits<double>::infinity();
  double end = -std::numeric_limits<double>::infinity();
  for (const auto& animation : animations) {
    for (const auto& channel : animation.channels) {
      const auto& times = animation.samplers[static_cast<std::size_t>(channel.sampler)].times;
      if (times.empty()) continue;
      start = std::min(start, static_cast<double>(times.front()));
      end = std::max(end, static_cast<double>(times.back()));
    }
  }
  if (start > end) return {};
  return {start, end};
}

bool keepOnlyAnimation(Scene& scene, const std::string& selector) {
  for (std::size_t i = 0; i < scene.animations.size(); ++i) {
    if (scene.animations[i].name == selector || std::to_string(i) == selector) {
      Animation kept = std::move(scene.animations[i]);
      scene.animations.clear();
      scene.animations.push_back(std::move(kept));
      return true;
    }
  }
  return false;
}

}  // namespace dynbench::scene
