#include "scene/pose.h"

#include <algorithm>
#include <cmath>

namespace dynbench::scene {
namespace {

// Index k of the segment [times[k], times[k+1]) holding t, and the segment parameter s in [0, 1].
// Returns false when t is outside the keys (the caller clamps).
struct Segment {
  std::size_t k = 0;
  double s = 0.0;
  double dt = 0.0;
};

enum class Clamp { kBefore, kInside, kAfter };

// Key times are floats (glTF stores them so). The sample time is compared in float too: a frame at
// t = k / fps computed in double then lands exactly on a key written as the float nearest k / fps,
// instead of just before it, which would make STEP keys one frame late.
Clamp locate(const std::vector<float>& times, double t, Segment& seg) {
  const auto tf = static_cast<float>(t);
  if (tf <= times.front()) return Clamp::kBefore;
  if (tf >= times.back()) return Clamp::kAfter;
  const auto it = std::upper_bound(times.begin(), times.end(), tf);
  seg.k = static_cast<std::size_t>(it - times.begin()) - 1;
  seg.dt = static_cast<double>(times[seg.k + 1]) - times[seg.k];
  seg.s = std::clamp((t - times[seg.k]) / seg.dt, 0.0, 1.0);
  return Clamp::kInside;
}

// Value (not tangent) of key k, component c.
double keyValue(const Sampler& sampler, std::size_t k, int c) {
  const std::size_t n = static_cast<std::size_t>(sampler.components);
  if (sampler.interpolation == Interpolation::kCubicSpline) return sampler.values[(3 * k + 1) * n + static_cast<std::size_t>(c)];
  return sampler.values[k * n + static_cast<std::size_t>(c)];
}

glm::dquat keyQuat(const Sampler& sampler, std::size_t k) {
  // glTF stores (x, y, z, w); glm constructs (w, x, y, z).
  return glm::dquat(keyValue(sampler, k, 3), keyValue(sampler, k, 0), keyValue(sampler, k, 1), keyValue(sampler, k, 2));
}

}  // namespace

void sampleValues(const Sampler& sampler, double t, std::span<double> out) {
  const int n = sampler.components;
  Segment seg;
  const Clamp where = locate(sampler.times, t, seg);
  if (where != Clamp::kInside) {
    const std::size_t k = where == Clamp::kBefore ? 0 : sampler.times.size() - 1;
    for (int c = 0; c < n; ++c) out[static_cast<std::size_t>(c)] = keyValue(sampler, k, c);
    return;
  }
  const std::size_t k = seg.k;
  const double s = seg.s;
  switch (sampler.interpolation) {
    case Interpolation::kStep:
      for (int c = 0; c < n; ++c) out[static_cast<std::size_t>(c)] = keyValue(sampler, k, c);
      break;
    case Interpolation::kLinear:
      for (int c = 0; c < n; ++c)
        out[static_cast<std::size_t>(c)] = (1.0 - s) * keyValue(sampler, k, c) + s * keyValue(sampler, k + 1, c);
      break;
    case Interpolation::kCubicSpline: {
      // glTF Appendix C: p(s) = (2s^3 - 3s^2 + 1) v_k + td (s^3 - 2s^2 + s) b_k
      //                        + (-2s^3 + 3s^2) v_{k+1} + td (s^3 - s^2) a_{k+1},
      // with a = in-tangent, v = value, b = out-tangent, td = t_{k+1} - t_k.
      const std::size_t w = static_cast<std::size_t>(n);
      const double s2 = s * s, s3 = s2 * s;
      const double hv0 = 2 * s3 - 3 * s2 + 1, hb0 = s3 - 2 * s2 + s, hv1 = -2 * s3 + 3 * s2, ha1 = s3 - s2;
      for (std::size_t c = 0; c < w; ++c) {
        const double v0 = sampler.values[(3 * k + 1) * w + c];
        const double b0 = sampler.values[(3 * k + 2) * w + c];
        const double a1 = sampler.values[(3 * (k + 1) + 0) * w + c];
        const double v1 = sampler.values[(3 * (k + 1) + 1) * w + c];
        out[c] = hv0 * v0 + seg.dt * hb0 * b0 + hv1 * v1 + seg.dt * ha1 * a1;
      }
      break;
    }
  }
}

glm::dquat sampleRotation(const Sampler& sampler, double t) {
  if (sampler.interpolation == Interpolation::kLinear) {
    Segment seg;
    const Clamp where = locate(sampler.times, t, seg);
    if (where != Clamp::kInside)
      return glm::normalize(keyQuat(sampler, where == Clamp::kBefore ? 0 : sampler.times.size() - 1));
    // glm::slerp takes the shortest arc (negates one end when the dot product is negative).
    return glm::normalize(glm::slerp(glm::normalize(keyQuat(sampler, seg.k)),
                                     glm::normalize(keyQuat(sampler, seg.k + 1)), seg.s));
  }
  double v[4];
  sampleValues(sampler, t, v);
  const glm::dquat q(v[3], v[0], v[1], v[2]);
  const double len = glm::length(q);
  return len > 0 ? q / len : glm::dquat(1, 0, 0, 0);
}

bool hasZeroScale(const glm::dmat4& world) {
  constexpr double kEpsilon = 1e-12;
  return glm::length(glm::dvec3(world[0])) < kEpsilon || glm::length(glm::dvec3(world[1])) < kEpsilon ||
         glm::length(glm::dvec3(world[2])) < kEpsilon;
}

Evaluator::Evaluator(const Scene& scene) : scene_(scene), drivers_(scene.nodes.size()), lightDrivers_(scene.lights.size()) {
  for (const auto& animation : scene.animations) {
    for (const auto& channel : animation.channels) {
      const Sampler* sampler = &animation.samplers[static_cast<std::size_t>(channel.sampler)];
      if (sampler->times.empty()) continue;
      if (channel.light >= 0) {
        auto& l = lightDrivers_[static_cast<std::size_t>(channel.light)];
        (channel.path == AnimationPath::kLightColor ? l.color : channel.path == AnimationPath::kLightRange ? l.range : l.intensity) = sampler;
        continue;
      }
      auto& d = drivers_[static_cast<std::size_t>(channel.node)];
      switch (channel.path) {
        case AnimationPath::kTranslation: d.translation = sampler; break;
        case AnimationPath::kRotation: d.rotation = sampler; break;
        case AnimationPath::kScale: d.scale = sampler; break;
        case AnimationPath::kWeights: d.weights = sampler; break;
        case AnimationPath::kVisibility: d.visibility = sampler; break;
        case AnimationPath::kLightColor:
        case AnimationPath::kLightIntensity:
        case AnimationPath::kLightRange: break;  // handled above
      }
    }
  }
  // Breadth-first from the roots (and any other parentless node) gives parents before children.
  order_.reserve(scene.nodes.size());
  for (std::size_t i = 0; i < scene.nodes.size(); ++i)
    if (scene.nodes[i].parent < 0) order_.push_back(static_cast<int>(i));
  for (std::size_t head = 0; head < order_.size(); ++head)
    for (int c : scene.nodes[static_cast<std::size_t>(order_[head])].children) order_.push_back(c);
}

Transform Evaluator::localTransform(int node, double t) const {
  const Node& n = scene_.nodes[static_cast<std::size_t>(node)];
  Transform local = n.local;
  if (n.matrix) {
    const glm::dmat4& m = *n.matrix;
    local.translation = glm::dvec3(m[3]);
    local.scale = {glm::length(glm::dvec3(m[0])), glm::length(glm::dvec3(m[1])), glm::length(glm::dvec3(m[2]))};
    glm::dmat3 r(m);
    for (int c = 0; c < 3; ++c)
      if (local.scale[c] > 0) r[c] /= local.scale[c];
    local.rotation = glm::normalize(glm::quat_cast(r));
    return local;
  }
  const Drivers& d = drivers_[static_cast<std::size_t>(node)];
  double v[3];
  if (d.translation) {
    sampleValues(*d.translation, t, v);
    local.translation = {v[0], v[1], v[2]};
  }
  if (d.rotation) local.rotation = sampleRotation(*d.rotation, t);
  if (d.scale) {
    sampleValues(*d.scale, t, v);
    local.scale = {v[0], v[1], v[2]};
  }
  return local;
}

glm::dmat4 Evaluator::localMatrix(int node, double t) const {
  const Node& n = scene_.nodes[static_cast<std::size_t>(node)];
  if (n.matrix) return *n.matrix;
  return localTransform(node, t).matrix();
}

glm::dmat4 Evaluator::worldMatrix(int node, double t) const {
  glm::dmat4 world = localMatrix(node, t);
  for (int p = scene_.nodes[static_cast<std::size_t>(node)].parent; p >= 0; p = scene_.nodes[static_cast<std::size_t>(p)].parent)
    world = localMatrix(p, t) * world;
  return world;
}

bool Evaluator::ownVisibility(int node, double t) const {
  const Drivers& d = drivers_[static_cast<std::size_t>(node)];
  if (!d.visibility) return scene_.nodes[static_cast<std::size_t>(node)].visible;
  double v = 0;
  sampleValues(*d.visibility, t, std::span<double>(&v, 1));
  // KHR_animation_pointer booleans: any non-zero value is true. Interpolating a boolean only makes
  // sense as STEP; for LINEAR keys we treat >= 0.5 as true.
  return d.visibility->interpolation == Interpolation::kStep ? v != 0.0 : v >= 0.5;
}

bool Evaluator::visible(int node, double t) const {
  for (int n = node; n >= 0; n = scene_.nodes[static_cast<std::size_t>(n)].parent)
    if (!ownVisibility(n, t)) return false;
  return !hasZeroScale(worldMatrix(node, t));
}

std::vector<double> Evaluator::morphWeights(int node, double t) const {
  const Node& n = scene_.nodes[static_cast<std::size_t>(node)];
  std::vector<double> weights;
  if (n.mesh >= 0) {
    const auto& defaults = scene_.meshes[static_cast<std::size_t>(n.mesh)].defaultWeights;
    weights.assign(defaults.begin(), defaults.end());
  }
  if (!n.weights.empty()) weights = n.weights;
  if (const Sampler* s = drivers_[static_cast<std::size_t>(node)].weights) {
    weights.resize(static_cast<std::size_t>(s->components));
    sampleValues(*s, t, weights);
  }
  return weights;
}

std::vector<glm::dvec3> Evaluator::worldPositions(int node, std::size_t primitive, double t) const {
  std::vector<glm::dvec3> positions, normals;
  worldGeometry(node, primitive, t, positions, normals);
  return positions;
}

void Evaluator::worldGeometry(int node, std::size_t primitive, double t, std::vector<glm::dvec3>& positions,
                              std::vector<glm::dvec3>& normals) const {
  ScenePose pose;
  pose.world.resize(scene_.nodes.size());
  // Only the matrices this primitive needs: its node's, or its skin's joints'.
  const Node& owner = scene_.nodes[static_cast<std::size_t>(node)];
  if (owner.skin >= 0)
    for (int j : scene_.skins[static_cast<std::size_t>(owner.skin)].joints) pose.world[static_cast<std::size_t>(j)] = worldMatrix(j, t);
  else
    pose.world[static_cast<std::size_t>(node)] = worldMatrix(node, t);
  worldGeometry(node, primitive, t, pose, positions, normals);
}

void Evaluator::worldGeometry(int node, std::size_t primitive, double t, const ScenePose& pose, std::vector<glm::dvec3>& positions,
                              std::vector<glm::dvec3>& normals) const {
  const Node& n = scene_.nodes[static_cast<std::size_t>(node)];
  const Primitive& p = scene_.meshes[static_cast<std::size_t>(n.mesh)].primitives[primitive];
  positions.assign(p.positions.begin(), p.positions.end());
  normals.assign(p.normals.begin(), p.normals.end());
  const auto weights = morphWeights(node, t);
  for (std::size_t k = 0; k < std::min(weights.size(), p.targets.size()); ++k) {
    if (weights[k] == 0.0) continue;
    const auto& target = p.targets[k];
    for (std::size_t v = 0; v < target.positionDeltas.size() && v < positions.size(); ++v)
      positions[v] += weights[k] * glm::dvec3(target.positionDeltas[v]);
    for (std::size_t v = 0; v < target.normalDeltas.size() && v < normals.size(); ++v)
      normals[v] += weights[k] * glm::dvec3(target.normalDeltas[v]);
  }
  auto normalMatrix = [](const glm::dmat4& m) { return glm::transpose(glm::inverse(glm::dmat3(m))); };
  if (n.skin >= 0 && !p.joints.empty() && !p.weights.empty()) {
    const Skin& skin = scene_.skins[static_cast<std::size_t>(n.skin)];
    std::vector<glm::dmat4> jointMatrices(skin.joints.size());
    for (std::size_t j = 0; j < skin.joints.size(); ++j)
      jointMatrices[j] = pose.world[static_cast<std::size_t>(skin.joints[j])] * skin.inverseBindMatrices[j];
    for (std::size_t v = 0; v < positions.size(); ++v) {
      glm::dmat4 blended(0.0);
      for (int k = 0; k < 4; ++k)
        if (p.weights[v][k] != 0.0f) blended += static_cast<double>(p.weights[v][k]) * jointMatrices[p.joints[v][k]];
      positions[v] = glm::dvec3(blended * glm::dvec4(positions[v], 1.0));
      if (v < normals.size()) normals[v] = normalMatrix(blended) * normals[v];
    }
  } else {
    const glm::dmat4& world = pose.world[static_cast<std::size_t>(node)];
    const glm::dmat3 nm = normalMatrix(world);
    for (auto& v : positions) v = glm::dvec3(world * glm::dvec4(v, 1.0));
    for (auto& v : normals) v = nm * v;
  }
  for (auto& v : normals) {
    const double len = glm::length(v);
    if (len > 0) v /= len;
  }
}

Light Evaluator::light(int index, double t) const {
  Light l = scene_.lights[static_cast<std::size_t>(index)];
  const LightDrivers& d = lightDrivers_[static_cast<std::size_t>(index)];
  if (d.color) {
    double v[3];
    sampleValues(*d.color, t, v);
    l.color = glm::vec3(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
  }
  if (d.intensity) {
    double v = 0;
    sampleValues(*d.intensity, t, std::span<double>(&v, 1));
    l.intensity = static_cast<float>(v);
  }
  if (d.range) {
    double v = 0;
    sampleValues(*d.range, t, std::span<double>(&v, 1));
    l.range = static_cast<float>(std::max(0.0, v));
  }
  return l;
}

void Evaluator::evaluate(double t, ScenePose& pose) const {
  pose.lights.resize(scene_.lights.size());
  for (std::size_t l = 0; l < scene_.lights.size(); ++l) pose.lights[l] = light(static_cast<int>(l), t);
  const std::size_t count = scene_.nodes.size();
  pose.world.resize(count);
  pose.visible.resize(count);
  for (int node : order_) {
    const auto i = static_cast<std::size_t>(node);
    const int parent = scene_.nodes[i].parent;
    const glm::dmat4 local = localMatrix(node, t);
    const bool own = ownVisibility(node, t);
    if (parent < 0) {
      pose.world[i] = local;
      pose.visible[i] = own;
    } else {
      pose.world[i] = pose.world[static_cast<std::size_t>(parent)] * local;
      pose.visible[i] = own && pose.visible[static_cast<std::size_t>(parent)];
    }
  }
  // Zero scale hides a node but not its visibility flag's inheritance; apply it last.
  for (std::size_t i = 0; i < count; ++i)
    if (pose.visible[i] && hasZeroScale(pose.world[i])) pose.visible[i] = 0;
}

}  // namespace dynbench::scene
