#include "convert/converter.h"

namespace dynbench::convert::detail {

Expected<void> Converter::buildDocument() {
  doc_ = {{"asset", {{"version", "2.0"}, {"generator", fmt::format("dynbench {} convert", kVersion)}}},
          {"scene", 0},
          {"scenes", {{{"name", "capture"}, {"nodes", {0}}}}},
          {"nodes", json::array()},
          {"buffers", json::array()},
          {"bufferViews", json::array()},
          {"accessors", json::array()},
          {"samplers", {{{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 10497}, {"wrapT", 10497}}}}};
  const int world = addNode({{"name", "WorldOrigo"}}, -1);
  const int staticObjects = addNode({{"name", "StaticObjects"}}, world);
  const int dynamicObjects = addNode({{"name", "DynamicObjects"}}, world);
  if (auto ok = buildMeshes(); !ok) return ok;

  // The map geometry: a model whose path is the map's name, placed at the map offset.
  const auto& settings = reader_->settings();
  if (int model = reader_->modelIndex(settings.mapName); !settings.mapName.empty() && model >= 0 && meshOfModel_[static_cast<std::size_t>(model)] >= 0) {
    json node = trs(settings.mapOffset, glm::dquat(1, 0, 0, 0));
    node["name"] = "map " + settings.mapName;
    node["mesh"] = meshOfModel_[static_cast<std::size_t>(model)];
    addNode(node, staticObjects);
  }
  // The camera definition.
  CameraSettings cam = settings.camera.value_or(CameraSettings{16.0 / 9.0, 60.0, 0.1, 1000.0});
  if (!settings.camera) report_.warnings.push_back("the capture has no camera settings (C record); using 16:9, 60 degrees, 0.1-1000");
  doc_["cameras"] = {{{"type", "perspective"},
                      {"perspective", {{"aspectRatio", cam.aspect}, {"yfov", radians(cam.yfovDegrees)}, {"znear", cam.znear}, {"zfar", cam.zfar}}}}};

  // Times: one array for the whole capture; every track's input is a slice of it.
  const std::uint64_t timesBytes = times_.size() * sizeof(float);
  const std::uint64_t timesOffset = bin_->allocate(timesBytes);
  bin_->write(timesOffset, times_.data(), timesBytes);
  timesView_ = bufferView(timesOffset, timesBytes);

  std::vector<json> channels, samplers;
  auto channel = [&](int input, int output, const char* interpolation, int node, const char* path) {
    samplers.push_back({{"input", input}, {"output", output}, {"interpolation", interpolation}});
    json target = {{"node", node}, {"path", path}};
    channels.push_back({{"sampler", samplers.size() - 1}, {"target", target}});
  };
  auto lightChannel = [&](int input, int output, int light, const char* property) {
    samplers.push_back({{"input", input}, {"output", output}, {"interpolation", "LINEAR"}});
    channels.push_back({{"sampler", samplers.size() - 1},
                        {"target", {{"path", "pointer"},
                                    {"extensions", {{"KHR_animation_pointer",
                                                     {{"pointer", fmt::format("/extensions/KHR_lights_punctual/lights/{}/{}", light, property)}}}}}}}});
    usesAnimationPointer_ = true;
  };
  auto pointerChannel = [&](int input, int output, int node) {
    samplers.push_back({{"input", input}, {"output", output}, {"interpolation", "STEP"}});
    channels.push_back({{"sampler", samplers.size() - 1},
                        {"target", {{"path", "pointer"},
                                    {"extensions", {{"KHR_animation_pointer",
                                                     {{"pointer", fmt::format("/nodes/{}/extensions/KHR_node_visibility/visible", node)}}}}}}}});
    usesVisibility_ = true;
  };
  auto spanInput = [&](const Track& t) {
    return accessor(timesView_, 4 * t.first, kFloat, t.span(), "SCALAR", std::vector<float>{times_[t.first]},
                    std::vector<float>{times_[t.lastSpan]});
  };
  auto region = [&](std::size_t count, std::size_t elementBytes, std::uint64_t& offset, int& view) {
    offset = bin_->allocate(count * elementBytes);
    view = bufferView(offset, count * elementBytes);
  };

  for (auto& [id, t] : tracks_) {
    ++report_.capturables;
    if (placeStatic(t, staticObjects)) continue;
    if (!t.appeared) continue;
    // Dynamic capturables: node, key frames over their span, visibility keys.
    json node = {{"name", fmt::format("{}_{}", kindName(t.kind), t.id)}};
    if (t.kind == Kind::kModel) node["name"] = fmt::format("model_{}_{}", t.id, reader_->models()[static_cast<std::size_t>(t.model)].path);
    if (t.kind == Kind::kCamera) node["camera"] = 0;
    if (t.kind == Kind::kCamera && !t.cuts.empty()) {
      json cuts = json::array();
      for (const auto& c : t.cuts) cuts.push_back({{"from", c.from}, {"time", c.time}, {"reason", c.reason}});
      node["extras"]["dynbench_camera_cuts"] = cuts;
      report_.cameraCuts += t.cuts.size();
    }
    const int mesh = t.kind == Kind::kModel ? meshOfModel_[static_cast<std::size_t>(t.model)] : -1;
    if (mesh >= 0 && !t.skinned) node["mesh"] = mesh;
    const bool nodeVisibility = t.hasVisibilityChannel() && options_.visibility != VisibilityMode::kScale;
    const bool scaleVisibility = t.hasVisibilityChannel() && options_.visibility != VisibilityMode::kNode && t.kind == Kind::kModel;
    if (nodeVisibility && t.kind != Kind::kCamera) node["extensions"]["KHR_node_visibility"] = {{"visible", true}};
    t.node = addNode(node, dynamicObjects);
    if (t.kind == Kind::kLight) lightNodes(t, t.node);

    const int input = spanInput(t);
    int view = -1;
    region(t.span(), 12, t.translationOffset, view);
    channel(input, accessor(view, 0, kFloat, t.span(), "VEC3"), "LINEAR", t.node, "translation");
    if (t.kind != Kind::kLight) {
      region(t.span(), 16, t.rotationOffset, view);
      channel(input, accessor(view, 0, kFloat, t.span(), "VEC4"), "LINEAR", t.node, "rotation");
    }
    if (t.kind == Kind::kLight && t.colorVaries) {
      region(t.span(), 12, t.colorOffset, view);
      lightChannel(input, accessor(view, 0, kFloat, t.span(), "VEC3"), t.lightDefinition, "color");
      region(t.span(), 4, t.intensityOffset, view);
      lightChannel(input, accessor(view, 0, kFloat, t.span(), "SCALAR"), t.lightDefinition, "intensity");
      // A light whose engine radius changes (an explosion grows): its range is animated too. A
      // light without a range keeps none (the falloff the engine gives it is fixed by the first).
      if (t.light.range > 0) {
        region(t.span(), 4, t.rangeOffset, view);
        lightChannel(input, accessor(view, 0, kFloat, t.span(), "SCALAR"), t.lightDefinition, "range");
      }
    }
    if (t.hasVisibilityChannel() && ((nodeVisibility && t.kind != Kind::kCamera) || scaleVisibility)) {
      region(t.visibilityKeys, 4, t.visTimeOffset, view);
      const int visInput = accessor(view, 0, kFloat, t.visibilityKeys, "SCALAR", std::vector<float>{times_.front()},
                                    std::vector<float>{times_[t.lastKeyFrame]});
      visInputs_[t.id] = visInput;
      if (nodeVisibility && t.kind != Kind::kCamera) {
        region(t.visibilityKeys, 1, t.visValueOffset, view);
        pointerChannel(visInput, accessor(view, 0, kUnsignedByte, t.visibilityKeys, "SCALAR"), t.node);
      }
      if (scaleVisibility) {
        region(t.visibilityKeys, 12, t.scaleOffset, view);
        channel(visInput, accessor(view, 0, kFloat, t.visibilityKeys, "VEC3"), "STEP", t.node, "scale");
      }
    }
    if (t.skinned) buildSkin(t, mesh, input, channel, region);
    // A vertex-animated model's morph weights, a key frame's worth per capture frame (key frame 0
    // until its first `v` record).
    if (const std::size_t keyFrames = t.kind == Kind::kModel ? reader_->models()[static_cast<std::size_t>(t.model)].keyFrames : 0;
        keyFrames > 0 && mesh >= 0) {
      region(t.span() * keyFrames, 4, t.weightsOffset, view);
      channel(input, accessor(view, 0, kFloat, t.span() * keyFrames, "SCALAR"), "LINEAR", t.node, "weights");
      t.heldWeights.assign(keyFrames, 0.0f);
      t.heldWeights[0] = 1.0f;
    }
  }
  report_.channels = channels.size();
  if (!channels.empty()) doc_["animations"] = {{{"name", "capture"}, {"samplers", samplers}, {"channels", channels}}};
  return {};
}

bool Converter::placeStatic(Track& t, int staticObjects) {
  if (t.kind == Kind::kStaticModel) {
    const int mesh = meshOfModel_[static_cast<std::size_t>(t.model)];
    const auto& model = reader_->models()[static_cast<std::size_t>(t.model)];
    json node = trs(translationOf(t.staticPose), rotationOf(t.staticPose));
    node["name"] = fmt::format("static_{}_{}", t.id, model.path);
    if (mesh >= 0 && model.joints.empty()) node["mesh"] = mesh;
    t.node = addNode(node, staticObjects);
    // A skinned model placed as a static one keeps its bind pose: a skin whose joints never move.
    if (!model.joints.empty()) addSkin(t, mesh);
    return true;
  }
  if (t.kind == Kind::kLight && !t.light.dynamic) {
    json node = trs(t.light.position, glm::dquat(1, 0, 0, 0));
    node["name"] = fmt::format("light_{}_{}", t.id, t.light.modelType);
    t.node = addNode(node, staticObjects);
    lightNodes(t, t.node);
    return true;
  }
  return false;
}

// Joint nodes in the bind pose under the capturable's node, the skin, and the skinned mesh node;
// returns the joint nodes.
std::vector<int> Converter::addSkin(const Track& t, int mesh) {
  const auto& model = reader_->models()[static_cast<std::size_t>(t.model)];
  std::vector<int> jointNodes;
  int roots = 0;
  for (const auto& j : model.joints) {
    json node = trs(translationOf(j.bindPose), rotationOf(j.bindPose));
    node["name"] = fmt::format("{}_{}", j.name.empty() ? "joint" : j.name, t.id);
    jointNodes.push_back(addNode(node, j.parent < 0 ? t.node : jointNodes[static_cast<std::size_t>(j.parent)]));
    roots += j.parent < 0 ? 1 : 0;
  }
  // glTF: the skeleton is the joints' closest common root or an ancestor of it; with several
  // root joints that is the capturable's node.
  json skin = {{"joints", jointNodes}, {"skeleton", roots == 1 ? jointNodes.front() : t.node}, {"name", fmt::format("skin_{}", t.id)}};
  if (auto it = ibmOfModel_.find(t.model); it != ibmOfModel_.end()) skin["inverseBindMatrices"] = it->second;
  doc_["skins"].push_back(skin);
  ++report_.skins;
  if (mesh >= 0)
    addNode({{"name", fmt::format("skinned_{}", t.id)}, {"mesh", mesh}, {"skin", doc_["skins"].size() - 1}}, t.node);
  return jointNodes;
}

template <typename Channel, typename Region>
void Converter::buildSkin(Track& t, int mesh, int input, Channel& channel, Region& region) {
  const auto& model = reader_->models()[static_cast<std::size_t>(t.model)];
  for (const int jointNode : addSkin(t, mesh)) {
    std::uint64_t offset = 0;
    int view = -1;
    region(t.span(), 12, offset, view);
    t.jointTranslationOffsets.push_back(offset);
    channel(input, accessor(view, 0, kFloat, t.span(), "VEC3"), "LINEAR", jointNode, "translation");
    region(t.span(), 16, offset, view);
    t.jointRotationOffsets.push_back(offset);
    channel(input, accessor(view, 0, kFloat, t.span(), "VEC4"), "LINEAR", jointNode, "rotation");
  }
  // Until the first joint record, joints hold the bind pose.
  for (const auto& j : model.joints) {
    t.heldJointTranslation.push_back(translationOf(j.bindPose));
    t.heldJointRotation.push_back(rotationOf(j.bindPose));
    t.lastJointRotation.push_back(rotationOf(j.bindPose));
  }
}
}  // namespace dynbench::convert::detail
