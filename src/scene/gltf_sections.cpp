#include "scene/gltf_reader.h"

namespace dynbench::scene::gltf_detail {

void GltfReader::readAsset() {
  const json* asset = member(root_, "asset");
  if (!asset || !asset->is_object()) invalid("/asset", "missing; every glTF file needs an asset object");
  const std::string version = string(*asset, "version", "/asset");
  if (version.rfind("2.", 0) != 0)
    fail(ErrorCode::kUnsupported, "/asset/version",
         fmt::format("glTF version '{}' is not supported (expected 2.x)", version));
  const json& required = array(root_, "extensionsRequired", "");
  for (std::size_t i = 0; i < required.size(); ++i) {
    if (!required[i].is_string()) invalid(child("/extensionsRequired", i), "expected a string");
    const auto name = required[i].get<std::string>();
    if (!kSupportedExtensions.contains(name))
      fail(ErrorCode::kUnsupported, child("/extensionsRequired", i),
           fmt::format("required extension '{}' is not supported by dynbench", name));
  }
}

void GltfReader::readImages() {
  const json& images = array(root_, "images", "");
  for (std::size_t i = 0; i < images.size(); ++i) {
    const auto p = child("/images", i);
    const json& im = objectAt(images, i, "/images");
    Image image;
    image.name = string(im, "name", p);
    image.mimeType = string(im, "mimeType", p);
    const int view = index(im, "bufferView", p, bufferViews_.size(), "bufferView");
    const json* uri = member(im, "uri");
    if (view >= 0) {
      image.embedded = true;
      image.bytes = bufferViews_[static_cast<std::size_t>(view)].length;
    } else if (uri) {
      if (!uri->is_string()) invalid(child(p, "uri"), "expected a string");
      image.uri = uri->get<std::string>();
      if (image.uri.rfind("data:", 0) == 0) {
        image.embedded = true;
        const auto comma = image.uri.find(',');
        image.bytes = comma == std::string::npos ? 0 : base64DecodedSize(std::string_view(image.uri).substr(comma + 1));
        image.uri.clear();  // the payload is not a name worth keeping
      } else {
        image.file = resolveUri(image.uri, child(p, "uri"));
        auto size = fileSize(image.file);  // only the size: images are never read or decoded here
        if (!size)
          fail(ErrorCode::kIo, child(p, "uri"), fmt::format("cannot find image '{}' ({})", image.uri, size.error().message));
        image.bytes = *size;
        addSourceFile(image.file, image.bytes);
      }
    } else {
      invalid(p, "has neither uri nor bufferView");
    }
    scene_.images.push_back(std::move(image));
  }
  const json& textures = array(root_, "textures", "");
  for (std::size_t i = 0; i < textures.size(); ++i) {
    const auto p = child("/textures", i);
    const json& t = objectAt(textures, i, "/textures");
    int source = index(t, "source", p, scene_.images.size(), "image");
    // Texture-format extensions name their own source (e.g. KHR_texture_basisu, EXT_texture_webp).
    if (const json* ext = member(t, "extensions"); ext && ext->is_object())
      for (const auto& [name, value] : ext->items())
        if (value.is_object() && value.contains("source"))
          source = index(value, "source", child(child(p, "extensions"), name), scene_.images.size(), "image");
    textureImage_.push_back(source);
  }
}

TextureRef GltfReader::textureRef(const json& object, std::string_view key, std::string_view pointer) const {
  TextureRef ref;
  const json* t = member(object, key);
  if (!t) return ref;
  const auto p = child(pointer, key);
  if (!t->is_object()) invalid(p, "expected a textureInfo object");
  const int texture = index(*t, "index", p, textureImage_.size(), "texture", true);
  ref.image = textureImage_[static_cast<std::size_t>(texture)];
  ref.texCoord = static_cast<int>(unsignedInt(*t, "texCoord", p, 0));
  return ref;
}

void GltfReader::readMaterials() {
  const json& materials = array(root_, "materials", "");
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const auto p = child("/materials", i);
    const json& m = objectAt(materials, i, "/materials");
    Material material;
    material.name = string(m, "name", p);
    if (const json* pbr = member(m, "pbrMetallicRoughness")) {
      const auto pp = child(p, "pbrMetallicRoughness");
      material.baseColorFactor = glm::vec4(vector<4>(*pbr, "baseColorFactor", pp, glm::dvec4(1.0)));
      material.metallicFactor = static_cast<float>(number(*pbr, "metallicFactor", pp, 1.0));
      material.roughnessFactor = static_cast<float>(number(*pbr, "roughnessFactor", pp, 1.0));
      material.baseColorTexture = textureRef(*pbr, "baseColorTexture", pp);
      material.metallicRoughnessTexture = textureRef(*pbr, "metallicRoughnessTexture", pp);
    }
    if (const json* sg = extension(m, "KHR_materials_pbrSpecularGlossiness")) {
      const auto sp = child(child(p, "extensions"), "KHR_materials_pbrSpecularGlossiness");
      material.workflow = MaterialWorkflow::kSpecularGlossiness;
      material.baseColorFactor = glm::vec4(vector<4>(*sg, "diffuseFactor", sp, glm::dvec4(1.0)));
      material.baseColorTexture = textureRef(*sg, "diffuseTexture", sp);
      material.metallicRoughnessTexture = textureRef(*sg, "specularGlossinessTexture", sp);
    }
    material.normalTexture = textureRef(m, "normalTexture", p);
    material.occlusionTexture = textureRef(m, "occlusionTexture", p);
    material.emissiveTexture = textureRef(m, "emissiveTexture", p);
    material.emissiveFactor = glm::vec3(vector<3>(m, "emissiveFactor", p, glm::dvec3(0.0)));
    if (const json* es = extension(m, "KHR_materials_emissive_strength"))
      material.emissiveFactor *= static_cast<float>(
          number(*es, "emissiveStrength", child(child(p, "extensions"), "KHR_materials_emissive_strength"), 1.0));
    if (const json* sp = extension(m, "KHR_materials_specular")) {
      const auto spp = child(child(p, "extensions"), "KHR_materials_specular");
      material.specularFactor = static_cast<float>(number(*sp, "specularFactor", spp, 1.0));
      material.specularColorFactor = glm::vec3(vector<3>(*sp, "specularColorFactor", spp, glm::dvec3(1.0)));
    }
    const std::string alphaMode = string(m, "alphaMode", p, "OPAQUE");
    if (alphaMode == "MASK") material.alphaMode = AlphaMode::kMask;
    else if (alphaMode == "BLEND") material.alphaMode = AlphaMode::kBlend;
    else if (alphaMode != "OPAQUE") invalid(child(p, "alphaMode"), "expected OPAQUE, MASK or BLEND");
    material.alphaCutoff = static_cast<float>(number(m, "alphaCutoff", p, 0.5));
    material.doubleSided = boolean(m, "doubleSided", p, false);
    for (const auto* ref : {&material.baseColorTexture, &material.metallicRoughnessTexture, &material.normalTexture,
                            &material.occlusionTexture, &material.emissiveTexture})
      if (ref->image >= 0 && std::find(material.images.begin(), material.images.end(), ref->image) == material.images.end())
        material.images.push_back(ref->image);
    scene_.materials.push_back(std::move(material));
  }
}

