#pragma once
// Reader and validator of the capture format (docs/capture-format.md). ModelMesh files are read
// whole (they are small); Capture.txt is streamed one frame at a time, so memory stays bounded
// however long the capture. Every error names file:line and what was expected.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "core/math.h"

namespace dynbench::capture {

struct CapturedMesh {
  int id = 0;
  std::string name, texture, maskTexture;  // textures relative to the data root; empty when none
  // The material beyond its maps (ModelMesh version 3: `f`, `r`, `e`, `E`).
  glm::vec4 baseColor{1.0f};                       // linear RGBA, multiplies the texture map
  std::optional<glm::vec2> metallicRoughness;      // unset: from the mask map, or the converter's default
  glm::vec3 emission{0.0f};                        // in the light colours' units (1: the engine's full light on white)
  std::string emissionTexture;                     // multiplies emission; empty when none
  bool emissionTextureMeanOne = false;             // emission is the mean; the map is scaled to mean 1 (record m)
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<glm::vec4> colors;  // `c`: linear RGBA per vertex, multiplying baseColor; empty when none
  std::vector<glm::u16vec4> joints;  // up to 4 influences; unused ones have weight 0
  std::vector<glm::vec4> weights;
  std::vector<std::uint32_t> indices;  // 3 per triangle
  // Vertex animation (`K`, `P`, `N`): per key frame, every vertex's position (and normal, or none
  // for any key frame); empty for a mesh that is not vertex-animated.
  std::vector<std::vector<glm::vec3>> keyPositions, keyNormals;
};

struct CapturedJoint {
  int id = 0;
  int parent = -1;
  std::string name;
  DualQuaternion bindPose;         // local to the parent joint
  DualQuaternion inverseBindPose;  // model space to joint space
};

struct CapturedModel {
  std::string path;            // the model path Capture.txt refers to
  std::filesystem::path file;  // its ModelMesh file
  std::vector<CapturedMesh> meshes;
  std::vector<CapturedJoint> joints;  // empty for a rigid model
  std::size_t keyFrames = 0;          // of its vertex-animated meshes (0: none; never with joints)
};

Expected<CapturedModel> readModelMesh(const std::filesystem::path& file);

struct CameraSettings {
  double aspect = 0, yfovDegrees = 0, znear = 0, zfar = 0;
};

// The map's own lighting (`L`), in the light colours' units (1: the engine's full light).
struct MapLighting {
  glm::dvec3 sunDirection{0.0, 1.0, 0.0};  // towards the sun, unit
  glm::dvec3 sun{0.0}, ambient{0.0}, sky{0.0};
  bool hasSun() const { return sun.r > 0 || sun.g > 0 || sun.b > 0; }
};

struct CaptureSettings {
  std::string source, dataRoot, mapName;
  glm::dvec3 mapOffset{0.0};
  double metresPerUnit = 1.0;
  std::optional<CameraSettings> camera;  // as set before the first frame
  std::optional<MapLighting> lighting;   // the `L` record
};

enum class LightType { kPoint, kSpot, kDirectional };
// How the engine's light fades to nothing at its range: colour x (1 - d/range) or x (1 - (d/range)^2).
// kInverseSquare: colour x (range / d)^2, no end (the range is where it gives its colour).
// kWindowedInverseSquare: colour x (range / d)^2 x max(0, 1 - (d / range)^4), KHR_lights_punctual's
// point light with a range, which ends there.
enum class LightFalloff { kNone, kLinear, kQuadratic, kInverseSquare, kWindowedInverseSquare };

struct CameraRecord {
  std::uint64_t id = 0;
  glm::dvec3 position{0.0};
  double pitch = 0, yaw = 0, roll = 0;  // degrees
};

struct CameraCutRecord {  // `c`: the camera jumped between the previous frame and this one
  std::uint64_t id = 0;
  std::string reason;  // "respawn", "switch", "teleport", ...
};

struct ModelRecord {  // `p` (static map model) and `m` (model transform)
  std::uint64_t id = 0;
  int model = -1;  // index into CaptureReader::models()
  DualQuaternion pose;
};

struct JointsRecord {
  std::uint64_t id = 0;
  int model = -1;
  std::vector<DualQuaternion> joints;  // model space, after blending, before the inverse bind pose
};

struct VertexFramesRecord {  // `v`: a vertex-animated model's key-frame pose this frame
  std::uint64_t id = 0;
  int model = -1;
  std::uint32_t from = 0, to = 0;  // key frames
  double fraction = 0.0;           // every vertex at (1 - fraction) x from + fraction x to
};

struct LightRecord {
  std::uint64_t id = 0;
  glm::dvec3 position{0.0};
  glm::dvec3 color{0.0};
  double range = 0.0;  // capture units where the engine's light ends; 0: none
  LightFalloff falloff = LightFalloff::kNone;
  LightType type = LightType::kPoint;
  bool dynamic = false;
  std::string modelType;  // "none", "flash", "bouncer", "rocket", ...
};

struct CaptureFrame {
  std::uint64_t number = 0;
  double time = 0.0;
  std::size_t line = 0;  // line of its `f` record
  std::optional<CameraSettings> cameraSettings;  // a `C` record inside this frame
  std::vector<CameraRecord> cameras;
  std::vector<CameraCutRecord> cuts;
  std::vector<ModelRecord> staticModels, models;
  std::vector<JointsRecord> joints;
  std::vector<VertexFramesRecord> vertexFrames;
  std::vector<LightRecord> lights;
  void clear();
};

class Line;  // capture/record_lexer.h

class CaptureReader {
 public:
  // Reads every ModelMesh file and Capture.txt's records up to the first frame.
  static Expected<std::unique_ptr<CaptureReader>> open(const std::filesystem::path& directory);

  // The next complete frame: true, false at the end, or an error. A last frame cut short by a
  // crash is dropped with a warning.
  Expected<bool> next(CaptureFrame& frame);

  const CaptureSettings& settings() const { return settings_; }
  const std::vector<CapturedModel>& models() const { return models_; }
  int modelIndex(const std::string& path) const;
  const std::vector<std::string>& warnings() const { return warnings_; }
  bool closed() const { return closed_; }  // the `z` record was read

  struct Impl;
  ~CaptureReader();

 private:
  CaptureReader();
  bool nextLine(std::string& line, std::size_t& number, bool inFrame, const CaptureFrame& frame);
  bool startFrame(const Line& l, CaptureFrame& frame);
  CaptureSettings settings_;
  std::vector<CapturedModel> models_;
  std::map<std::string, int> modelByPath_;
  std::vector<std::string> warnings_;
  bool closed_ = false;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynbench::capture
