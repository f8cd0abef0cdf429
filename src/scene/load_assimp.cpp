// FBX, COLLADA, OBJ and every other format assimp reads, mapped onto the glTF-shaped scene model.
// This is the only translation unit that includes assimp.
#include <algorithm>
#include <map>
#include <memory>
#include <set>

#include <glm/gtx/quaternion.hpp>

#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "core/files.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

namespace fs = std::filesystem;

// Records every file assimp opens (the model, .mtl libraries, external buffers) so that the
// dataset's size on disk counts everything it references.
class RecordingIOSystem : public Assimp::DefaultIOSystem {
 public:
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    Assimp::IOStream* stream = Assimp::DefaultIOSystem::Open(file, mode);
    if (stream) opened.insert(fs::path(file).lexically_normal());
    return stream;
  }
  std::set<fs::path> opened;
};

glm::dmat4 toGlm(const aiMatrix4x4& m) {
  // assimp is row-major (a1..a4 is the first row); glm is column-major.
  return glm::dmat4(m.a1, m.b1, m.c1, m.d1, m.a2, m.b2, m.c2, m.d2, m.a3, m.b3, m.c3, m.d3, m.a4, m.b4, m.c4, m.d4);
}

glm::dvec3 toGlm(const aiVector3D& v) { return {v.x, v.y, v.z}; }

// A frame whose -Z looks along `look` with +Y along `up` at `position`: how assimp's camera and
// light directions become glTF's convention (cameras look down -Z, lights shine down -Z).
std::optional<glm::dmat4> viewFrame(const aiVector3D& position, const aiVector3D& look, const aiVector3D& up) {
  glm::dvec3 z = -toGlm(look);
  glm::dvec3 y = toGlm(up);
  if (glm::length(z) == 0.0) z = {0, 0, 1};
  if (glm::length(y) == 0.0) y = {0, 1, 0};
  z = glm::normalize(z);
  glm::dvec3 x = glm::cross(y, z);
  if (glm::length(x) < 1e-12) x = glm::cross(glm::dvec3(0, 0, 1), z);  // up parallel to look
  x = glm::normalize(x);
  y = glm::cross(z, x);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(x, 0);
  m[1] = glm::dvec4(y, 0);
  m[2] = glm::dvec4(z, 0);
  m[3] = glm::dvec4(toGlm(position), 1);
  if (m == glm::dmat4(1.0)) return std::nullopt;
  return m;
}

// The workflow a material was authored in. assimp maps every importer onto its own keys, and its
// FBX importer derives a roughness factor even for Phong materials, so only explicit PBR signals
// count: glTF-style factors, PBR texture slots, and the raw parameters of 3ds Max / Maya PBR
// materials ("...|glossiness" with useGlossiness set means specular-glossiness).
MaterialWorkflow detectWorkflow(const aiMaterial& material) {
  float value = 0;
  if (material.Get(AI_MATKEY_GLOSSINESS_FACTOR, value) == AI_SUCCESS) return MaterialWorkflow::kSpecularGlossiness;
  bool rawGlossiness = false, rawMetalRough = false;
  int useGlossiness = -1;
  for (unsigned i = 0; i < material.mNumProperties; ++i) {
    const std::string rawKey = material.mProperties[i]->mKey.C_Str();
    if (!rawKey.starts_with("$raw.")) continue;
    const std::string key = asciiLowercase(rawKey);
    if (key.ends_with("|useglossiness")) material.Get(material.mProperties[i]->mKey.C_Str(), 0, 0, useGlossiness);
    else if (key.ends_with("|glossiness")) rawGlossiness = true;
    else if (key.ends_with("|roughness") || key.ends_with("|metalness") || key.ends_with("|metallic")) rawMetalRough = true;
  }
  if (useGlossiness == 1 || (rawGlossiness && !rawMetalRough)) return MaterialWorkflow::kSpecularGlossiness;
  if (useGlossiness == 0 || rawMetalRough) return MaterialWorkflow::kMetallicRoughness;
  int shading = 0;
  if ((material.Get(AI_MATKEY_SHADING_MODEL, shading) == AI_SUCCESS && shading == aiShadingMode_PBR_BRDF) ||
      material.Get(AI_MATKEY_METALLIC_FACTOR, value) == AI_SUCCESS ||
      material.GetTextureCount(aiTextureType_METALNESS) > 0 || material.GetTextureCount(aiTextureType_DIFFUSE_ROUGHNESS) > 0 ||
      material.GetTextureCount(aiTextureType_BASE_COLOR) > 0)
    return MaterialWorkflow::kMetallicRoughness;
  return MaterialWorkflow::kPhongOrOther;
}

