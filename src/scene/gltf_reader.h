#pragma once
// Private to src/scene: the glTF reader (load_gltf.cpp has why dynbench has its own). One class whose
// member functions are split by concern: the GLB/JSON container and entry point (load_gltf.cpp),
// JSON-pointer helpers and URIs (gltf_json.cpp), buffers and accessor decoding (gltf_accessors.cpp)
// and the section readers (gltf_sections.cpp). Errors are thrown as Failure (core/error.h) and
// turned into an Expected by loadGltf; nothing escapes as an exception.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <set>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/files.h"
#include "scene/load.h"

namespace dynbench::scene::gltf_detail {

namespace fs = std::filesystem;
using json = nlohmann::json;

// Extensions whose meaning dynbench implements or that cannot change what it measures.
const std::set<std::string, std::less<>> kSupportedExtensions = {
    "KHR_lights_punctual",       "KHR_node_visibility",     "KHR_animation_pointer",
    "KHR_materials_pbrSpecularGlossiness", "KHR_mesh_quantization", "KHR_materials_emissive_strength",
    "KHR_materials_unlit",       "KHR_texture_transform",   "KHR_materials_ior",
    "KHR_materials_specular",    "KHR_materials_transmission", "KHR_materials_clearcoat",
    "KHR_materials_sheen",       "KHR_materials_volume",    "EXT_lights_image_based",
};

constexpr std::uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr std::uint32_t kChunkBin = 0x004E4942;      // "BIN\0"

std::uint32_t readU32(const std::string& data, std::size_t offset);

// RFC 4648 base64 decoding. Written here (twenty lines) rather than adding a dependency.
std::string decodeBase64(std::string_view in, bool& ok);

std::uint64_t base64DecodedSize(std::string_view payload);

std::string percentDecode(std::string_view uri);

int componentBytes(int componentType);

int typeComponents(std::string_view type);

struct AccessorInfo {
  int bufferView = -1;
  std::size_t byteOffset = 0;
  int componentType = 0;
  bool normalized = false;
  std::size_t count = 0;
  std::string type;
  int components = 0;
};

class GltfReader {
 public:
  GltfReader(fs::path path, Scene& scene) : path_(std::move(path)), scene_(scene) {
    display_ = path_.string();
    baseDir_ = path_.has_parent_path() ? path_.parent_path() : fs::path(".");
  }

  void read();

 private:
  [[noreturn]] void fail(ErrorCode code, std::string_view pointer, std::string_view message) const;
  [[noreturn]] void invalid(std::string_view pointer, std::string_view message) const;

  void addSourceFile(const fs::path& p, std::uint64_t bytes);

  std::string_view parseGlbContainer();

  void parseJson(std::string_view text);

  // ---- JSON helpers: each names the pointer it was asked about --------------------------------

  static std::string child(std::string_view pointer, std::string_view key);
  static std::string child(std::string_view pointer, std::size_t index);

  const json* member(const json& object, std::string_view key) const;

  const json& array(const json& object, std::string_view key, std::string_view pointer) const;

  const json& objectAt(const json& array, std::size_t i, std::string_view pointer) const;

  // An index into a top-level array of `limit` elements; -1 when absent and not required.
  int index(const json& object, std::string_view key, std::string_view pointer, std::size_t limit,
            std::string_view what, bool required = false) const;

  // An array of indices into a top-level array of `limit` elements.
  std::vector<int> indexList(const json& object, std::string_view key, std::string_view pointer, std::size_t limit,
                             std::string_view what) const;

  std::vector<double> numberList(const json& object, std::string_view key, std::string_view pointer) const;

  double number(const json& object, std::string_view key, std::string_view pointer, double fallback,
                bool required = false) const;

  std::size_t unsignedInt(const json& object, std::string_view key, std::string_view pointer,
                          std::size_t fallback, bool required = false) const {
    const json* v = member(object, key);
    if (!v) {
      if (required) invalid(child(pointer, key), "missing; expected a non-negative integer");
      return fallback;
    }
    if (!v->is_number_integer() || v->get<long long>() < 0)
      invalid(child(pointer, key), fmt::format("expected a non-negative integer, got {}", v->dump()));
    return static_cast<std::size_t>(v->get<long long>());
  }

  std::string string(const json& object, std::string_view key, std::string_view pointer,
                     std::string fallback = {}) const;

  bool boolean(const json& object, std::string_view key, std::string_view pointer, bool fallback) const;

