#include "convert/convert.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <set>

#include <fcntl.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "capture/reader.h"
#include "convert/gltf_writer.h"
#include "core/files.h"
#include "core/image_io.h"
#include "core/math.h"
#include "dynbench/version.h"

namespace dynbench::convert {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace dynbench::capture;

enum class Kind { kCamera, kStaticModel, kModel, kLight };

// One capturable: what pass 1 learns, the buffer layout, and pass 2's running state.
struct Track {
  std::uint64_t id = 0;
  Kind kind = Kind::kModel;
  int model = -1;
  bool skinned = false;
  int extraFrames = 0;  // lights kept on after their last record (flash rule)
  // Life span and visibility (pass 1 counts, pass 2 writes).
  bool appeared = false, visible = false;
  std::size_t first = 0, lastPresent = 0, lastSpan = 0;
  std::size_t visibilityKeys = 0;
  std::size_t lastKeyFrame = 0;  // frame of the last visibility key
  // Static records and light properties (from the first record).
  DualQuaternion staticPose;
  LightRecord light;
  // Layout.
  int node = -1;
  std::uint64_t translationOffset = 0, rotationOffset = 0, visTimeOffset = 0, visValueOffset = 0, scaleOffset = 0;
  std::vector<std::uint64_t> jointTranslationOffsets, jointRotationOffsets;
  // Pass 2.
  RegionWriter translation, rotation, visTime, visValue, scale;
  std::vector<RegionWriter> jointTranslation, jointRotation;
  glm::dvec3 heldTranslation{0.0};
  glm::dquat heldRotation{1, 0, 0, 0};
  std::vector<glm::dvec3> heldJointTranslation;
  std::vector<glm::dquat> heldJointRotation;
  glm::dquat lastRotation{1, 0, 0, 0};  // the last rotation key written, for the shortest arc
  std::vector<glm::dquat> lastJointRotation;
  bool hasVisibilityChannel() const { return visibilityKeys > 1; }
  std::size_t span() const { return lastSpan - first + 1; }
  bool animated() const { return kind == Kind::kCamera || kind == Kind::kModel || (kind == Kind::kLight && light.dynamic); }
};

const char* kindName(Kind kind) {
  switch (kind) {
    case Kind::kCamera: return "camera";
    case Kind::kStaticModel: return "static";
    case Kind::kModel: return "model";
    case Kind::kLight: return "light";
  }
  return "?";
}

std::vector<float> quat(const glm::dquat& q) {
  return {static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z), static_cast<float>(q.w)};
}
std::vector<float> vec(const glm::dvec3& v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }

// Keeps consecutive rotation keys on the shortest arc (q and -q are the same rotation; LINEAR
// interpolation between keys of opposite sign would spin the long way round).
glm::dquat nearest(const glm::dquat& previous, glm::dquat q) {
  if (glm::dot(previous, q) < 0.0) q = -q;
  return q;
}

class Converter {
 public:
  explicit Converter(const ConvertOptions& options) : options_(options) {}

  ConvertReport run() {
    auto opened = CaptureReader::open(options_.capture);
    if (!opened) throw Failure{Error{opened.error().code, opened.error().message}};
    reader_ = std::move(*opened);
    const fs::path out = options_.output;
    stem_ = out.stem().string();
    outDir_ = out.has_parent_path() ? out.parent_path() : fs::path(".");
    std::error_code ec;
    fs::create_directories(outDir_, ec);
    if (ec) throw Failure{Error{ErrorCode::kIo, fmt::format("{}: cannot create folder: {}", outDir_.string(), ec.message())}};

    passOne();
    if (times_.empty()) throw Failure{Error{ErrorCode::kInvalidData, fmt::format("{}: the capture has no complete frame", options_.capture.string())}};
    binPath_ = temporarySibling(outDir_ / (stem_ + ".bin"));
    try {
      {
        BinaryBuffer bin(binPath_);
        bin_ = &bin;
        buildDocument();
        passTwo();
        bin.finish();
        report_.binBytes = bin.size();
        bin_ = nullptr;
      }
      writeOutputs();
    } catch (...) {
      std::error_code ec;
      fs::remove(binPath_, ec);  // no half-written buffer left behind
      throw;
    }
    report_.warnings.insert(report_.warnings.begin(), reader_->warnings().begin(), reader_->warnings().end());
    return report_;
  }

