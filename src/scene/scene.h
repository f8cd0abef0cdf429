#pragma once
// The scene model: what every loader produces and what stats, render and convert consume.
// It follows glTF 2.0's data model (nodes with TRS or matrix, meshes of primitives, skins,
// animations of samplers and channels) because glTF is the dataset format; assimp and OBJ-sequence
// loaders map their input onto it. Units: seconds for time, the file's own length unit for space.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace dynbench::scene {

// A file the dataset consists of, with its size on disk (textures are never decoded to get this).
struct SourceFile {
  std::filesystem::path path;
  std::uint64_t bytes = 0;
};

struct SceneSource {
  std::filesystem::path path;  // what the user named (file, folder or glob)
  std::string format;          // "glTF", "GLB", "FBX", "COLLADA", "OBJ sequence", ...
  std::vector<SourceFile> files;  // the main file(s) first, then everything they reference
  std::uint64_t totalBytes() const;
};

struct MorphTarget {
  std::vector<glm::vec3> positionDeltas;  // empty or one per vertex
  std::vector<glm::vec3> normalDeltas;    // empty or one per vertex
};

enum class PrimitiveMode { kTriangles, kLines, kPoints };

struct Primitive {
  PrimitiveMode mode = PrimitiveMode::kTriangles;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // empty when the file has none
  std::vector<glm::vec2> uvs;       // TEXCOORD_0; empty when absent
  std::vector<glm::vec4> colors;    // COLOR_0 (linear RGBA, multiplies the base colour); empty when absent
  std::vector<glm::u16vec4> joints;  // JOINTS_0 (indices into the node's skin joints)
  std::vector<glm::vec4> weights;    // WEIGHTS_0
  std::vector<std::uint32_t> indices;  // triangle list (strips and fans are expanded on load)
  int material = -1;
  std::vector<MorphTarget> targets;

  std::size_t triangleCount() const {
    return mode == PrimitiveMode::kTriangles ? indices.size() / 3 : 0;
  }
};

struct Mesh {
  std::string name;
  std::vector<Primitive> primitives;
  std::vector<float> defaultWeights;  // morph weights when no animation drives them
  std::size_t triangleCount() const;
  std::size_t morphTargetCount() const;
};

enum class MaterialWorkflow { kMetallicRoughness, kSpecularGlossiness, kPhongOrOther };
const char* toString(MaterialWorkflow workflow);

struct TextureRef {
  int image = -1;  // index into Scene::images, -1 when unused
  int texCoord = 0;
};

enum class AlphaMode { kOpaque, kMask, kBlend };

struct Material {
  std::string name;
  MaterialWorkflow workflow = MaterialWorkflow::kMetallicRoughness;
  glm::vec4 baseColorFactor{1.0f};
  float metallicFactor = 1.0f;
  float roughnessFactor = 1.0f;
  glm::vec3 emissiveFactor{0.0f};  // times KHR_materials_emissive_strength's emissiveStrength
  // KHR_materials_specular: scales the dielectric's 4% reflection (0 makes it purely diffuse).
  float specularFactor = 1.0f;
  glm::vec3 specularColorFactor{1.0f};
  AlphaMode alphaMode = AlphaMode::kOpaque;
  float alphaCutoff = 0.5f;
  bool doubleSided = false;
  TextureRef baseColorTexture, metallicRoughnessTexture, normalTexture, occlusionTexture,
      emissiveTexture;
  // Images used by this material in any slot (including slots not listed above, e.g. Phong maps).
  std::vector<int> images;
};

// A texture image: an external file (only its size is read) or bytes embedded in the file.
struct Image {
  std::string name;
  std::string uri;                 // as written in the file; empty when embedded in a buffer
  std::filesystem::path file;      // resolved path; empty when embedded
  std::string mimeType;
  std::uint64_t bytes = 0;         // encoded size (file size or embedded byte count)
  bool embedded = false;
};

struct Skin {
  std::string name;
  std::vector<int> joints;                      // node indices
  std::vector<glm::dmat4> inverseBindMatrices;  // one per joint (identity when absent)
  int skeleton = -1;
};