void GltfReader::readMeshes() {
  const json& meshes = array(root_, "meshes", "");
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const auto p = child("/meshes", i);
    const json& m = objectAt(meshes, i, "/meshes");
    Mesh mesh;
    mesh.name = string(m, "name", p);
    const json& primitives = array(m, "primitives", p);
    if (primitives.empty()) invalid(child(p, "primitives"), "a mesh needs at least one primitive");
    for (std::size_t k = 0; k < primitives.size(); ++k)
      mesh.primitives.push_back(readPrimitive(objectAt(primitives, k, child(p, "primitives")), child(child(p, "primitives"), k)));
    for (double w : numberList(m, "weights", p)) mesh.defaultWeights.push_back(static_cast<float>(w));
    mesh.defaultWeights.resize(mesh.morphTargetCount(), 0.0f);
    scene_.meshes.push_back(std::move(mesh));
  }
}

Primitive GltfReader::readPrimitive(const json& pr, const std::string& p) {
  Primitive prim;
  const std::size_t mode = unsignedInt(pr, "mode", p, 4);
  if (mode > 6) invalid(child(p, "mode"), fmt::format("{} is not a glTF primitive mode (0-6)", mode));
  prim.mode = mode >= 4 ? PrimitiveMode::kTriangles : mode >= 1 ? PrimitiveMode::kLines : PrimitiveMode::kPoints;
  prim.material = index(pr, "material", p, scene_.materials.size(), "material");
  const json* attributes = member(pr, "attributes");
  if (!attributes || !attributes->is_object()) invalid(child(p, "attributes"), "missing; expected an object");
  const auto ap = child(p, "attributes");
  auto attribute = [&](std::string_view name) { return index(*attributes, name, ap, accessors_.size(), "accessor"); };
  const int position = attribute("POSITION");
  if (position < 0) invalid(ap, "has no POSITION attribute");
  requireType(position, child(ap, "POSITION"), {"VEC3"});
  prim.positions = readVectors<glm::vec3>(position, child(ap, "POSITION"));
  const std::size_t vertexCount = prim.positions.size();
  auto sameCount = [&](int accessor, std::string_view name) {
    if (accessorAt(accessor).count != vertexCount)
      invalid(child(ap, name), fmt::format("has {} elements but POSITION has {}", accessorAt(accessor).count, vertexCount));
  };
  if (int a = attribute("NORMAL"); a >= 0) {
    requireType(a, child(ap, "NORMAL"), {"VEC3"});
    sameCount(a, "NORMAL");
    prim.normals = readVectors<glm::vec3>(a, child(ap, "NORMAL"));
  }
  if (int a = attribute("TEXCOORD_0"); a >= 0) {
    requireType(a, child(ap, "TEXCOORD_0"), {"VEC2"});
    sameCount(a, "TEXCOORD_0");
    prim.uvs = readVectors<glm::vec2>(a, child(ap, "TEXCOORD_0"));
  }
  if (int a = attribute("COLOR_0"); a >= 0) {
    // glTF: RGB or RGBA, float or normalised unsigned; RGB has alpha 1.
    requireType(a, child(ap, "COLOR_0"), {"VEC3", "VEC4"});
    sameCount(a, "COLOR_0");
    if (accessorAt(a).components == 4) {
      prim.colors = readVectors<glm::vec4>(a, child(ap, "COLOR_0"));
    } else {
      for (const auto& rgb : readVectors<glm::vec3>(a, child(ap, "COLOR_0"))) prim.colors.push_back(glm::vec4(rgb, 1.0f));
    }
  }
  if (int a = attribute("JOINTS_0"); a >= 0) {
    requireType(a, child(ap, "JOINTS_0"), {"VEC4"});
    sameCount(a, "JOINTS_0");
    prim.joints = readVectors<glm::u16vec4>(a, child(ap, "JOINTS_0"));
  }
  if (int a = attribute("WEIGHTS_0"); a >= 0) {
    requireType(a, child(ap, "WEIGHTS_0"), {"VEC4"});
    sameCount(a, "WEIGHTS_0");
    prim.weights = readVectors<glm::vec4>(a, child(ap, "WEIGHTS_0"));
  }
  std::vector<std::uint32_t> indices;
  if (int a = index(pr, "indices", p, accessors_.size(), "accessor"); a >= 0) {
    requireType(a, child(p, "indices"), {"SCALAR"});
    const auto values = readAccessor(a);
    indices.reserve(values.size());
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (values[k] >= static_cast<double>(vertexCount))
        invalid(child(p, "indices"), fmt::format("index {} at position {} is out of range (the primitive has {} vertices)",
                                                 static_cast<std::uint64_t>(values[k]), k, vertexCount));
      indices.push_back(static_cast<std::uint32_t>(values[k]));
    }
  } else {
    indices.resize(vertexCount);
    for (std::size_t k = 0; k < vertexCount; ++k) indices[k] = static_cast<std::uint32_t>(k);
  }
  if (mode == 4) {
    indices.resize(indices.size() / 3 * 3);
    prim.indices = std::move(indices);
  } else if (mode == 5) {  // strip: alternate winding to keep faces consistent
    for (std::size_t k = 2; k < indices.size(); ++k) {
      const bool even = (k % 2) == 0;
      prim.indices.insert(prim.indices.end(), {indices[k - 2], even ? indices[k - 1] : indices[k], even ? indices[k] : indices[k - 1]});
    }
  } else if (mode == 6) {  // fan
    for (std::size_t k = 2; k < indices.size(); ++k)
      prim.indices.insert(prim.indices.end(), {indices[0], indices[k - 1], indices[k]});
  } else {
    prim.indices = std::move(indices);
  }
  const json& targets = array(pr, "targets", p);
  for (std::size_t t = 0; t < targets.size(); ++t) {
    const auto tp = child(child(p, "targets"), t);
    const json& target = objectAt(targets, t, child(p, "targets"));
    MorphTarget morph;
    if (int a = index(target, "POSITION", tp, accessors_.size(), "accessor"); a >= 0) {
      requireType(a, child(tp, "POSITION"), {"VEC3"});
      if (accessorAt(a).count != vertexCount) invalid(child(tp, "POSITION"), "count differs from the primitive's POSITION");
      morph.positionDeltas = readVectors<glm::vec3>(a, child(tp, "POSITION"));
    }
    if (int a = index(target, "NORMAL", tp, accessors_.size(), "accessor"); a >= 0) {
      requireType(a, child(tp, "NORMAL"), {"VEC3"});
      if (accessorAt(a).count != vertexCount) invalid(child(tp, "NORMAL"), "count differs from the primitive's POSITION");
      morph.normalDeltas = readVectors<glm::vec3>(a, child(tp, "NORMAL"));
    }
    prim.targets.push_back(std::move(morph));
  }
  return prim;
}