class AssimpConverter {
 public:
  AssimpConverter(const aiScene& ai, const fs::path& path, Scene& scene) : ai_(ai), path_(path), scene_(scene) {}

  void convert() {
    convertImagesAndMaterials();
    convertLights();
    convertCameras();
    // Z-up FBX files (3ds Max, some Maya exports) are turned to +Y up, as glTF and our Euler
    // convention expect. COLLADA's up axis is already handled by assimp.
    int upAxis = 1, upSign = 1;
    if (ai_.mMetaData) {
      ai_.mMetaData->Get("UpAxis", upAxis);
      ai_.mMetaData->Get("UpAxisSign", upSign);
    }
    int parent = -1;
    if (upAxis == 2 || upAxis == 0 || upSign < 0) {
      Node axes;
      axes.name = "dynbench_y_up";
      // Rotation taking the file's up vector to +Y.
      glm::dvec3 up(0.0);
      up[upAxis] = upSign < 0 ? -1.0 : 1.0;
      const glm::dquat q = glm::rotation(up, glm::dvec3(0, 1, 0));
      axes.local.rotation = q;
      scene_.nodes.push_back(axes);
      parent = 0;
      scene_.roots.push_back(0);
    }
    const int root = convertNode(*ai_.mRootNode, parent);
    if (parent < 0) scene_.roots.push_back(root);
    else scene_.nodes[0].children.push_back(root);
    convertSkins();
    convertAnimations();
  }

 private:
  void convertImagesAndMaterials() {
    std::map<std::string, int> imageByKey;
    for (unsigned m = 0; m < ai_.mNumMaterials; ++m) {
      const aiMaterial& am = *ai_.mMaterials[m];
      Material material;
      material.name = am.GetName().C_Str();
      material.workflow = detectWorkflow(am);
      aiColor4D color;
      if (am.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS || am.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS)
        material.baseColorFactor = {color.r, color.g, color.b, color.a};
      for (int type = aiTextureType_DIFFUSE; type <= AI_TEXTURE_TYPE_MAX; ++type) {
        const auto textureType = static_cast<aiTextureType>(type);
        for (unsigned k = 0; k < am.GetTextureCount(textureType); ++k) {
          aiString texturePath;
          if (am.GetTexture(textureType, k, &texturePath) != AI_SUCCESS) continue;
          const std::string key = texturePath.C_Str();
          auto it = imageByKey.find(key);
          int image = it == imageByKey.end() ? -1 : it->second;
          if (image < 0) {
            image = static_cast<int>(scene_.images.size());
            scene_.images.push_back(makeImage(key));
            imageByKey[key] = image;
          }
          if (std::find(material.images.begin(), material.images.end(), image) == material.images.end())
            material.images.push_back(image);
          if (k == 0 && (textureType == aiTextureType_DIFFUSE || textureType == aiTextureType_BASE_COLOR) &&
              material.baseColorTexture.image < 0)
            material.baseColorTexture.image = image;
          if (k == 0 && (textureType == aiTextureType_NORMALS || textureType == aiTextureType_NORMAL_CAMERA))
            material.normalTexture.image = image;
          if (k == 0 && textureType == aiTextureType_EMISSIVE) material.emissiveTexture.image = image;
        }
      }
      scene_.materials.push_back(std::move(material));
    }
  }