 private:
  // ---- pass 1: spans and visibility key counts ------------------------------------------------

  Track& track(std::uint64_t id, Kind kind, int model) {
    auto [it, inserted] = tracks_.try_emplace(id);
    Track& t = it->second;
    if (inserted) {
      t.id = id;
      t.kind = kind;
      t.model = model;
      t.skinned = model >= 0 && !reader_->models()[static_cast<std::size_t>(model)].joints.empty();
    }
    return t;
  }

  // Called for every record of a dynamic capturable in frame i (once per frame and capturable).
  // Emits visibility keys through `key(track, frame, value)`.
  template <typename Key>
  void present(Track& t, std::size_t i, Key&& key) {
    if (t.lastPresent == i && t.appeared) return;  // a second record of the same capturable this frame
    if (!t.visible) {
      if (!t.appeared) {
        t.appeared = true;
        t.first = i;
        if (i > 0) key(t, 0, false);  // hidden from the start until it appears
      }
      key(t, i, true);
      t.visible = true;
      visibleNow_.push_back(&t);
    }
    t.lastPresent = i;
  }

  template <typename Key>
  void endFrame(std::size_t i, Key&& key) {
    std::erase_if(visibleNow_, [&](Track* t) {
      if (i - t->lastPresent <= static_cast<std::size_t>(t->extraFrames)) return false;
      key(*t, i, false);
      t->visible = false;
      return true;
    });
  }

  template <typename Key>
  void scanFrame(const CaptureFrame& frame, std::size_t i, Key&& key) {
    for (const auto& c : frame.cameras) present(track(c.id, Kind::kCamera, -1), i, key);
    for (const auto& m : frame.models) present(track(m.id, Kind::kModel, m.model), i, key);
    for (const auto& l : frame.lights) {
      Track& t = track(l.id, Kind::kLight, -1);
      if (!t.appeared && !l.dynamic) {
        t.light = l;
        t.appeared = true;
        continue;
      }
      if (!t.appeared) {
        t.light = l;
        t.extraFrames = options_.lightRules.rule(l.modelType).extraFrames;
      }
      if (l.dynamic) present(t, i, key);
    }
    for (const auto& p : frame.staticModels) {
      Track& t = track(p.id, Kind::kStaticModel, p.model);
      t.staticPose = p.pose;
      t.appeared = true;
    }
    endFrame(i, key);
  }

  void passOne() {
    CaptureFrame frame;
    std::size_t i = 0;
    auto count = [](Track& t, std::size_t frame, bool) {
      ++t.visibilityKeys;
      t.lastKeyFrame = frame;
    };
    while (true) {
      auto more = reader_->next(frame);
      if (!more) throw Failure{Error{more.error().code, more.error().message}};
      if (!*more) break;
      if (frame.cameraSettings && !cameraChanged_) {
        cameraChanged_ = true;
        report_.warnings.push_back(fmt::format("{}: camera settings change at frame {}; the dataset keeps the first ones",
                                               options_.capture.string(), frame.number));
      }
      times_.push_back(static_cast<float>(frame.time));
      scanFrame(frame, i, count);
      if (options_.onProgress) options_.onProgress(1, i + 1, 0);
      ++i;
    }
    const std::size_t n = times_.size();
    for (auto& [id, t] : tracks_) t.lastSpan = std::min(n - 1, t.lastPresent + static_cast<std::size_t>(t.extraFrames));
    // Times must strictly increase for glTF samplers; equal capture times (a paused game) cannot be keyed.
    for (std::size_t k = 1; k < n; ++k)
      if (!(times_[k] > times_[k - 1]))
        throw Failure{Error{ErrorCode::kInvalidData,
                           fmt::format("{}: frames {} and {} have the same time {} s (as float); glTF key times must increase",
                                       options_.capture.string(), k - 1, k, times_[k])}};
  }

  // ---- the document --------------------------------------------------------------------------

  int bufferView(std::uint64_t offset, std::uint64_t length, int target = 0) { return addBufferView(doc_, offset, length, target); }
  int accessor(int view, std::uint64_t byteOffset, int componentType, std::size_t count, const char* type, json min = nullptr,
               json max = nullptr) {
    return addAccessor(doc_, view, byteOffset, componentType, count, type, std::move(min), std::move(max));
  }
  template <typename T>
  int dataAccessor(const std::vector<T>& data, int componentType, const char* type, int target, json min = nullptr, json max = nullptr,
                   std::size_t count = 0) {
    return addDataAccessor(doc_, *bin_, data, componentType, type, target, std::move(min), std::move(max), count);
  }

