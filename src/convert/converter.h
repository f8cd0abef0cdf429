#pragma once
// Private to src/convert: the capture -> glTF converter, one class whose member functions are split
// by concern over convert_*.cpp (passes over the capture, materials and meshes, lights, the
// document with skins, output files). convert.h is the public face; nothing outside includes this.
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

namespace dynbench::convert::detail {

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
  bool colorVaries = false;  // a dynamic light whose captured colour or range changes: colour, intensity (and range) are animated
  int lightDefinition = -1;  // its KHR_lights_punctual light
  double lightShare = 1.0;   // its share of the captured light (1/6 for each of a ring's lights)
  struct Cut {
    float from, time;  // the key before the jump and the key after it
    std::string reason;
  };
  std::vector<Cut> cuts;  // a camera's cuts
  // Layout.
  int node = -1;
  std::uint64_t translationOffset = 0, rotationOffset = 0, visTimeOffset = 0, visValueOffset = 0, scaleOffset = 0;
  std::vector<std::uint64_t> jointTranslationOffsets, jointRotationOffsets;
  // Pass 2.
  std::uint64_t colorOffset = 0, intensityOffset = 0, rangeOffset = 0;
  std::uint64_t weightsOffset = 0;  // a vertex-animated model's morph weights, one per key frame per key
  RegionWriter translation, rotation, visTime, visValue, scale, color, intensity, range, weights;
  std::vector<float> heldWeights;
  std::vector<RegionWriter> jointTranslation, jointRotation;
  glm::dvec3 heldTranslation{0.0};
  glm::dvec3 heldColor{0.0};
  double heldRange = 0.0;
  glm::dquat heldRotation{1, 0, 0, 0};
  std::vector<glm::dvec3> heldJointTranslation;
  std::vector<glm::dquat> heldJointRotation;
  glm::dquat lastRotation{1, 0, 0, 0};  // the last rotation key written, for the shortest arc
  std::vector<glm::dquat> lastJointRotation;
  bool hasVisibilityChannel() const { return visibilityKeys > 1; }
  std::size_t span() const { return lastSpan - first + 1; }
  bool animated() const { return kind == Kind::kCamera || kind == Kind::kModel || (kind == Kind::kLight && light.dynamic); }
};

inline const char* kindName(Kind kind) {
  switch (kind) {
    case Kind::kCamera: return "camera";
    case Kind::kStaticModel: return "static";
    case Kind::kModel: return "model";
    case Kind::kLight: return "light";
  }
  return "?";
}

inline std::vector<float> quat(const glm::dquat& q) {
  return {static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z), static_cast<float>(q.w)};
}
inline std::vector<float> vec(const glm::dvec3& v) { return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)}; }

// Keeps consecutive rotation keys on the shortest arc (q and -q are the same rotation; LINEAR
// interpolation between keys of opposite sign would spin the long way round).
inline glm::dquat nearest(const glm::dquat& previous, glm::dquat q) {
  if (glm::dot(previous, q) < 0.0) q = -q;
  return q;
}

class Converter {
 public:
  explicit Converter(const ConvertOptions& options) : options_(options) {}

  Expected<ConvertReport> run();

 private:
  // ---- pass 1: spans and visibility key counts ------------------------------------------------

  Track& track(std::uint64_t id, Kind kind, int model);

  // Called for every record of a dynamic capturable in frame i (once per frame and capturable).
  // Emits visibility keys through `key(track, frame, value)`.
  template <typename Key>
  void present(Track& t, std::size_t i, Key&& key);

  template <typename Key>
  void endFrame(std::size_t i, Key&& key);

  template <typename Key>
  void scanFrame(const CaptureFrame& frame, std::size_t i, Key&& key);

  Expected<void> passOne();

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

  Expected<int> image(const std::string& texture);

  // A texture's file under the data root, or empty (with a warning) when it cannot be used.
  fs::path textureSource(const std::string& texture);
  // An emission map that only shapes a mean emission (record m) as the map of its level: each
  // texel's linear luminance, written sRGB-encoded in grey (TEXTURE_emission_level.png), and that
  // map's mean as the renderer reads it back. nullopt (with a warning) when it cannot be read.
  struct EmissionLevelMap {
    int texture = -1;  // glTF texture index
    double mean = 0.0; // mean linear level
  };
  Expected<std::optional<EmissionLevelMap>> emissionLevelMap(const std::string& texture);