  Image makeImage(const std::string& reference) {
    Image image;
    image.uri = reference;
    if (const aiTexture* embedded = ai_.GetEmbeddedTexture(reference.c_str())) {
      image.embedded = true;
      // mHeight == 0: a compressed file of mWidth bytes; otherwise raw ARGB8888 texels.
      image.bytes = embedded->mHeight == 0 ? embedded->mWidth : std::uint64_t{embedded->mWidth} * embedded->mHeight * 4;
      return image;
    }
    // Exporters often write the author's absolute path; look beside the model as well.
    const fs::path base = path_.parent_path();
    std::string normalized = reference;
    std::replace(normalized.begin(), normalized.end(), '\\', '/');
    for (const fs::path& candidate : {base / normalized, base / fs::path(normalized).filename()}) {
      if (auto size = fileSize(candidate)) {
        image.file = candidate.lexically_normal();
        image.bytes = *size;
        addSourceFile(image.file, image.bytes);
        return image;
      }
    }
    scene_.warnings.push_back(fmt::format("{}: texture '{}' not found beside the model; counted with size 0",
                                          path_.string(), reference));
    return image;
  }

  void addSourceFile(const fs::path& p, std::uint64_t bytes) {
    for (const auto& f : scene_.source.files)
      if (f.path == p) return;
    scene_.source.files.push_back({p, bytes});
  }

  void convertLights() {
    for (unsigned i = 0; i < ai_.mNumLights; ++i) {
      const aiLight& al = *ai_.mLights[i];
      Light light;
      light.name = al.mName.C_Str();
      switch (al.mType) {
        case aiLightSource_SPOT: light.type = Light::Type::kSpot; break;
        case aiLightSource_DIRECTIONAL: light.type = Light::Type::kDirectional; break;
        default: light.type = Light::Type::kPoint; break;  // point, ambient, area: counted as points
      }
      const glm::vec3 c(al.mColorDiffuse.r, al.mColorDiffuse.g, al.mColorDiffuse.b);
      // assimp folds intensity into the colour; split it back so that colour is in [0, 1].
      light.intensity = std::max({c.r, c.g, c.b, 0.0f});
      light.color = light.intensity > 0 ? c / light.intensity : glm::vec3(1.0f);
      light.innerConeAngle = al.mAngleInnerCone;
      light.outerConeAngle = al.mAngleOuterCone;
      lightFrames_[light.name] = viewFrame(al.mPosition, al.mDirection, al.mUp);
      scene_.lights.push_back(std::move(light));
    }
  }

  void convertCameras() {
    for (unsigned i = 0; i < ai_.mNumCameras; ++i) {
      const aiCamera& ac = *ai_.mCameras[i];
      Camera camera;
      camera.name = ac.mName.C_Str();
      if (ac.mOrthographicWidth > 0) {
        camera.type = Camera::Type::kOrthographic;
        camera.xmag = ac.mOrthographicWidth;
        camera.ymag = ac.mAspect > 0 ? ac.mOrthographicWidth / ac.mAspect : ac.mOrthographicWidth;
      }
      // assimp's mHorizontalFOV is half the horizontal angle.
      camera.aspectRatio = ac.mAspect;
      const double aspect = ac.mAspect > 0 ? ac.mAspect : 1.0;
      camera.yfov = 2.0 * std::atan(std::tan(static_cast<double>(ac.mHorizontalFOV)) / aspect);
      camera.znear = ac.mClipPlaneNear;
      camera.zfar = ac.mClipPlaneFar;
      cameraFrames_[camera.name] = viewFrame(ac.mPosition, ac.mLookAt, ac.mUp);
      scene_.cameras.push_back(std::move(camera));
    }
  }

  int addNode(Node node, int parent) {
    const int index = static_cast<int>(scene_.nodes.size());
    node.parent = parent;
    scene_.nodes.push_back(std::move(node));
    if (parent >= 0) scene_.nodes[static_cast<std::size_t>(parent)].children.push_back(index);
    return index;
  }