void GltfReader::readCameras() {
  const json& cameras = array(root_, "cameras", "");
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const auto p = child("/cameras", i);
    const json& c = objectAt(cameras, i, "/cameras");
    Camera camera;
    camera.name = string(c, "name", p);
    const std::string type = string(c, "type", p);
    if (type == "perspective") {
      const json* pe = member(c, "perspective");
      if (!pe || !pe->is_object()) invalid(child(p, "perspective"), "missing; expected an object");
      const auto pp = child(p, "perspective");
      camera.yfov = number(*pe, "yfov", pp, 0, true);
      camera.aspectRatio = number(*pe, "aspectRatio", pp, 0);
      camera.znear = number(*pe, "znear", pp, 0, true);
      camera.zfar = number(*pe, "zfar", pp, 0);
      if (camera.yfov <= 0 || camera.yfov >= kPiRadians) invalid(child(pp, "yfov"), "must be in (0, pi) radians");
    } else if (type == "orthographic") {
      const json* o = member(c, "orthographic");
      if (!o || !o->is_object()) invalid(child(p, "orthographic"), "missing; expected an object");
      const auto op = child(p, "orthographic");
      camera.type = Camera::Type::kOrthographic;
      camera.xmag = number(*o, "xmag", op, 0, true);
      camera.ymag = number(*o, "ymag", op, 0, true);
      camera.znear = number(*o, "znear", op, 0, true);
      camera.zfar = number(*o, "zfar", op, 0, true);
    } else {
      invalid(child(p, "type"), fmt::format("'{}' is neither perspective nor orthographic", type));
    }
    scene_.cameras.push_back(std::move(camera));
  }
}