  int addTexture(const std::string& relativeUri, const std::string& mime);
  // An image made from a capture texture, written beside the dataset's copies as
  // TEXTURE_textures/<texture's folder>/<its stem><suffix>.png and added as a texture.
  struct DerivedTexture {
    int texture = -1;
    fs::path file;
  };
  Expected<DerivedTexture> derivedTexture(const std::string& texture, const std::string& suffix, const FloatImage& image);

  // The mask map turned into a glTF metallic-roughness texture (docs/dataset.md): Cube 2 masks hold
  // specular intensity in R and the environment-map (chrome) mask in B, so roughness (G) = 1 - 0.8 R
  // and metallic (B) = B. Returns -1 when the mask cannot be read.
  Expected<int> metallicRoughnessFromMask(const std::string& mask);

  // Material per distinct maps and factors (docs/dataset.md): base colour from the texture map;
  // metallic and roughness from the mask map, or dielectric with roughness 0.8 without one.
  Expected<int> material(const CapturedMesh& mesh);

  json morphTargets(const CapturedModel& model, const CapturedMesh& mesh);
  Expected<void> buildMeshes();

  // KHR_lights_punctual colour (the captured colour over its largest channel) and intensity of a
  // captured light under the light rules; `share` divides it between a ring's lights. A light with
  // a range gets the flux the engine's falloff gives within it; a light of constant irradiance at
  // `constantAt` (> 0: its distance to the map's centre) the engine's irradiance there
  // (docs/dataset.md, "Lights").
  std::pair<glm::dvec3, double> lightColorIntensity(const glm::dvec3& captured, double range, LightFalloff falloff,
                                                    const std::string& modelType, double share, double constantAt) const;

  // A static light the engine does not attenuate (falloff `none`; Cube 2's lights of radius 0,
  // which maps use as a sun) lights every surface with its full colour however far: a constant
  // irradiance, which no KHR_lights_punctual light gives. It stays a point light, so that its
  // shadows fall as the engine's do (a directional light from the same place casts them up to
  // 30 degrees off on colos), with the engine's irradiance at the centre of the map's bounds.
  static bool hasConstantIrradiance(const LightRecord& l);
  double distanceToMapCentre(const glm::dvec3& position) const;

  // The generated sky (when there is no --env) and the illuminance of the engine's full light,
  // from the map's lighting: computed before any light is written.
  Expected<void> calibrateLighting();

  int lightDefinition(const LightRecord& l, double share);

  // A light capturable: one light, or (ring rule) six around its node.
  void lightNodes(Track& t, int node);

  Expected<void> buildDocument();
  // A static model or a static light: its node under StaticObjects (no animation); false for any
  // other capturable.
  bool placeStatic(Track& t, int staticObjects);

  // Joint nodes in the bind pose under the capturable's node, the skin, and the skinned mesh node;
  // returns the joint nodes.
  std::vector<int> addSkin(const Track& t, int mesh);

  template <typename Channel, typename Region>
  void buildSkin(Track& t, int mesh, int input, Channel& channel, Region& region);

  // ---- pass 2: key frames ----------------------------------------------------------------------

  Expected<void> passTwo();

  // ---- files -----------------------------------------------------------------------------------

  std::string datasetReadme() const;

  // The environment image beside the dataset and the root extension that names it (docs/dataset.md).
  Expected<json> environment();

  Expected<void> writeOutputs();

  // The buffer (buildDocument, passTwo) and then the files; on an error the caller removes the buffer.
  Expected<void> writeBufferAndDocument();

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
  std::map<std::string, std::optional<EmissionLevelMap>> emissionLevelMaps_;
  std::map<std::string, int> materialByMaps_;  // by maps and factors (material())
  std::map<std::uint64_t, int> visInputs_;
  int timesView_ = -1;
  bool cameraChanged_ = false, usesVisibility_ = false, usesAnimationPointer_ = false, usesEmissiveStrength_ = false;
  ConvertReport report_;
  std::optional<SkyImage> sky_;  // the generated sky
  SkyParameters skyParameters_;
  double luxPerUnit_ = 0.0;      // lux of a captured colour of 1 at a light with a range
  json calibration_;             // how luxPerUnit_ was found, for the dataset's extras
};

}  // namespace dynbench::convert::detail