  // Attaches a camera or light, through a child node when assimp gives it its own frame.
  void attach(int node, const std::optional<glm::dmat4>& frame, int Node::*slot, int value, const std::string& name) {
    if (!frame) {
      scene_.nodes[static_cast<std::size_t>(node)].*slot = value;
      return;
    }
    Node child;
    child.name = name;  // the frame node carries the name users know the camera or light by
    child.matrix = *frame;
    child.*slot = value;
    addNode(std::move(child), node);
  }

  int convertNode(const aiNode& an, int parent) {
    Node node;
    node.name = an.mName.C_Str();
    const glm::dmat4 m = toGlm(an.mTransformation);
    // Keep TRS (animatable); assimp's decomposition handles the affine matrices files contain.
    aiVector3D s, t;
    aiQuaternion r;
    an.mTransformation.Decompose(s, r, t);
    node.local.translation = toGlm(t);
    node.local.rotation = glm::dquat(r.w, r.x, r.y, r.z);
    node.local.scale = toGlm(s);
    if (glm::length(glm::dvec4(node.local.matrix()[0] - m[0])) + glm::length(glm::dvec4(node.local.matrix()[1] - m[1])) +
            glm::length(glm::dvec4(node.local.matrix()[2] - m[2])) > 1e-6 * (1 + glm::length(glm::dvec3(m[0]))))
      node.matrix = m;  // shear: not representable as TRS
    const int index = addNode(std::move(node), parent);
    nodeByName_.emplace(an.mName.C_Str(), index);
    if (an.mNumMeshes > 0) {
      std::vector<unsigned> meshes(an.mMeshes, an.mMeshes + an.mNumMeshes);
      scene_.nodes[static_cast<std::size_t>(index)].mesh = meshFor(meshes);
      meshNodes_.push_back({index, meshes});
    }
    for (unsigned i = 0; i < ai_.mNumCameras; ++i)
      if (an.mName == ai_.mCameras[i]->mName)
        attach(index, cameraFrames_[ai_.mCameras[i]->mName.C_Str()], &Node::camera, static_cast<int>(i), an.mName.C_Str());
    for (unsigned i = 0; i < ai_.mNumLights; ++i)
      if (an.mName == ai_.mLights[i]->mName)
        attach(index, lightFrames_[ai_.mLights[i]->mName.C_Str()], &Node::light, static_cast<int>(i), an.mName.C_Str());
    for (unsigned c = 0; c < an.mNumChildren; ++c) convertNode(*an.mChildren[c], index);
    return index;
  }