void GltfReader::readLights() {
  const json* ext = extension(root_, "KHR_lights_punctual");
  if (!ext) return;
  const std::string p = "/extensions/KHR_lights_punctual";
  const json& lights = array(*ext, "lights", p);
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const auto lp = child(child(p, "lights"), i);
    const json& l = objectAt(lights, i, child(p, "lights"));
    Light light;
    light.name = string(l, "name", lp);
    const std::string type = string(l, "type", lp);
    if (type == "point") light.type = Light::Type::kPoint;
    else if (type == "spot") light.type = Light::Type::kSpot;
    else if (type == "directional") light.type = Light::Type::kDirectional;
    else invalid(child(lp, "type"), fmt::format("'{}' is not point, spot or directional", type));
    light.color = glm::vec3(vector<3>(l, "color", lp, glm::dvec3(1.0)));
    light.intensity = static_cast<float>(number(l, "intensity", lp, 1.0));
    light.range = static_cast<float>(number(l, "range", lp, 0.0));
    if (const json* spot = member(l, "spot")) {
      light.innerConeAngle = static_cast<float>(number(*spot, "innerConeAngle", child(lp, "spot"), 0.0));
      light.outerConeAngle = static_cast<float>(number(*spot, "outerConeAngle", child(lp, "spot"), kPiRadians / 4));
    }
    scene_.lights.push_back(std::move(light));
  }
}