struct Camera {
  enum class Type { kPerspective, kOrthographic };
  std::string name;
  Type type = Type::kPerspective;
  double yfov = 0.0;         // radians, perspective only
  double aspectRatio = 0.0;  // 0 = not given (use the viewport's)
  double znear = 0.0;
  double zfar = 0.0;         // 0 = infinite
  double xmag = 0.0, ymag = 0.0;  // orthographic half extents
};

// KHR_lights_punctual. A light shines down its node's local -Z (spot, directional).
struct Light {
  enum class Type { kPoint, kSpot, kDirectional };
  std::string name;
  Type type = Type::kPoint;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // candela (point, spot) or lux (directional), as glTF defines
  float range = 0.0f;      // 0 = infinite
  float innerConeAngle = 0.0f;
  float outerConeAngle = 0.7853981633974483f;
};
const char* toString(Light::Type type);

struct Transform {
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // (w, x, y, z)
  glm::dvec3 scale{1.0};
  glm::dmat4 matrix() const;
};

struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  Transform local;                   // used unless `matrix` is set
  std::optional<glm::dmat4> matrix;  // a static matrix transform (glTF forbids animating it)
  int mesh = -1;
  int skin = -1;
  int camera = -1;
  int light = -1;
  std::vector<double> weights;  // morph weights overriding the mesh's defaults, if non-empty
  bool visible = true;          // KHR_node_visibility "visible" at rest
  // A camera node's cuts (extras.dynbench_camera_cuts, docs/dataset.md): the camera jumps between
  // the key at `from` and the key at `time` (seconds) instead of moving (a respawn, a switch to
  // another player); in increasing order.
  struct Cut {
    double from = 0.0, time = 0.0;
    std::string reason;
  };
  std::vector<Cut> cuts;
};

enum class Interpolation { kStep, kLinear, kCubicSpline };
const char* toString(Interpolation interpolation);

// kLightColor, kLightIntensity and kLightRange: KHR_animation_pointer to a KHR_lights_punctual
// light's colour, intensity or range (the channel names a light, not a node).
enum class AnimationPath { kTranslation, kRotation, kScale, kWeights, kVisibility, kLightColor, kLightIntensity, kLightRange };
const char* toString(AnimationPath path);

// One glTF animation sampler. `values` holds, per key, `components` floats, three times over for
// CUBICSPLINE (in-tangent, value, out-tangent), exactly as glTF stores them.
struct Sampler {
  Interpolation interpolation = Interpolation::kLinear;
  std::vector<float> times;   // strictly increasing, seconds
  std::vector<float> values;
  int components = 0;         // 3 (T, S), 4 (R), morph target count (weights), 1 (visibility)
};

struct Channel {
  int sampler = -1;
  int node = -1;   // -1 for a light's channel
  AnimationPath path = AnimationPath::kTranslation;
  int light = -1;  // kLightColor, kLightIntensity: index into Scene::lights
};

struct Animation {
  std::string name;
  std::vector<Sampler> samplers;
  std::vector<Channel> channels;
};

// The dataset's image-based light (dynbench's DYNBENCH_environment extension, docs/dataset.md):
// an equirectangular HDR image of radiance in cd/m2 (+Y up, the image centre looking down -Z).
struct Environment {
  std::string uri;
  std::filesystem::path file;  // resolved; empty when the scene has no environment
  float intensity = 1.0f;      // multiplies every pixel
};

struct Scene {
  SceneSource source;
  std::optional<Environment> environment;
  std::vector<Node> nodes;
  std::vector<int> roots;  // root nodes of the displayed scene
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Image> images;
  std::vector<Skin> skins;
  std::vector<Camera> cameras;
  std::vector<Light> lights;
  std::vector<Animation> animations;
  std::vector<std::string> warnings;  // things the loader skipped or repaired, one sentence each

  // The animation time range: earliest and latest key time over every channel of every animation
  // (all animations play together on one clock). {0, 0} when there is no animation.
  struct TimeRange {
    double start = 0.0;
    double end = 0.0;
  };
  TimeRange timeRange() const;
};

// Keeps only the animation `selector` names (an index, or an animation's name) so that it plays
// alone; returns false when nothing matches.
bool keepOnlyAnimation(Scene& scene, const std::string& selector);

}  // namespace dynbench::scene