  int meshFor(const std::vector<unsigned>& aiMeshes) {
    if (auto it = meshBySet_.find(aiMeshes); it != meshBySet_.end()) return it->second;
    Mesh mesh;
    for (unsigned i : aiMeshes) {
      const aiMesh& am = *ai_.mMeshes[i];
      if (mesh.name.empty()) mesh.name = am.mName.C_Str();
      Primitive prim;
      prim.material = static_cast<int>(am.mMaterialIndex);
      prim.positions.resize(am.mNumVertices);
      for (unsigned v = 0; v < am.mNumVertices; ++v) prim.positions[v] = {am.mVertices[v].x, am.mVertices[v].y, am.mVertices[v].z};
      if (am.mNormals) {
        prim.normals.resize(am.mNumVertices);
        for (unsigned v = 0; v < am.mNumVertices; ++v) prim.normals[v] = {am.mNormals[v].x, am.mNormals[v].y, am.mNormals[v].z};
      }
      if (am.mTextureCoords[0]) {
        prim.uvs.resize(am.mNumVertices);
        for (unsigned v = 0; v < am.mNumVertices; ++v) prim.uvs[v] = {am.mTextureCoords[0][v].x, am.mTextureCoords[0][v].y};
      }
      prim.mode = (am.mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON)) ? PrimitiveMode::kTriangles
                  : (am.mPrimitiveTypes & aiPrimitiveType_LINE)                               ? PrimitiveMode::kLines
                                                                                              : PrimitiveMode::kPoints;
      for (unsigned f = 0; f < am.mNumFaces; ++f) {
        const aiFace& face = am.mFaces[f];
        if (prim.mode == PrimitiveMode::kTriangles && face.mNumIndices != 3) continue;
        prim.indices.insert(prim.indices.end(), face.mIndices, face.mIndices + face.mNumIndices);
      }
      for (unsigned a = 0; a < am.mNumAnimMeshes; ++a) {
        const aiAnimMesh& anim = *am.mAnimMeshes[a];
        MorphTarget target;
        if (anim.mVertices) {
          target.positionDeltas.resize(am.mNumVertices);
          for (unsigned v = 0; v < am.mNumVertices; ++v)
            target.positionDeltas[v] = glm::vec3(anim.mVertices[v].x, anim.mVertices[v].y, anim.mVertices[v].z) - prim.positions[v];
        }
        if (anim.mNormals && am.mNormals) {
          target.normalDeltas.resize(am.mNumVertices);
          for (unsigned v = 0; v < am.mNumVertices; ++v)
            target.normalDeltas[v] = glm::vec3(anim.mNormals[v].x, anim.mNormals[v].y, anim.mNormals[v].z) - prim.normals[v];
        }
        prim.targets.push_back(std::move(target));
      }
      mesh.primitives.push_back(std::move(prim));
    }
    mesh.defaultWeights.assign(mesh.morphTargetCount(), 0.0f);
    const int index = static_cast<int>(scene_.meshes.size());
    scene_.meshes.push_back(std::move(mesh));
    meshBySet_[aiMeshes] = index;
    return index;
  }

  // One skin per mesh node whose meshes have bones: the union of their bones, with glTF-style
  // JOINTS_0/WEIGHTS_0 holding each vertex's four strongest influences, renormalised.
  void convertSkins() {
    for (const auto& [nodeIndex, aiMeshes] : meshNodes_) {
      bool anyBones = false;
      for (unsigned i : aiMeshes) anyBones |= ai_.mMeshes[i]->mNumBones > 0;
      if (!anyBones) continue;
      Skin skin;
      skin.name = scene_.nodes[static_cast<std::size_t>(nodeIndex)].name;
      std::map<std::string, int> jointByName;
      // A shared mesh may be instanced by several nodes; skinned meshes get their own copy here.
      Mesh mesh = scene_.meshes[static_cast<std::size_t>(scene_.nodes[static_cast<std::size_t>(nodeIndex)].mesh)];
      for (std::size_t p = 0; p < aiMeshes.size(); ++p) {
        const aiMesh& am = *ai_.mMeshes[aiMeshes[p]];
        std::vector<std::vector<std::pair<float, int>>> influences(am.mNumVertices);
        for (unsigned b = 0; b < am.mNumBones; ++b) {
          const aiBone& bone = *am.mBones[b];
          auto node = nodeByName_.find(bone.mName.C_Str());
          if (node == nodeByName_.end()) {
            scene_.warnings.push_back(fmt::format("{}: bone '{}' names no node; its weights are dropped", path_.string(), bone.mName.C_Str()));
            continue;
          }
          auto [it, inserted] = jointByName.emplace(bone.mName.C_Str(), static_cast<int>(skin.joints.size()));
          if (inserted) {
            skin.joints.push_back(node->second);
            skin.inverseBindMatrices.push_back(toGlm(bone.mOffsetMatrix));
          }
          for (unsigned w = 0; w < bone.mNumWeights; ++w)
            if (bone.mWeights[w].mVertexId < am.mNumVertices)
              influences[bone.mWeights[w].mVertexId].push_back({bone.mWeights[w].mWeight, it->second});
        }
        Primitive& prim = mesh.primitives[p];
        prim.joints.assign(am.mNumVertices, glm::u16vec4(0));
        prim.weights.assign(am.mNumVertices, glm::vec4(0.0f));
        for (unsigned v = 0; v < am.mNumVertices; ++v) {
          auto& list = influences[v];
          std::sort(list.begin(), list.end(), [](auto& a, auto& b) { return a.first > b.first; });
          float sum = 0;
          for (std::size_t k = 0; k < std::min<std::size_t>(4, list.size()); ++k) sum += list[k].first;
          for (std::size_t k = 0; k < std::min<std::size_t>(4, list.size()); ++k) {
            prim.joints[v][static_cast<int>(k)] = static_cast<std::uint16_t>(list[k].second);
            prim.weights[v][static_cast<int>(k)] = sum > 0 ? list[k].first / sum : 0.0f;
          }
        }
      }
      if (skin.joints.empty()) continue;
      auto& node = scene_.nodes[static_cast<std::size_t>(nodeIndex)];
      node.mesh = static_cast<int>(scene_.meshes.size());
      scene_.meshes.push_back(std::move(mesh));
      node.skin = static_cast<int>(scene_.skins.size());
      scene_.skins.push_back(std::move(skin));
    }
  }

  // Keys as a strictly increasing sampler; duplicate times (assimp emits some) keep the last key.
  template <typename Key, typename Write>
  void appendKeys(Sampler& sampler, const Key* keys, unsigned count, double ticksPerSecond, Write write) {
    for (unsigned k = 0; k < count; ++k) {
      const auto t = static_cast<float>(keys[k].mTime / ticksPerSecond);
      if (!sampler.times.empty() && t <= sampler.times.back()) {
        if (t < sampler.times.back()) continue;  // out of order: dropped
        sampler.times.pop_back();
        sampler.values.resize(sampler.values.size() - static_cast<std::size_t>(sampler.components));
      }
      sampler.times.push_back(t);
      write(keys[k], sampler.values);
    }
  }

  void convertAnimations() {
    for (unsigned a = 0; a < ai_.mNumAnimations; ++a) {
      const aiAnimation& aa = *ai_.mAnimations[a];
      Animation animation;
      animation.name = aa.mName.C_Str();
      double tps = aa.mTicksPerSecond;
      if (tps <= 0) {
        tps = 25.0;  // assimp's documented default when a file gives no rate
        scene_.warnings.push_back(fmt::format("{}: animation '{}' gives no ticks per second; assuming 25",
                                              path_.string(), animation.name));
      }
      auto addSampler = [&](Sampler sampler, int node, AnimationPath path) {
        if (sampler.times.empty()) return;
        animation.channels.push_back({static_cast<int>(animation.samplers.size()), node, path});
        animation.samplers.push_back(std::move(sampler));
      };
      for (unsigned c = 0; c < aa.mNumChannels; ++c) {
        const aiNodeAnim& ch = *aa.mChannels[c];
        auto node = nodeByName_.find(ch.mNodeName.C_Str());
        if (node == nodeByName_.end()) {
          scene_.warnings.push_back(fmt::format("{}: animation channel for unknown node '{}' ignored", path_.string(), ch.mNodeName.C_Str()));
          continue;
        }
        auto& n = scene_.nodes[static_cast<std::size_t>(node->second)];
        n.matrix.reset();  // animated nodes are TRS by definition
        Sampler t{Interpolation::kLinear, {}, {}, 3}, r{Interpolation::kLinear, {}, {}, 4}, s{Interpolation::kLinear, {}, {}, 3};
        appendKeys(t, ch.mPositionKeys, ch.mNumPositionKeys, tps,
                   [](const aiVectorKey& k, std::vector<float>& v) { v.insert(v.end(), {k.mValue.x, k.mValue.y, k.mValue.z}); });
        appendKeys(r, ch.mRotationKeys, ch.mNumRotationKeys, tps, [](const aiQuatKey& k, std::vector<float>& v) {
          v.insert(v.end(), {k.mValue.x, k.mValue.y, k.mValue.z, k.mValue.w});
        });
        appendKeys(s, ch.mScalingKeys, ch.mNumScalingKeys, tps,
                   [](const aiVectorKey& k, std::vector<float>& v) { v.insert(v.end(), {k.mValue.x, k.mValue.y, k.mValue.z}); });
        addSampler(std::move(t), node->second, AnimationPath::kTranslation);
        addSampler(std::move(r), node->second, AnimationPath::kRotation);
        addSampler(std::move(s), node->second, AnimationPath::kScale);
      }
      for (unsigned c = 0; c < aa.mNumMorphMeshChannels; ++c) {
        const aiMeshMorphAnim& ch = *aa.mMorphMeshChannels[c];
        // glTF-style importers name the node; strip assimp's "*N" mesh suffix if present.
        std::string name = ch.mName.C_Str();
        if (auto star = name.find('*'); star != std::string::npos) name.resize(star);
        auto node = nodeByName_.find(name);
        if (node == nodeByName_.end() || scene_.nodes[static_cast<std::size_t>(node->second)].mesh < 0) {
          scene_.warnings.push_back(fmt::format("{}: morph channel '{}' names no mesh node; ignored", path_.string(), ch.mName.C_Str()));
          continue;
        }
        const int targets = static_cast<int>(
            scene_.meshes[static_cast<std::size_t>(scene_.nodes[static_cast<std::size_t>(node->second)].mesh)].morphTargetCount());
        if (targets == 0) continue;
        Sampler w{Interpolation::kLinear, {}, {}, targets};
        appendKeys(w, ch.mKeys, ch.mNumKeys, tps, [targets](const aiMeshMorphKey& k, std::vector<float>& v) {
          const std::size_t start = v.size();
          v.resize(start + static_cast<std::size_t>(targets), 0.0f);
          for (unsigned i = 0; i < k.mNumValuesAndWeights; ++i)
            if (k.mValues[i] < static_cast<unsigned>(targets)) v[start + k.mValues[i]] = static_cast<float>(k.mWeights[i]);
        });
        addSampler(std::move(w), node->second, AnimationPath::kWeights);
      }
      scene_.animations.push_back(std::move(animation));
    }
  }

  const aiScene& ai_;
  fs::path path_;
  Scene& scene_;
  std::map<std::string, int> nodeByName_;
  std::map<std::vector<unsigned>, int> meshBySet_;
  std::vector<std::pair<int, std::vector<unsigned>>> meshNodes_;
  std::map<std::string, std::optional<glm::dmat4>> cameraFrames_, lightFrames_;
};