// DYNBENCH_environment (docs/dataset.md): the image is resolved like any URI and must exist.
void GltfReader::readEnvironment() {
  const json* ext = extension(root_, "DYNBENCH_environment");
  if (!ext) return;
  const std::string p = "/extensions/DYNBENCH_environment";
  Environment env;
  if (!member(*ext, "uri")) invalid(p, "missing 'uri' (the environment image)");
  env.uri = string(*ext, "uri", p);
  env.file = resolveUri(env.uri, child(p, "uri"));
  auto size = fileSize(env.file);
  if (!size) fail(ErrorCode::kIo, child(p, "uri"), fmt::format("cannot find environment image '{}' ({})", env.uri, size.error().message));
  const std::string projection = string(*ext, "projection", p, "equirectangular");
  if (projection != "equirectangular")
    fail(ErrorCode::kUnsupported, child(p, "projection"), fmt::format("'{}' is not supported (expected equirectangular)", projection));
  env.intensity = static_cast<float>(number(*ext, "intensity", p, 1.0));
  if (!(env.intensity >= 0.0f)) invalid(child(p, "intensity"), "expected a non-negative number");
  addSourceFile(env.file, *size);
  scene_.environment = std::move(env);
}

void GltfReader::readNodes() {
  const json& nodes = array(root_, "nodes", "");
  scene_.nodes.resize(nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto p = child("/nodes", i);
    const json& n = objectAt(nodes, i, "/nodes");
    Node& node = scene_.nodes[i];
    node.name = string(n, "name", p);
    node.mesh = index(n, "mesh", p, scene_.meshes.size(), "mesh");
    node.camera = index(n, "camera", p, scene_.cameras.size(), "camera");
    if (const json* m = member(n, "matrix")) {
      if (!m->is_array() || m->size() != 16) invalid(child(p, "matrix"), "expected an array of 16 numbers");
      glm::dmat4 matrix;
      for (int k = 0; k < 16; ++k) {
        if (!(*m)[k].is_number()) invalid(child(child(p, "matrix"), k), "expected a number");
        matrix[k / 4][k % 4] = (*m)[k].get<double>();  // column-major, as glTF stores it
      }
      node.matrix = matrix;
    }
    node.local.translation = vector<3>(n, "translation", p, glm::dvec3(0.0));
    const glm::dvec4 r = vector<4>(n, "rotation", p, glm::dvec4(0, 0, 0, 1));
    node.local.rotation = glm::dquat(r.w, r.x, r.y, r.z);
    node.local.scale = vector<3>(n, "scale", p, glm::dvec3(1.0));
    node.weights = numberList(n, "weights", p);
    if (const json* lp = extension(n, "KHR_lights_punctual"))
      node.light = index(*lp, "light", child(child(p, "extensions"), "KHR_lights_punctual"), scene_.lights.size(), "light", true);
    if (const json* vis = extension(n, "KHR_node_visibility"))
      node.visible = boolean(*vis, "visible", child(child(p, "extensions"), "KHR_node_visibility"), true);
    if (const json* extras = member(n, "extras"); extras && extras->is_object()) readCameraCuts(*extras, child(p, "extras"), node);
    node.children = indexList(n, "children", p, nodes.size(), "node");
  }
  for (std::size_t i = 0; i < scene_.nodes.size(); ++i) {
    for (std::size_t k = 0; k < scene_.nodes[i].children.size(); ++k) {
      const int c = scene_.nodes[i].children[k];
      auto& childNode = scene_.nodes[static_cast<std::size_t>(c)];
      if (childNode.parent >= 0 || c == static_cast<int>(i))
        invalid(child(child(child("/nodes", i), "children"), k),
                fmt::format("node {} already has a parent; glTF node hierarchies must be trees", c));
      childNode.parent = static_cast<int>(i);
    }
  }
  // A cycle among parented nodes would have no root; walk up from each node to catch it.
  for (std::size_t i = 0; i < scene_.nodes.size(); ++i) {
    int at = static_cast<int>(i);
    for (std::size_t steps = 0; at >= 0; ++steps) {
      if (steps > scene_.nodes.size()) invalid(child("/nodes", i), "is part of a parent cycle");
      at = scene_.nodes[static_cast<std::size_t>(at)].parent;
    }
  }
}

