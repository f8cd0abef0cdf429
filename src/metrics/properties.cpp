#include "metrics/properties.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

#include <fmt/format.h>

#include "scene/queries.h"

namespace dynbench::metrics {

using namespace dynbench::scene;

DatasetProperties measureProperties(const Scene& scene, double fps) {
  DatasetProperties p;
  p.fileFormat = scene.source.format;
  p.totalBytes = scene.source.totalBytes();
  p.fileCount = scene.source.files.size();
  p.nodes = scene.nodes.size();
  p.meshes = scene.meshes.size();
  p.skins = scene.skins.size();
  p.cameras = scene.cameras.size();
  p.lights = scene.lights.size();
  p.animations = scene.animations.size();
  p.warnings = scene.warnings;
  // Several animations driving the same node property usually means separate clips (walk, run)
  // that were never meant to play at once; all play together here and the later one wins.
  std::set<std::tuple<int, int, AnimationPath>> driven, conflicting;
  for (const auto& a : scene.animations) {
    std::set<std::tuple<int, int, AnimationPath>> own;
    for (const auto& c : a.channels) own.insert({c.node, c.light, c.path});
    for (const auto& key : own)
      if (!driven.insert(key).second) conflicting.insert(key);
  }
  if (!conflicting.empty())
    p.warnings.push_back(fmt::format("{}: {} node properties are driven by more than one animation; all {} animations play "
                                     "together and the later one wins (pick one with --animation)",
                                     scene.source.path.string(), conflicting.size(), scene.animations.size()));
  for (const auto& s : scene.skins) p.joints += s.joints.size();
  for (const auto& a : scene.animations) p.channels += a.channels.size();
  for (const auto& m : scene.meshes) {
    p.uniqueFaces += m.triangleCount();
    p.morphTargets = p.morphTargets || m.morphTargetCount() > 0;
  }

  p.materialCount = scene.materials.size();
  for (const auto& m : scene.materials) ++p.workflowCounts[toString(m.workflow)];
  p.materialWorkflow = std::string(1, '-');  // not = "-": GCC 12's -Wrestrict false positive (bug 105651)
  std::size_t best = 0;
  for (const auto& [name, count] : p.workflowCounts)
    if (count > best) {
      best = count;
      p.materialWorkflow = name;
    }
  p.textureCount = scene.images.size();
  for (const auto& image : scene.images) p.textureBytes += image.bytes;

  const auto range = scene.timeRange();
  p.fps = fps;
  p.startTime = range.start;
  p.endTime = range.end;
  p.animationFrames = frameCount(scene, fps);

  const auto dynamic = dynamicNodes(scene);
  const auto inScene = nodesInScene(scene);
  std::set<int> morphAnimated;
  for (const auto& a : scene.animations)
    for (const auto& c : a.channels)
      if (c.path == AnimationPath::kWeights) morphAnimated.insert(c.node);
  std::set<int> usedSkins;
  for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
    if (!inScene[i]) continue;
    const Node& node = scene.nodes[i];
    if (node.mesh >= 0) {
      p.faces += scene.meshes[static_cast<std::size_t>(node.mesh)].triangleCount();
      if (morphAnimated.contains(static_cast<int>(i))) ++p.morphAnimatedObjects;
      if (node.skin >= 0) usedSkins.insert(node.skin);
      else if (dynamic[i]) ++p.dynamicRigidObjects;
      else ++p.staticObjects;
    }
    if (node.camera >= 0 && dynamic[i]) p.animatedCamera = true;
    if (node.light >= 0) {
      switch (scene.lights[static_cast<std::size_t>(node.light)].type) {
        case Light::Type::kPoint: ++(dynamic[i] ? p.dynamicPointLights : p.staticPointLights); break;
        case Light::Type::kSpot: ++p.spotLights; break;
        case Light::Type::kDirectional: ++p.directionalLights; break;
      }
    }
  }
  p.armatures = usedSkins.size();
  return p;
}

}  // namespace dynbench::metrics
