#include "scene/queries.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include <fmt/format.h>

namespace dynbench::scene {

std::size_t frameCount(const Scene::TimeRange& range, bool animated, double fps) {
  if (!animated || !(fps > 0)) return 0;
  // The small epsilon keeps 2.0 s at 24 fps at 49 frames despite float key times.
  return static_cast<std::size_t>(std::floor((range.end - range.start) * fps + 1e-6)) + 1;
}

std::size_t frameCount(const Scene& scene, double fps) {
  bool animated = false;
  for (const auto& a : scene.animations) animated = animated || !a.channels.empty();
  return frameCount(scene.timeRange(), animated, fps);
}

bool cameraCutBetween(const Node& camera, double after, double upTo) {
  const auto slack = [](double t) { return 4.0 * std::numeric_limits<float>::epsilon() * std::max(1.0, std::abs(t)); };
  for (const auto& cut : camera.cuts)
    if (after < cut.time - slack(cut.time) && upTo > cut.from + slack(cut.from)) return true;
  return false;
}

std::vector<char> dynamicNodes(const Scene& scene) {
  std::vector<char> animated(scene.nodes.size(), 0);
  for (const auto& animation : scene.animations)
    for (const auto& channel : animation.channels)
      if (channel.node >= 0 && channel.path != AnimationPath::kWeights) animated[static_cast<std::size_t>(channel.node)] = 1;
  std::vector<char> dynamic(scene.nodes.size(), 0);
  for (std::size_t i = 0; i < scene.nodes.size(); ++i)
    for (int n = static_cast<int>(i); n >= 0 && !dynamic[i]; n = scene.nodes[static_cast<std::size_t>(n)].parent)
      dynamic[i] = animated[static_cast<std::size_t>(n)];
  return dynamic;
}

std::vector<char> nodesInScene(const Scene& scene) {
  std::vector<char> in(scene.nodes.size(), 0);
  std::vector<int> stack(scene.roots.begin(), scene.roots.end());
  while (!stack.empty()) {
    const int n = stack.back();
    stack.pop_back();
    if (in[static_cast<std::size_t>(n)]) continue;
    in[static_cast<std::size_t>(n)] = 1;
    for (int c : scene.nodes[static_cast<std::size_t>(n)].children) stack.push_back(c);
  }
  return in;
}

Expected<int> selectCameraNode(const Scene& scene, const std::optional<std::string>& selector) {
  std::vector<int> cameraNodes;
  for (std::size_t i = 0; i < scene.nodes.size(); ++i)
    if (scene.nodes[i].camera >= 0) cameraNodes.push_back(static_cast<int>(i));
  auto available = [&] {
    std::string list;
    for (int n : cameraNodes) {
      const auto& node = scene.nodes[static_cast<std::size_t>(n)];
      const auto& camera = scene.cameras[static_cast<std::size_t>(node.camera)];
      list += fmt::format("{}{} (camera {} '{}')", list.empty() ? "" : ", ", node.name.empty() ? "<unnamed node>" : node.name,
                          node.camera, camera.name);
    }
    return list.empty() ? std::string("none") : list;
  };
  if (!selector) {
    if (cameraNodes.empty()) return -1;
    const auto dynamic = dynamicNodes(scene);
    for (int n : cameraNodes)
      if (dynamic[static_cast<std::size_t>(n)]) return n;
    return cameraNodes.front();
  }
  int index = -1;
  const auto& s = *selector;
  if (!s.empty() && std::from_chars(s.data(), s.data() + s.size(), index).ec == std::errc() &&
      std::all_of(s.begin(), s.end(), ::isdigit)) {
    for (int n : cameraNodes)
      if (scene.nodes[static_cast<std::size_t>(n)].camera == index) return n;
    return fail(ErrorCode::kUsage, "{}: --camera {}: no node uses camera {} (cameras in the file: {})",
                scene.source.path.string(), s, index, available());
  }
  for (int n : cameraNodes) {
    const auto& node = scene.nodes[static_cast<std::size_t>(n)];
    if (node.name == s || scene.cameras[static_cast<std::size_t>(node.camera)].name == s) return n;
  }
  return fail(ErrorCode::kUsage, "{}: --camera '{}' names no camera (cameras in the file: {})", scene.source.path.string(),
              s, available());
}

}  // namespace dynbench::scene