void GltfReader::readSkins() {
  const json& skins = array(root_, "skins", "");
  for (std::size_t i = 0; i < skins.size(); ++i) {
    const auto p = child("/skins", i);
    const json& s = objectAt(skins, i, "/skins");
    Skin skin;
    skin.name = string(s, "name", p);
    skin.skeleton = index(s, "skeleton", p, scene_.nodes.size(), "node");
    skin.joints = indexList(s, "joints", p, scene_.nodes.size(), "node");
    if (skin.joints.empty()) invalid(child(p, "joints"), "a skin needs at least one joint");
    skin.inverseBindMatrices.assign(skin.joints.size(), glm::dmat4(1.0));
    if (int a = index(s, "inverseBindMatrices", p, accessors_.size(), "accessor"); a >= 0) {
      const auto ap = child(p, "inverseBindMatrices");
      requireType(a, ap, {"MAT4"});
      if (accessorAt(a).count < skin.joints.size())
        invalid(ap, fmt::format("accessor {} has {} matrices for {} joints", a, accessorAt(a).count, skin.joints.size()));
      const auto values = readAccessor(a);
      requireFinite(values, 16, ap, "matrix");
      for (std::size_t k = 0; k < skin.joints.size(); ++k)
        for (int e = 0; e < 16; ++e) skin.inverseBindMatrices[k][e / 4][e % 4] = values[k * 16 + static_cast<std::size_t>(e)];
    }
    scene_.skins.push_back(std::move(skin));
  }
  const json& nodes = array(root_, "nodes", "");
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto p = child("/nodes", i);
    scene_.nodes[i].skin = index(nodes[i], "skin", p, scene_.skins.size(), "skin");
    if (scene_.nodes[i].skin >= 0 && scene_.nodes[i].mesh < 0)
      invalid(child(p, "skin"), "a node with a skin must also have a mesh");
  }
}

void GltfReader::readScenes() {
  const json& scenes = array(root_, "scenes", "");
  const int active = index(root_, "scene", "", scenes.size(), "scene");
  if (scenes.empty()) {
    // No scene: show every root node (glTF leaves this to the application).
    for (std::size_t i = 0; i < scene_.nodes.size(); ++i)
      if (scene_.nodes[i].parent < 0) scene_.roots.push_back(static_cast<int>(i));
    return;
  }
  const std::size_t s = active >= 0 ? static_cast<std::size_t>(active) : 0;
  const auto p = child("/scenes", s);
  scene_.roots = indexList(objectAt(scenes, s, "/scenes"), "nodes", p, scene_.nodes.size(), "node");
  for (std::size_t k = 0; k < scene_.roots.size(); ++k)
    if (scene_.nodes[static_cast<std::size_t>(scene_.roots[k])].parent >= 0)
      invalid(child(child(p, "nodes"), k), fmt::format("node {} is not a root node", scene_.roots[k]));
}

// A camera node's extras.dynbench_camera_cuts: [{"from": seconds, "time": seconds, "reason": text},
// ...] in increasing time (docs/dataset.md).
void GltfReader::readCameraCuts(const json& extras, const std::string& p, Node& node) {
  const json& cuts = array(extras, "dynbench_camera_cuts", p);
  const auto cp = child(p, "dynbench_camera_cuts");
  for (std::size_t k = 0; k < cuts.size(); ++k) {
    const json& c = objectAt(cuts, k, cp);
    Node::Cut cut;
    cut.time = number(c, "time", child(cp, k), 0.0, true);
    cut.from = number(c, "from", child(cp, k), cut.time);
    cut.reason = string(c, "reason", child(cp, k));
    if (!std::isfinite(cut.time) || (!node.cuts.empty() && !(cut.time > node.cuts.back().time)))
      invalid(child(child(cp, k), "time"), "expected a finite time greater than the previous cut's");
    if (!std::isfinite(cut.from) || cut.from > cut.time)
      invalid(child(child(cp, k), "from"), fmt::format("expected a finite time not after the cut's time {}", cut.time));
    node.cuts.push_back(std::move(cut));
  }
}

