#pragma once
// Questions every stage asks of a loaded scene: how many frames it has at a sampling rate, which
// nodes move, which are displayed, which node is "the camera". They live with the scene model so
// that metrics, render, convert and pipeline all ask them the same way (docs/metrics.md defines
// each answer).
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"

namespace dynbench::scene {

// Frames sampled at `fps` over [start, end]: floor((end - start) * fps) + 1, or 0 without animation.
std::size_t frameCount(const Scene::TimeRange& range, bool animated, double fps);
// The same for a whole scene: its time range, 0 when no animation has a channel.
std::size_t frameCount(const Scene& scene, double fps);

// Per node: 1 when the node or an ancestor has a translation, rotation, scale or visibility channel.
std::vector<char> dynamicNodes(const Scene& scene);

// Nodes reachable from the displayed scene's roots.
std::vector<char> nodesInScene(const Scene& scene);

// The camera node `selector` names (a camera index or a node/camera name), or by default the first
// animated camera node, else the first camera node; -1 when the scene has no camera at all.
Expected<int> selectCameraNode(const Scene& scene, const std::optional<std::string>& selector);

// True when a cut of the camera node (Node::cuts, the jump from key `from` to key `time`) overlaps
// (after, upTo]: the frame at upTo does not continue the frame at `after`. At another frame rate
// than the capture's, the frames on both sides of a jump's interpolated segment are cuts. Cut times
// are glTF key times (float): comparisons allow a float's precision.
bool cameraCutBetween(const Node& camera, double after, double upTo);

}  // namespace dynbench::scene