std::string formatName(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::toupper(c); });
  if (ext == ".DAE") return "COLLADA";
  if (ext == ".FBX") return "FBX";
  if (ext == ".OBJ") return "Wavefront OBJ";
  return ext.empty() ? "unknown" : ext.substr(1);
}

}  // namespace

Expected<Scene> loadWithAssimp(const std::filesystem::path& path) {
  Assimp::Importer importer;
  auto* io = new RecordingIOSystem;  // owned and deleted by the importer
  importer.SetIOHandler(io);
  // No vertex welding: an OBJ sequence relies on every frame keeping assimp's vertex order.
  const aiScene* ai = importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_SortByPType |
                                                           aiProcess_ValidateDataStructure);
  if (!ai || !ai->mRootNode)
    return fail(ErrorCode::kParse, "{}: cannot import: {}", path.string(), importer.GetErrorString());
  Scene scene;
  scene.source.path = path;
  scene.source.format = formatName(path);
  auto mainSize = fileSize(path);
  if (!mainSize) return std::unexpected(mainSize.error());
  scene.source.files.push_back({path.lexically_normal(), *mainSize});
  for (const auto& opened : io->opened) {
    if (opened == path.lexically_normal()) continue;
    if (auto size = fileSize(opened)) scene.source.files.push_back({opened, *size});
  }
  AssimpConverter(*ai, path, scene).convert();
  return scene;
}

}  // namespace dynbench::scene