// Parses "/nodes/N/extensions/KHR_node_visibility/visible"; -1 for any other pointer.
int GltfReader::visibilityPointerNode(const std::string& pointer) {
  static constexpr std::string_view prefix = "/nodes/";
  static constexpr std::string_view suffix = "/extensions/KHR_node_visibility/visible";
  if (!pointer.starts_with(prefix) || !pointer.ends_with(suffix)) return -1;
  const auto digits = pointer.substr(prefix.size(), pointer.size() - prefix.size() - suffix.size());
  if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), ::isdigit)) return -1;
  return std::stoi(digits);
}

// Parses "/extensions/KHR_lights_punctual/lights/N/color" (or /intensity, /range): the light and the
// property; light -1 for any other pointer.
GltfReader::LightPointer GltfReader::lightPointer(const std::string& pointer) {
  static constexpr std::string_view prefix = "/extensions/KHR_lights_punctual/lights/";
  if (!pointer.starts_with(prefix)) return {};
  const auto rest = pointer.substr(prefix.size());
  const auto slash = rest.find('/');
  if (slash == std::string::npos) return {};
  const auto digits = rest.substr(0, slash), property = rest.substr(slash + 1);
  if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), ::isdigit)) return {};
  if (property == "color") return {std::stoi(digits), AnimationPath::kLightColor};
  if (property == "intensity") return {std::stoi(digits), AnimationPath::kLightIntensity};
  if (property == "range") return {std::stoi(digits), AnimationPath::kLightRange};
  return {};
}

void GltfReader::readAnimations() {
  const json& animations = array(root_, "animations", "");
  for (std::size_t i = 0; i < animations.size(); ++i) {
    const auto p = child("/animations", i);
    const json& an = objectAt(animations, i, "/animations");
    Animation animation;
    animation.name = string(an, "name", p);
    const json& samplers = array(an, "samplers", p);
    const json& channels = array(an, "channels", p);
    // Channels first: a sampler's expected output width depends on what it drives.
    std::vector<int> samplerComponents(samplers.size(), 0);
    std::vector<std::string> samplerUse(samplers.size());
    for (std::size_t c = 0; c < channels.size(); ++c) {
      const auto cp = child(child(p, "channels"), c);
      const json& ch = objectAt(channels, c, child(p, "channels"));
      Channel channel;
      channel.sampler = index(ch, "sampler", cp, samplers.size(), "sampler", true);
      const json* target = member(ch, "target");
      if (!target || !target->is_object()) invalid(child(cp, "target"), "missing; expected an object");
      const auto tp = child(cp, "target");
      const std::string path = string(*target, "path", tp);
      int components = 0;
      if (path == "pointer") {
        const json* ptr = extension(*target, "KHR_animation_pointer");
        const std::string pointer = ptr ? string(*ptr, "pointer", child(child(tp, "extensions"), "KHR_animation_pointer")) : "";
        const int node = visibilityPointerNode(pointer);
        const LightPointer light = lightPointer(pointer);
        if (node < 0 && light.light < 0) {
          scene_.warnings.push_back(fmt::format("{}: {}: animation pointer '{}' is ignored (dynbench animates only "
                                                "node transforms, morph weights, KHR_node_visibility and KHR_lights_punctual "
                                                "colour and intensity)", display_, cp, pointer));
          continue;
        }
        if (node >= 0) {
          if (static_cast<std::size_t>(node) >= scene_.nodes.size())
            invalid(tp, fmt::format("pointer '{}' names node {} but the file has {} nodes", pointer, node, scene_.nodes.size()));
          channel.node = node;
          channel.path = AnimationPath::kVisibility;
          components = 1;
        } else {
          if (static_cast<std::size_t>(light.light) >= scene_.lights.size())
            invalid(tp, fmt::format("pointer '{}' names light {} but the file has {} lights", pointer, light.light, scene_.lights.size()));
          channel.light = light.light;
          channel.path = light.path;
          components = light.path == AnimationPath::kLightColor ? 3 : 1;
        }
      } else {
        channel.node = index(*target, "node", tp, scene_.nodes.size(), "node");
        if (channel.node < 0) continue;  // glTF: a channel without a node is ignored
        if (path == "translation") { channel.path = AnimationPath::kTranslation; components = 3; }
        else if (path == "rotation") { channel.path = AnimationPath::kRotation; components = 4; }
        else if (path == "scale") { channel.path = AnimationPath::kScale; components = 3; }
        else if (path == "weights") {
          channel.path = AnimationPath::kWeights;
          const int mesh = scene_.nodes[static_cast<std::size_t>(channel.node)].mesh;
          components = mesh >= 0 ? static_cast<int>(scene_.meshes[static_cast<std::size_t>(mesh)].morphTargetCount()) : 0;
          if (components == 0)
            invalid(child(tp, "node"), fmt::format("weights are animated but node {} has no mesh with morph targets", channel.node));
        } else {
          invalid(child(tp, "path"), fmt::format("'{}' is not translation, rotation, scale, weights or pointer", path));
        }
        if (channel.path != AnimationPath::kWeights && scene_.nodes[static_cast<std::size_t>(channel.node)].matrix)
          invalid(child(tp, "node"), fmt::format("node {} has a matrix; glTF forbids animating its TRS", channel.node));
      }
      auto& expected = samplerComponents[static_cast<std::size_t>(channel.sampler)];
      if (expected != 0 && expected != components)
        invalid(child(cp, "sampler"), fmt::format("sampler {} drives targets of different widths", channel.sampler));
      expected = components;
      samplerUse[static_cast<std::size_t>(channel.sampler)] = path;
      animation.channels.push_back(channel);
    }
    for (std::size_t s = 0; s < samplers.size(); ++s)
      animation.samplers.push_back(readSampler(objectAt(samplers, s, child(p, "samplers")),
                                               child(child(p, "samplers"), s), samplerComponents[s], samplerUse[s]));
    scene_.animations.push_back(std::move(animation));
  }
}