  template <int N>
  glm::vec<N, double> vector(const json& object, std::string_view key, std::string_view pointer,
                             glm::vec<N, double> fallback) const {
    const json* v = member(object, key);
    if (!v) return fallback;
    const auto p = child(pointer, key);
    if (!v->is_array() || v->size() != N) invalid(p, fmt::format("expected an array of {} numbers", N));
    glm::vec<N, double> out;
    for (int i = 0; i < N; ++i) {
      if (!(*v)[i].is_number()) invalid(child(p, i), "expected a number");
      out[i] = (*v)[i].get<double>();
      if (!std::isfinite(out[i])) invalid(child(p, i), "expected a finite number");
    }
    return out;
  }

  const json* extension(const json& object, std::string_view name) const;

  // ---- URIs ----------------------------------------------------------------------------------

  // Resolves a relative URI inside the dataset's folder; refuses absolute paths, URLs and `..`
  // escapes so that a dataset can never make dynbench read files outside itself.
  fs::path resolveUri(const std::string& uri, std::string_view pointer) const;

  // ---- top level -----------------------------------------------------------------------------

  void readAsset();

  void readBuffers();

  struct BufferView {
    int buffer = -1;
    std::size_t offset = 0, length = 0, stride = 0;
  };

  void readBufferViews();

  void readAccessors();

  static std::size_t elementBytes(const AccessorInfo& a);

  static double componentValue(const char* src, int componentType, bool normalized);

  // All elements of an accessor as doubles, components flattened, sparse substitution applied.
  std::vector<double> readAccessor(int accessorIndex) const;

  void readSparse(const json& sparse, const AccessorInfo& a, const std::string& p, std::vector<double>& out) const;

  const AccessorInfo& accessorAt(int i) const { return accessors_[static_cast<std::size_t>(i)]; }

  void requireType(int accessor, std::string_view pointer, std::initializer_list<std::string_view> types) const {
    const auto& a = accessorAt(accessor);
    for (auto t : types)
      if (a.type == t) return;
    std::string list;
    for (auto t : types) list += (list.empty() ? "" : " or ") + std::string(t);
    invalid(pointer, fmt::format("accessor {} has type {}; expected {}", accessor, a.type, list));
  }

  void requireFinite(const std::vector<double>& values, int components, std::string_view pointer,
                     std::string_view what) const {
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        invalid(pointer, fmt::format("{} {} (component {}) is {}; values must be finite", what,
                                     i / static_cast<std::size_t>(components), i % static_cast<std::size_t>(components),
                                     std::isnan(values[i]) ? "NaN" : "infinite"));
  }

  void readImages();

  TextureRef textureRef(const json& object, std::string_view key, std::string_view pointer) const;

  void readMaterials();

  template <typename Vec>
  std::vector<Vec> readVectors(int accessor, std::string_view pointer) const {
    constexpr int N = Vec::length();
    const auto values = readAccessor(accessor);
    requireFinite(values, accessorAt(accessor).components, pointer, "element");
    std::vector<Vec> out(accessorAt(accessor).count);
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < N; ++c) out[i][c] = static_cast<typename Vec::value_type>(values[i * N + c]);
    return out;
  }

  void readMeshes();

  Primitive readPrimitive(const json& pr, const std::string& p);

  void readCameras();
  static constexpr double kPiRadians = 3.14159265358979323846;

  void readLights();

  // DYNBENCH_environment (docs/dataset.md): the image is resolved like any URI and must exist.
  void readEnvironment();

  void readNodes();

  void readSkins();

  void readScenes();

  // Parses "/nodes/N/extensions/KHR_node_visibility/visible"; -1 for any other pointer.
  void readCameraCuts(const json& extras, const std::string& pointer, Node& node);
  static int visibilityPointerNode(const std::string& pointer);
  struct LightPointer {
    int light = -1;
    AnimationPath path = AnimationPath::kLightColor;
  };
  static LightPointer lightPointer(const std::string& pointer);

  void readAnimations();

  Sampler readSampler(const json& s, const std::string& p, int components, const std::string& use);

  fs::path path_;
  std::string display_;
  fs::path baseDir_;
  Scene& scene_;
  std::string fileBytes_;
  std::optional<std::string_view> glbBin_;
  json root_;
  std::vector<std::string> buffers_;
  std::vector<BufferView> bufferViews_;
  std::vector<AccessorInfo> accessors_;
  std::vector<int> textureImage_;
};

}  // namespace dynbench::scene::gltf_detail