  int addNode(json node, int parent) {
    doc_["nodes"].push_back(std::move(node));
    const int index = static_cast<int>(doc_["nodes"].size()) - 1;
    if (parent >= 0) doc_["nodes"][static_cast<std::size_t>(parent)]["children"].push_back(index);
    return index;
  }

  static json trs(const glm::dvec3& t, const glm::dquat& r) {
    json n = json::object();
    if (t != glm::dvec3(0.0)) n["translation"] = vec(t);
    if (r != glm::dquat(1, 0, 0, 0)) n["rotation"] = quat(glm::normalize(r));
    return n;
  }

  int image(const std::string& texture) {
    if (texture.empty()) return -1;
    if (auto it = imageByTexture_.find(texture); it != imageByTexture_.end()) return it->second;
    int index = -1;
    std::string ext = fs::path(texture).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext != ".png" && ext != ".jpg" && ext != ".jpeg") {
      report_.warnings.push_back(fmt::format("texture '{}' is neither PNG nor JPEG (glTF's image formats); left out", texture));
    } else if (const fs::path source = textureSource(texture); !source.empty()) {
      const fs::path relative = fs::path(texture).lexically_normal();
      const fs::path target = outDir_ / (stem_ + "_textures") / relative;
      std::error_code ec;
      fs::create_directories(target.parent_path(), ec);
      fs::copy_file(source, target, fs::copy_options::overwrite_existing, ec);
      if (ec) throw Failure{Error{ErrorCode::kIo, fmt::format("{}: cannot copy texture: {}", target.string(), ec.message())}};
      report_.written.push_back(target);
      index = addTexture(relative.generic_string(), ext == ".png" ? "image/png" : "image/jpeg");
    }
    imageByTexture_[texture] = index;
    return index;
  }

  // A texture's file under the data root, or empty (with a warning) when it cannot be used.
  fs::path textureSource(const std::string& texture) {
    const fs::path relative = fs::path(texture).lexically_normal();
    std::string ext = relative.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    fs::path root = options_.dataRoot ? *options_.dataRoot : fs::path(reader_->settings().dataRoot);
    if (root.is_relative()) root = options_.capture / root;
    std::error_code ec;
    if (relative.is_absolute() || relative.empty() || *relative.begin() == "..") {
      report_.warnings.push_back(fmt::format("texture '{}' is not a path inside the data root; left out", texture));
      return {};
    }
    if (!fs::is_regular_file(root / relative, ec)) {
      report_.warnings.push_back(fmt::format("texture '{}' not found at {}; left out", texture, (root / relative).string()));
      return {};
    }
    return root / relative;
  }

  int addTexture(const std::string& relativeUri, const std::string& mime) {
    doc_["images"].push_back({{"uri", uriPath(stem_ + "_textures/" + relativeUri)}, {"mimeType", mime}});
    doc_["textures"].push_back({{"source", doc_["images"].size() - 1}, {"sampler", 0}});
    ++report_.textures;
    return static_cast<int>(doc_["textures"].size()) - 1;
  }

  // The mask map turned into a glTF metallic-roughness texture (docs/dataset.md): Cube 2 masks hold
  // specular intensity in R and the environment-map (chrome) mask in B, so roughness (G) = 1 - 0.8 R
  // and metallic (B) = B. Returns -1 when the mask cannot be read.
  int metallicRoughnessFromMask(const std::string& mask) {
    if (mask.empty()) return -1;
    if (auto it = maskTextures_.find(mask); it != maskTextures_.end()) return it->second;
    int index = -1;
    if (const fs::path source = textureSource(mask); !source.empty()) {
      auto image = readImage(source);
      if (!image) {
        report_.warnings.push_back(fmt::format("mask map '{}': {}; left out", mask, image.error().message));
      } else {
        FloatImage mr{image->width, image->height, 3, {}, {}};
        mr.pixels.resize(static_cast<std::size_t>(image->width) * image->height * 3);
        for (std::size_t p = 0; p < mr.pixels.size() / 3; ++p) {
          const float* in = &image->pixels[p * static_cast<std::size_t>(image->channels)];
          const float specular = in[0];
          const float chrome = image->channels >= 3 ? in[2] : 0.0f;
          mr.pixels[p * 3 + 0] = 1.0f;                    // R: occlusion, unused
          mr.pixels[p * 3 + 1] = 1.0f - 0.8f * specular;  // G: roughness
          mr.pixels[p * 3 + 2] = chrome;                  // B: metallic
        }
        const std::string relative = (fs::path(mask).parent_path() / (fs::path(mask).stem().string() + "_metallic_roughness.png")).generic_string();
        const fs::path target = outDir_ / (stem_ + "_textures") / relative;
        std::error_code ec;
        fs::create_directories(target.parent_path(), ec);
        if (auto ok = writeImage(target, mr); !ok) throw Failure{Error{ok.error().code, ok.error().message}};
        report_.written.push_back(target);
        index = addTexture(relative, "image/png");
      }
    }
    maskTextures_[mask] = index;
    return index;
  }

  // Material per (texture, mask) pair (docs/dataset.md): base colour from the texture map;
  // metallic and roughness from the mask map, or dielectric with roughness 0.8 without one.
  int material(const CapturedMesh& mesh) {
    const auto key = std::make_pair(mesh.texture, mesh.maskTexture);
    if (auto it = materialByMaps_.find(key); it != materialByMaps_.end()) return it->second;
    json m = {{"name", mesh.texture.empty() ? "untextured" : fs::path(mesh.texture).stem().string()},
              {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}};
    if (int t = image(mesh.texture); t >= 0) m["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", t}};
    if (int t = metallicRoughnessFromMask(mesh.maskTexture); t >= 0) {
      m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", t}};
      m["pbrMetallicRoughness"]["metallicFactor"] = 1.0;
      m["pbrMetallicRoughness"]["roughnessFactor"] = 1.0;
      m["extras"] = {{"dynbench_mask_map", mesh.maskTexture}};
    }
    doc_["materials"].push_back(m);
    const int index = static_cast<int>(doc_["materials"].size()) - 1;
    materialByMaps_[key] = index;
    return index;
  }

  void buildMeshes() {
    for (const auto& model : reader_->models()) {
      json primitives = json::array();
      for (const auto& mesh : model.meshes) {
        if (mesh.indices.empty()) continue;
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        std::vector<float> positions;
        for (const auto& p : mesh.positions) {
          lo = glm::min(lo, p);
          hi = glm::max(hi, p);
          positions.insert(positions.end(), {p.x, p.y, p.z});
        }
        json attributes = {{"POSITION", dataAccessor(positions, kFloat, "VEC3", kArrayBuffer, std::vector<float>{lo.x, lo.y, lo.z},
                                                     std::vector<float>{hi.x, hi.y, hi.z})}};
        if (!mesh.normals.empty()) {
          std::vector<float> normals;
          for (auto n : mesh.normals) {
            const float len = glm::length(n);
            n = len > 0 ? n / len : glm::vec3(0, 1, 0);  // glTF requires unit normals
            normals.insert(normals.end(), {n.x, n.y, n.z});
          }
          attributes["NORMAL"] = dataAccessor(normals, kFloat, "VEC3", kArrayBuffer);
        }
        if (!mesh.uvs.empty()) {
          std::vector<float> uvs;
          for (const auto& t : mesh.uvs) uvs.insert(uvs.end(), {t.x, t.y});
          attributes["TEXCOORD_0"] = dataAccessor(uvs, kFloat, "VEC2", kArrayBuffer);
        }
        if (!model.joints.empty() && !mesh.joints.empty()) {
          std::vector<std::uint16_t> joints;
          std::vector<float> weights;
          for (std::size_t v = 0; v < mesh.joints.size(); ++v) {
            const glm::vec4 w = mesh.weights[v];
            const float sum = w.x + w.y + w.z + w.w;
            for (int k = 0; k < 4; ++k) {
              joints.push_back(w[k] > 0 ? mesh.joints[v][k] : 0);
              weights.push_back(sum > 0 ? w[k] / sum : (k == 0 ? 1.0f : 0.0f));  // glTF: weights sum to 1
            }
          }
          attributes["JOINTS_0"] = dataAccessor(joints, kUnsignedShort, "VEC4", kArrayBuffer);
          attributes["WEIGHTS_0"] = dataAccessor(weights, kFloat, "VEC4", kArrayBuffer);
        }
        primitives.push_back({{"attributes", attributes},
                              {"indices", dataAccessor(mesh.indices, kUnsignedInt, "SCALAR", kElementArrayBuffer)},
                              {"material", material(mesh)}});
      }
      if (primitives.empty()) {
        meshOfModel_.push_back(-1);
        continue;
      }
      doc_["meshes"].push_back({{"name", model.path}, {"primitives", primitives}});
      meshOfModel_.push_back(static_cast<int>(doc_["meshes"].size()) - 1);
      ++report_.meshes;
      // Inverse bind matrices, shared by every instance of the model.
      if (!model.joints.empty()) {
        std::vector<float> matrices;
        for (const auto& j : model.joints) {
          const glm::dmat4 m = matrixOf(j.inverseBindPose);
          for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) matrices.push_back(static_cast<float>(m[c][r]));
        }
        ibmOfModel_[static_cast<int>(meshOfModel_.size()) - 1] = dataAccessor(matrices, kFloat, "MAT4", 0);
      }
    }
  }

  int lightDefinition(const LightRecord& l, double share) {
    // Engines have negative lights that darken (Cube 2 does); glTF lights only add light, and
    // KHR_lights_punctual colours are in [0, 1]: negative channels become 0.
    const glm::dvec3 captured = glm::max(l.color, glm::dvec3(0.0));
    const double peak = std::max({captured.r, captured.g, captured.b});
    const LightRule& rule = options_.lightRules.rule(l.modelType);
    const glm::dvec3 color = peak > 0 ? captured / peak : glm::dvec3(1.0);
    json light = {{"type", l.type == LightType::kSpot ? "spot" : l.type == LightType::kDirectional ? "directional" : "point"},
                  {"color", vec(color)},
                  {"intensity", options_.lightRules.candelaPerUnit * peak * rule.intensityScale * share},
                  {"name", l.modelType}};
    if (l.type == LightType::kSpot) light["spot"] = {{"outerConeAngle", 0.7853981633974483}};
    lights_.push_back(light);
    ++report_.lights;
    return static_cast<int>(lights_.size()) - 1;
  }

  // A light capturable: one light, or (ring rule) six around its node.
  void lightNodes(Track& t, int node) {
    const LightRule& rule = options_.lightRules.rule(t.light.modelType);
    if (rule.ringLights == 6) {
      const int def = lightDefinition(t.light, 1.0 / 6);
      const double r = rule.ringRadiusMetres / reader_->settings().metresPerUnit;
      for (const glm::dvec3 axis : {glm::dvec3(1, 0, 0), glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0),
                                    glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1)})
        addNode({{"name", fmt::format("light_{}_ring", t.id)}, {"translation", vec(axis * r)},
                 {"extensions", {{"KHR_lights_punctual", {{"light", def}}}}}},
                node);
    } else {
      doc_["nodes"][static_cast<std::size_t>(node)]["extensions"]["KHR_lights_punctual"] = {{"light", lightDefinition(t.light, 1.0)}};
    }
  }

  void buildDocument() {
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
    buildMeshes();

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
      if (t.kind == Kind::kStaticModel) {
        const int mesh = meshOfModel_[static_cast<std::size_t>(t.model)];
        const auto& model = reader_->models()[static_cast<std::size_t>(t.model)];
        json node = trs(translationOf(t.staticPose), rotationOf(t.staticPose));
        node["name"] = fmt::format("static_{}_{}", t.id, model.path);
        if (mesh >= 0 && model.joints.empty()) node["mesh"] = mesh;
        t.node = addNode(node, staticObjects);
        // A skinned model placed as a static one keeps its bind pose: a skin whose joints never move.
        if (!model.joints.empty()) addSkin(t, mesh);
        continue;
      }
      if (t.kind == Kind::kLight && !t.light.dynamic) {
        json node = trs(t.light.position, glm::dquat(1, 0, 0, 0));
        node["name"] = fmt::format("light_{}_{}", t.id, t.light.modelType);
        t.node = addNode(node, staticObjects);
        lightNodes(t, t.node);
        continue;
      }
      if (!t.appeared) continue;
      // Dynamic capturables: node, key frames over their span, visibility keys.
      json node = {{"name", fmt::format("{}_{}", kindName(t.kind), t.id)}};
      if (t.kind == Kind::kModel) node["name"] = fmt::format("model_{}_{}", t.id, reader_->models()[static_cast<std::size_t>(t.model)].path);
      if (t.kind == Kind::kCamera) node["camera"] = 0;
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
    }
    report_.channels = channels.size();
    if (!channels.empty()) doc_["animations"] = {{{"name", "capture"}, {"samplers", samplers}, {"channels", channels}}};
  }

  // Joint nodes in the bind pose under the capturable's node, the skin, and the skinned mesh node;
  // returns the joint nodes.
  std::vector<int> addSkin(const Track& t, int mesh) {
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
  void buildSkin(Track& t, int mesh, int input, Channel& channel, Region& region) {
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

  // ---- pass 2: key frames ----------------------------------------------------------------------

  void passTwo() {
    auto opened = CaptureReader::open(options_.capture);
    if (!opened) throw Failure{Error{opened.error().code, opened.error().message}};
    auto reader = std::move(*opened);
    for (auto& [id, t] : tracks_) {
      t.appeared = t.visible = false;
      t.lastPresent = 0;
      if (t.translationOffset) t.translation = RegionWriter(bin_, t.translationOffset);
      if (t.rotationOffset) t.rotation = RegionWriter(bin_, t.rotationOffset);
      if (t.visTimeOffset) t.visTime = RegionWriter(bin_, t.visTimeOffset);
      if (t.visValueOffset) t.visValue = RegionWriter(bin_, t.visValueOffset);
      if (t.scaleOffset) t.scale = RegionWriter(bin_, t.scaleOffset);
      for (auto o : t.jointTranslationOffsets) t.jointTranslation.emplace_back(bin_, o);
      for (auto o : t.jointRotationOffsets) t.jointRotation.emplace_back(bin_, o);
    }
    visibleNow_.clear();
    auto key = [&](Track& t, std::size_t frame, bool value) {
      if (!visInputs_.contains(t.id)) return;
      t.visTime.put(times_[frame]);
      if (t.visValueOffset) t.visValue.put(static_cast<std::uint8_t>(value ? 1 : 0));
      if (t.scaleOffset) {
        const float s = value ? 1.0f : 0.0f;
        for (int k = 0; k < 3; ++k) t.scale.put(s);
      }
    };
    std::vector<Track*> active;
    CaptureFrame frame;
    for (std::size_t i = 0; i < times_.size(); ++i) {
      auto more = reader->next(frame);
      if (!more) throw Failure{Error{more.error().code, more.error().message}};
      if (!*more) throw Failure{Error{ErrorCode::kIo, fmt::format("{}: the capture changed while it was converted", options_.capture.string())}};
      // Held values follow this frame's records.
      for (const auto& c : frame.cameras) {
        Track& t = tracks_.at(c.id);
        t.heldTranslation = c.position;
        t.heldRotation = quatFromYawPitchRoll(radians(c.yaw), radians(c.pitch), radians(c.roll));
        if (!t.appeared) active.push_back(&t);
      }
      for (const auto& m : frame.models) {
        Track& t = tracks_.at(m.id);
        t.heldTranslation = translationOf(m.pose);
        t.heldRotation = rotationOf(m.pose);
        if (!t.appeared) active.push_back(&t);
      }
      for (const auto& l : frame.lights) {
        Track& t = tracks_.at(l.id);
        if (!l.dynamic) continue;
        t.heldTranslation = l.position;
        if (!t.appeared) active.push_back(&t);
      }
      for (const auto& j : frame.joints) {
        Track& t = tracks_.at(j.id);
        // Model-space joints to parent-local: L_j = M_parent^-1 M_j (rigid, so exact).
        const auto& model = reader_->models()[static_cast<std::size_t>(t.model)];
        for (std::size_t k = 0; k < j.joints.size(); ++k) {
          const glm::dquat r = rotationOf(j.joints[k]);
          const glm::dvec3 p = translationOf(j.joints[k]);
          const int parent = model.joints[k].parent;
          if (parent < 0) {
            t.heldJointTranslation[k] = p;
            t.heldJointRotation[k] = r;
          } else {
            const glm::dquat rp = rotationOf(j.joints[static_cast<std::size_t>(parent)]);
            const glm::dvec3 pp = translationOf(j.joints[static_cast<std::size_t>(parent)]);
            t.heldJointTranslation[k] = glm::conjugate(rp) * (p - pp);
            t.heldJointRotation[k] = glm::normalize(glm::conjugate(rp) * r);
          }
        }
      }
      scanFrame(frame, i, key);
      // Every active track writes one key per frame of its span.
      std::erase_if(active, [&](Track* t) {
        if (i > t->lastSpan) return true;
        if (t->translationOffset) t->translation.put(std::array<float, 3>{static_cast<float>(t->heldTranslation.x),
                                                                           static_cast<float>(t->heldTranslation.y),
                                                                           static_cast<float>(t->heldTranslation.z)});
        if (t->rotationOffset) {
          t->heldRotation = nearest(t->lastRotation, t->heldRotation);
          t->lastRotation = t->heldRotation;
          t->rotation.put(std::array<float, 4>{static_cast<float>(t->heldRotation.x), static_cast<float>(t->heldRotation.y),
                                               static_cast<float>(t->heldRotation.z), static_cast<float>(t->heldRotation.w)});
        }
        for (std::size_t k = 0; k < t->jointTranslation.size(); ++k) {
          const glm::dvec3 p = t->heldJointTranslation[k];
          t->jointTranslation[k].put(std::array<float, 3>{static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
          glm::dquat r = t->heldJointRotation[k];
          r = nearest(t->lastJointRotation[k], r);
          t->heldJointRotation[k] = r;
          t->lastJointRotation[k] = r;
          t->jointRotation[k].put(std::array<float, 4>{static_cast<float>(r.x), static_cast<float>(r.y), static_cast<float>(r.z),
                                                       static_cast<float>(r.w)});
        }
        return i == t->lastSpan;
      });
      if (options_.onProgress) options_.onProgress(2, i + 1, times_.size());
    }
    for (auto& [id, t] : tracks_) {
      for (RegionWriter* w : {&t.translation, &t.rotation, &t.visTime, &t.visValue, &t.scale}) w->flush();
      for (auto& w : t.jointTranslation) w.flush();
      for (auto& w : t.jointRotation) w.flush();
    }
  }

  // ---- files -----------------------------------------------------------------------------------

  std::string datasetReadme() const {
    const auto& s = reader_->settings();
    std::string licences;
    std::ifstream in(options_.capture / "LICENSES.txt");
    if (in) licences.assign(std::istreambuf_iterator<char>(in), {});
    std::string out = fmt::format("# {}\n\nA dynamic benchmark dataset for temporal rendering, made by dynbench {} (`dynbench convert`) "
                                  "from a capture.\n\n", stem_, kVersion);
    out += fmt::format("- source: {}\n- capture: {}\n- map: {}\n", s.source.empty() ? "not stated" : s.source,
                       options_.capture.filename().string().empty() ? options_.capture.string() : options_.capture.filename().string(),
                       s.mapName.empty() ? "-" : s.mapName);
    out += fmt::format("- frames: {}, {:.3f} s to {:.3f} s\n", times_.size(), times_.front(), times_.back());
    out += fmt::format("- capturables: {}; nodes {}, meshes {}, skins {}, lights {}, animation channels {}\n", report_.capturables,
                       doc_["nodes"].size(), report_.meshes, report_.skins, report_.lights, report_.channels);
    out += fmt::format("- length unit: {} m\n", s.metresPerUnit);
    out += "\nLayout (thesis §5.1): WorldOrigo > StaticObjects (map, static map models, static lights) and DynamicObjects "
           "(cameras, rigid and skinned models, dynamic lights). Objects that appear and disappear are switched with "
           "KHR_node_visibility (STEP keys through KHR_animation_pointer) and, for meshes, a scale-0 STEP channel. "
           "See dynbench's docs/dataset.md.\n";
    out += "\n## Licences of the assets\n\n";
    out += licences.empty() ? "The capture states none (no LICENSES.txt in the capture directory). Check the licences of the "
                              "models and textures before publishing this dataset.\n"
                            : licences;
    return out;
  }

  // The environment image beside the dataset and the root extension that names it (docs/dataset.md).
  json environment() {
    json ext = {{"projection", "equirectangular"}, {"units", "cd/m2"}, {"intensity", 1.0}};
    fs::path target;
    if (options_.environment) {
      std::string ext2 = options_.environment->extension().string();
      std::transform(ext2.begin(), ext2.end(), ext2.begin(), [](unsigned char c) { return std::tolower(c); });
      if (ext2 != ".hdr" && ext2 != ".exr")
        throw Failure{Error{ErrorCode::kUsage, fmt::format("--env {}: expected an .hdr or .exr image", options_.environment->string())}};
      auto header = readImageHeader(*options_.environment);
      if (!header) throw Failure{Error{header.error().code, header.error().message}};
      if (header->width != 2 * header->height)
        report_.warnings.push_back(fmt::format("--env {}: {}x{} is not 2:1; is it equirectangular?", options_.environment->string(),
                                               header->width, header->height));
      target = outDir_ / (stem_ + "_environment" + ext2);
      std::error_code ec;
      fs::copy_file(*options_.environment, target, fs::copy_options::overwrite_existing, ec);
      if (ec) throw Failure{Error{ErrorCode::kIo, fmt::format("{}: cannot copy the environment: {}", target.string(), ec.message())}};
      ext["source"] = options_.environment->filename().string();
    } else {
      const SkyImage sky = preethamSky(options_.sky);
      target = outDir_ / (stem_ + "_sky.hdr");
      if (auto ok = writeImage(target, FloatImage{sky.width, sky.height, 3, sky.rgb, {}}); !ok) throw Failure{Error{ok.error().code, ok.error().message}};
      ext["source"] = "dynbench Preetham sky";
      ext["sky"] = {{"model", "Preetham 1999 + ESRA sun"}, {"turbidity", options_.sky.turbidity},
                    {"sun_elevation_degrees", options_.sky.sunElevationDegrees}, {"sun_azimuth_degrees", options_.sky.sunAzimuthDegrees},
                    {"sun_direction", vec(sky.sunDirection)}, {"sun_illuminance_lux", sky.sunIlluminanceLux},
                    {"zenith_luminance_cd_m2", sky.zenithLuminance}};
    }
    report_.written.push_back(target);
    ext["uri"] = uriPath(target.filename().string());
    return ext;
  }

  void writeOutputs() {
    json document = doc_;
    document["extensions"]["DYNBENCH_environment"] = environment();
    if (!lights_.empty()) document["extensions"]["KHR_lights_punctual"] = {{"lights", lights_}};
    std::vector<std::string> used{"DYNBENCH_environment"};
    if (!lights_.empty()) used.push_back("KHR_lights_punctual");
    if (usesVisibility_) {
      used.push_back("KHR_node_visibility");
      used.push_back("KHR_animation_pointer");
    }
    if (!used.empty()) document["extensionsUsed"] = used;
    for (const char* key : {"images", "textures", "materials", "meshes", "skins"})
      if (document.contains(key) && document[key].empty()) document.erase(key);
    if (!document.contains("images")) document.erase("samplers");
    document["buffers"] = {{{"byteLength", report_.binBytes}}};
    report_.nodes = document["nodes"].size();
    report_.materials = document.contains("materials") ? document["materials"].size() : 0;
    report_.frames = times_.size();

    const fs::path readme = outDir_ / (stem_ + ".README.md");
    if (auto ok = writeFileAtomic(readme, datasetReadme()); !ok) throw Failure{Error{ok.error().code, ok.error().message}};
    report_.written.push_back(readme);
    auto written = writeDataset(std::move(document), binPath_, report_.binBytes, options_.output, options_.glb);
    if (!written) throw Failure{written.error()};
    report_.written.insert(report_.written.end(), written->begin(), written->end());
  }

  const ConvertOptions& options_;
  std::unique_ptr<CaptureReader> reader_;
  std::string stem_;
  fs::path outDir_, binPath_;
  BinaryBuffer* bin_ = nullptr;
  std::vector<float> times_;
  std::map<std::uint64_t, Track> tracks_;
  std::vector<Track*> visibleNow_;
  json doc_;
  std::vector<json> lights_;
  std::vector<int> meshOfModel_;
  std::map<int, int> ibmOfModel_;
  std::map<std::string, int> imageByTexture_, maskTextures_;
  std::map<std::pair<std::string, std::string>, int> materialByMaps_;
  std::map<std::uint64_t, int> visInputs_;
  int timesView_ = -1;
  bool cameraChanged_ = false, usesVisibility_ = false;
  ConvertReport report_;
};

}  // namespace

Expected<ConvertReport> convertCapture(const ConvertOptions& options) {
  try {
    return Converter(options).run();
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  }
}

}  // namespace dynbench::convert