Sampler GltfReader::readSampler(const json& s, const std::string& p, int components, const std::string& use) {
  Sampler sampler;
  sampler.components = components;
  const std::string interpolation = string(s, "interpolation", p, "LINEAR");
  if (interpolation == "LINEAR") sampler.interpolation = Interpolation::kLinear;
  else if (interpolation == "STEP") sampler.interpolation = Interpolation::kStep;
  else if (interpolation == "CUBICSPLINE") sampler.interpolation = Interpolation::kCubicSpline;
  else invalid(child(p, "interpolation"), fmt::format("'{}' is not LINEAR, STEP or CUBICSPLINE", interpolation));
  const int input = index(s, "input", p, accessors_.size(), "accessor", true);
  const int output = index(s, "output", p, accessors_.size(), "accessor", true);
  const auto ip = child(p, "input"), op = child(p, "output");
  requireType(input, ip, {"SCALAR"});
  if (accessorAt(input).componentType != 5126) invalid(ip, fmt::format("accessor {}: key times must be floats", input));
  const auto times = readAccessor(input);
  requireFinite(times, 1, ip, "key time");
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (times[k] < 0) invalid(ip, fmt::format("key time {} is {}; times must not be negative", k, times[k]));
    if (k > 0 && !(times[k] > times[k - 1]))
      invalid(ip, fmt::format("key time {} ({}) is not greater than key time {} ({}); times must be strictly increasing",
                              k, times[k], k - 1, times[k - 1]));
  }
  if (components == 0) return sampler;  // sampler unused by any channel dynbench understands
  const std::size_t keys = times.size();
  if (sampler.interpolation == Interpolation::kCubicSpline && keys < 2)
    invalid(child(p, "interpolation"), "CUBICSPLINE needs at least two keys");
  const std::size_t perKey = static_cast<std::size_t>(components) * (sampler.interpolation == Interpolation::kCubicSpline ? 3 : 1);
  const auto& out = accessorAt(output);
  const auto values = readAccessor(output);
  if (values.size() != keys * perKey)
    invalid(op, fmt::format("accessor {} has {} values ({} x {}) but {} keys of {} need {}", output, values.size(),
                            out.count, out.type, keys, use, keys * perKey));
  requireFinite(values, static_cast<int>(perKey), op, "keyframe value at key");
  sampler.times.assign(times.begin(), times.end());
  sampler.values.assign(values.begin(), values.end());
  return sampler;
}
}  // namespace dynbench::scene::gltf_detail
