// glTF 2.0 reader (.gltf with external or embedded buffers, .glb).
//
// Why our own reader on nlohmann::json instead of tinygltf: every error must name the JSON pointer
// of the offending value (tinygltf's messages do not carry one); buffer and image URIs must be
// checked for leaving the dataset's folder before any file is opened (tinygltf resolves them inside
// its own loader); and stats must never read or decode texture images, only stat their size.
// JSON parsing itself is nlohmann::json's. Inside this file errors are thrown as Failure (core/error.h) and turned
// into an Expected at the public entry point; nothing escapes as an exception.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <set>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/files.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

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

std::uint32_t readU32(const std::string& data, std::size_t offset) {
  std::uint32_t v;
  std::memcpy(&v, data.data() + offset, 4);
  return v;  // GLB is little-endian, as is every platform dynbench builds on
}

// RFC 4648 base64 decoding. Written here (twenty lines) rather than adding a dependency.
std::string decodeBase64(std::string_view in, bool& ok) {
  static const std::array<int, 256> table = [] {
    std::array<int, 256> t{};
    t.fill(-1);
    const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(alphabet[i])] = i;
    return t;
  }();
  std::string out;
  out.reserve(in.size() / 4 * 3);
  unsigned buffer = 0;
  int bits = 0;
  ok = true;
  for (char c : in) {
    if (c == '=') break;
    const int v = table[static_cast<unsigned char>(c)];
    if (v < 0) {
      ok = false;
      return {};
    }
    buffer = (buffer << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<char>((buffer >> bits) & 0xFF));
    }
  }
  return out;
}

std::uint64_t base64DecodedSize(std::string_view payload) {
  std::size_t padding = 0;
  while (!payload.empty() && payload.back() == '=') {
    payload.remove_suffix(1);
    ++padding;
  }
  return payload.size() * 3 / 4;
}

std::string percentDecode(std::string_view uri) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
      out.push_back(static_cast<char>(std::stoi(std::string(uri.substr(i + 1, 2)), nullptr, 16)));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

int componentBytes(int componentType) {
  switch (componentType) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
  }
}

int typeComponents(std::string_view type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

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

  void read() {
    auto bytes = readWholeFile(path_);
    if (!bytes) throw Failure{Error{bytes.error().code, bytes.error().message}};
    fileBytes_ = std::move(*bytes);
    scene_.source.path = path_;
    addSourceFile(path_, fileBytes_.size());

    std::string_view jsonText = fileBytes_;
    const bool isGlb = fileBytes_.size() >= 4 && readU32(fileBytes_, 0) == kGlbMagic;
    if (isGlb || path_.extension() == ".glb" || path_.extension() == ".GLB") {
      scene_.source.format = "GLB";
      jsonText = parseGlbContainer();
    } else {
      scene_.source.format = "glTF";
    }
    parseJson(jsonText);
    readAsset();
    readBuffers();
    readBufferViews();
    readAccessors();
    readImages();
    readMaterials();
    readMeshes();
    readCameras();
    readLights();
    readEnvironment();
    readNodes();
    readSkins();
    readScenes();
    readAnimations();
  }

 private:
  [[noreturn]] void fail(ErrorCode code, std::string_view pointer, std::string_view message) const {
    throw Failure{Error{code, fmt::format("{}: {}: {}", display_, pointer.empty() ? "/" : pointer, message)}};
  }
  [[noreturn]] void invalid(std::string_view pointer, std::string_view message) const {
    fail(ErrorCode::kInvalidData, pointer, message);
  }

  void addSourceFile(const fs::path& p, std::uint64_t bytes) {
    const auto normal = p.lexically_normal();
    for (const auto& f : scene_.source.files)
      if (f.path == normal) return;
    scene_.source.files.push_back({normal, bytes});
  }

  std::string_view parseGlbContainer() {
    const std::size_t size = fileBytes_.size();
    if (size < 12)
      fail(ErrorCode::kParse, "", fmt::format("truncated GLB: the file has {} bytes, the GLB header needs 12", size));
    if (readU32(fileBytes_, 0) != kGlbMagic)
      fail(ErrorCode::kParse, "", "not a GLB file: the first 4 bytes are not \"glTF\"");
    const auto version = readU32(fileBytes_, 4);
    if (version != 2) fail(ErrorCode::kUnsupported, "", fmt::format("GLB version {} (expected 2)", version));
    const std::uint64_t declared = readU32(fileBytes_, 8);
    if (declared > size)
      fail(ErrorCode::kParse, "",
           fmt::format("truncated GLB: the header declares {} bytes but the file has {}", declared, size));
    std::size_t offset = 12;
    std::string_view jsonChunk;
    int chunkIndex = 0;
    while (offset < declared) {
      if (offset + 8 > declared)
        fail(ErrorCode::kParse, "", fmt::format("truncated GLB: chunk {} header at byte {} runs past the end ({} bytes)", chunkIndex, offset, declared));
      const std::uint64_t length = readU32(fileBytes_, offset);
      const auto type = readU32(fileBytes_, offset + 4);
      if (offset + 8 + length > declared)
        fail(ErrorCode::kParse, "",
             fmt::format("truncated GLB: chunk {} declares {} bytes at byte {} but only {} remain", chunkIndex,
                         length, offset + 8, declared - offset - 8));
      const std::string_view body(fileBytes_.data() + offset + 8, length);
      if (chunkIndex == 0) {
        if (type != kChunkJson) fail(ErrorCode::kParse, "", "GLB: the first chunk is not of type JSON");
        jsonChunk = body;
      } else if (type == kChunkBin && !glbBin_) {
        glbBin_ = body;
      }
      offset += 8 + length;
      ++chunkIndex;
    }
    if (chunkIndex == 0) fail(ErrorCode::kParse, "", "GLB: no JSON chunk");
    return jsonChunk;
  }

  void parseJson(std::string_view text) {
    try {
      root_ = json::parse(text.begin(), text.end());
    } catch (const json::parse_error& e) {
      // Turn the byte offset into line:column, which is what an editor shows.
      std::size_t line = 1, column = 1;
      const std::size_t end = std::min<std::size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
      for (std::size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') {
          ++line;
          column = 1;
        } else {
          ++column;
        }
      }
      std::string what = e.what();
      if (auto pos = what.find("syntax error"); pos != std::string::npos) what = what.substr(pos);
      throw Failure{Error{ErrorCode::kParse,
                      fmt::format("{}: line {}, column {}: invalid JSON: {}", display_, line, column, what)}};
    }
    if (!root_.is_object()) invalid("", "the top-level JSON value must be an object");
  }

  // ---- JSON helpers: each names the pointer it was asked about --------------------------------

  static std::string child(std::string_view pointer, std::string_view key) {
    return fmt::format("{}/{}", pointer, key);
  }
  static std::string child(std::string_view pointer, std::size_t index) {
    return fmt::format("{}/{}", pointer, index);
  }

  const json* member(const json& object, std::string_view key) const {
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  const json& array(const json& object, std::string_view key, std::string_view pointer) const {
    static const json empty = json::array();
    const json* v = member(object, key);
    if (!v) return empty;
    if (!v->is_array()) invalid(child(pointer, key), "expected an array");
    return *v;
  }

  const json& objectAt(const json& array, std::size_t i, std::string_view pointer) const {
    if (!array[i].is_object()) invalid(child(pointer, i), "expected an object");
    return array[i];
  }

  // An index into a top-level array of `limit` elements; -1 when absent and not required.
  int index(const json& object, std::string_view key, std::string_view pointer, std::size_t limit,
            std::string_view what, bool required = false) const {
    const json* v = member(object, key);
    const auto p = child(pointer, key);
    if (!v) {
      if (required) invalid(p, fmt::format("missing; expected the index of a {}", what));
      return -1;
    }
    if (!v->is_number_integer() || v->get<long long>() < 0)
      invalid(p, fmt::format("expected a non-negative integer index of a {}, got {}", what, v->dump()));
    const auto i = v->get<long long>();
    if (static_cast<std::size_t>(i) >= limit)
      invalid(p, fmt::format("{} index {} is out of range (the file has {} {}s)", what, i, limit, what));
    return static_cast<int>(i);
  }

  // An array of indices into a top-level array of `limit` elements.
  std::vector<int> indexList(const json& object, std::string_view key, std::string_view pointer, std::size_t limit,
                             std::string_view what) const {
    const json& list = array(object, key, pointer);
    std::vector<int> out;
    out.reserve(list.size());
    for (std::size_t k = 0; k < list.size(); ++k) {
      const json& v = list[k];
      if (!v.is_number_integer() || v.get<long long>() < 0 || static_cast<std::size_t>(v.get<long long>()) >= limit)
        invalid(child(child(pointer, key), k), fmt::format("expected a {} index below {}, got {}", what, limit, v.dump()));
      out.push_back(v.get<int>());
    }
    return out;
  }

  std::vector<double> numberList(const json& object, std::string_view key, std::string_view pointer) const {
    const json& list = array(object, key, pointer);
    std::vector<double> out;
    out.reserve(list.size());
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (!list[k].is_number() || !std::isfinite(list[k].get<double>()))
        invalid(child(child(pointer, key), k), fmt::format("expected a finite number, got {}", list[k].dump()));
      out.push_back(list[k].get<double>());
    }
    return out;
  }

  double number(const json& object, std::string_view key, std::string_view pointer, double fallback,
                bool required = false) const {
    const json* v = member(object, key);
    if (!v) {
      if (required) invalid(child(pointer, key), "missing; expected a number");
      return fallback;
    }
    if (!v->is_number()) invalid(child(pointer, key), fmt::format("expected a number, got {}", v->dump()));
    const double d = v->get<double>();
    if (!std::isfinite(d)) invalid(child(pointer, key), "expected a finite number");
    return d;
  }

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
                     std::string fallback = {}) const {
    const json* v = member(object, key);
    if (!v) return fallback;
    if (!v->is_string()) invalid(child(pointer, key), fmt::format("expected a string, got {}", v->dump()));
    return v->get<std::string>();
  }

  bool boolean(const json& object, std::string_view key, std::string_view pointer, bool fallback) const {
    const json* v = member(object, key);
    if (!v) return fallback;
    if (!v->is_boolean()) invalid(child(pointer, key), fmt::format("expected true or false, got {}", v->dump()));
    return v->get<bool>();
  }

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

  const json* extension(const json& object, std::string_view name) const {
    const json* ext = member(object, "extensions");
    if (!ext || !ext->is_object()) return nullptr;
    const json* e = member(*ext, name);
    return e && e->is_object() ? e : nullptr;
  }

  // ---- URIs ----------------------------------------------------------------------------------

  // Resolves a relative URI inside the dataset's folder; refuses absolute paths, URLs and `..`
  // escapes so that a dataset can never make dynbench read files outside itself.
  fs::path resolveUri(const std::string& uri, std::string_view pointer) const {
    const std::string decoded = percentDecode(uri);
    const auto colon = decoded.find(':');
    const auto slash = decoded.find('/');
    if (colon != std::string::npos && (slash == std::string::npos || colon < slash))
      invalid(pointer, fmt::format("'{}' is a URL or drive path; dynbench reads only data: URIs and "
                                   "relative paths inside the dataset's folder", uri));
    if (!decoded.empty() && (decoded[0] == '/' || decoded[0] == '\\'))
      invalid(pointer, fmt::format("'{}' is an absolute path; URIs must be relative to the dataset's folder", uri));
    const fs::path relative = fs::path(decoded).lexically_normal();
    if (relative.empty() || *relative.begin() == "..")
      invalid(pointer, fmt::format("'{}' leaves the dataset's folder; URIs must stay inside it", uri));
    return baseDir_ / relative;
  }

  // ---- top level -----------------------------------------------------------------------------

  void readAsset() {
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

  void readBuffers() {
    const json& buffers = array(root_, "buffers", "");
    for (std::size_t i = 0; i < buffers.size(); ++i) {
      const auto p = child("/buffers", i);
      const json& b = objectAt(buffers, i, "/buffers");
      const std::size_t byteLength = unsignedInt(b, "byteLength", p, 0, true);
      std::string data;
      const json* uri = member(b, "uri");
      if (!uri) {
        if (i != 0 || !glbBin_)
          invalid(p, "has no uri and is not the GLB binary chunk (only buffer 0 of a .glb may omit it)");
        data.assign(glbBin_->data(), glbBin_->size());
      } else {
        if (!uri->is_string()) invalid(child(p, "uri"), "expected a string");
        const auto u = uri->get<std::string>();
        if (u.rfind("data:", 0) == 0) {
          const auto comma = u.find(',');
          if (comma == std::string::npos || u.substr(0, comma).find(";base64") == std::string::npos)
            invalid(child(p, "uri"), "data URI is not base64 encoded (expected data:...;base64,...)");
          bool ok = false;
          data = decodeBase64(std::string_view(u).substr(comma + 1), ok);
          if (!ok) invalid(child(p, "uri"), "data URI holds characters that are not base64");
        } else {
          const fs::path file = resolveUri(u, child(p, "uri"));
          auto bytes = readWholeFile(file);
          if (!bytes)
            fail(ErrorCode::kIo, child(p, "uri"),
                 fmt::format("cannot read buffer '{}' ({})", u, bytes.error().message));
          data = std::move(*bytes);
          addSourceFile(file, data.size());
        }
      }
      if (data.size() < byteLength)
        invalid(p, fmt::format("byteLength is {} but the buffer data has only {} bytes", byteLength, data.size()));
      buffers_.push_back(std::move(data));
    }
  }

  struct BufferView {
    int buffer = -1;
    std::size_t offset = 0, length = 0, stride = 0;
  };

  void readBufferViews() {
    const json& views = array(root_, "bufferViews", "");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const auto p = child("/bufferViews", i);
      const json& v = objectAt(views, i, "/bufferViews");
      BufferView view;
      view.buffer = index(v, "buffer", p, buffers_.size(), "buffer", true);
      view.offset = unsignedInt(v, "byteOffset", p, 0);
      view.length = unsignedInt(v, "byteLength", p, 0, true);
      view.stride = unsignedInt(v, "byteStride", p, 0);
      if (view.stride != 0 && (view.stride < 4 || view.stride > 252 || view.stride % 4 != 0))
        invalid(child(p, "byteStride"), fmt::format("byteStride {} must be a multiple of 4 in [4, 252]", view.stride));
      const auto bufferLength = buffers_[static_cast<std::size_t>(view.buffer)].size();
      if (view.offset + view.length > bufferLength)
        invalid(p, fmt::format("byteOffset {} + byteLength {} runs past the end of buffer {} ({} bytes)",
                               view.offset, view.length, view.buffer, bufferLength));
      bufferViews_.push_back(view);
    }
  }

  void readAccessors() {
    const json& accessors = array(root_, "accessors", "");
    for (std::size_t i = 0; i < accessors.size(); ++i) {
      const auto p = child("/accessors", i);
      const json& a = objectAt(accessors, i, "/accessors");
      AccessorInfo info;
      info.bufferView = index(a, "bufferView", p, bufferViews_.size(), "bufferView");
      info.byteOffset = unsignedInt(a, "byteOffset", p, 0);
      info.componentType = static_cast<int>(unsignedInt(a, "componentType", p, 0, true));
      if (componentBytes(info.componentType) == 0)
        invalid(child(p, "componentType"),
                fmt::format("{} is not a glTF component type (5120, 5121, 5122, 5123, 5125 or 5126)", info.componentType));
      info.normalized = boolean(a, "normalized", p, false);
      info.count = unsignedInt(a, "count", p, 0, true);
      if (info.count == 0) invalid(child(p, "count"), "must be at least 1");
      info.type = string(a, "type", p);
      info.components = typeComponents(info.type);
      if (info.components == 0)
        invalid(child(p, "type"), fmt::format("'{}' is not SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4", info.type));
      if (info.bufferView >= 0) {
        const auto& view = bufferViews_[static_cast<std::size_t>(info.bufferView)];
        if (info.count > view.length)  // also keeps the byte arithmetic below from overflowing
          invalid(p, fmt::format("count {} is more elements than bufferView {} has bytes ({})", info.count,
                                 info.bufferView, view.length));
        const std::size_t element = elementBytes(info);
        const std::size_t stride = view.stride ? view.stride : element;
        const std::size_t needed = info.byteOffset + stride * (info.count - 1) + element;
        if (needed > view.length)
          invalid(p, fmt::format("needs {} bytes (byteOffset {} + {} x stride {} + element {}) but bufferView {} "
                                 "is only {} bytes long",
                                 needed, info.byteOffset, info.count - 1, stride, element, info.bufferView,
                                 view.length));
      }
      accessors_.push_back(info);
    }
  }

  static std::size_t elementBytes(const AccessorInfo& a) {
    // Matrix columns are padded to 4-byte boundaries for 1- and 2-byte components (glTF §3.6.2.4).
    const int cb = componentBytes(a.componentType);
    if (a.type == "MAT2" && cb == 1) return 8;
    if (a.type == "MAT3" && cb == 1) return 12;
    if (a.type == "MAT3" && cb == 2) return 24;
    return static_cast<std::size_t>(cb * a.components);
  }

  static double componentValue(const char* src, int componentType, bool normalized) {
    switch (componentType) {
      case 5120: { std::int8_t v; std::memcpy(&v, src, 1); return normalized ? std::max(v / 127.0, -1.0) : v; }
      case 5121: { std::uint8_t v; std::memcpy(&v, src, 1); return normalized ? v / 255.0 : v; }
      case 5122: { std::int16_t v; std::memcpy(&v, src, 2); return normalized ? std::max(v / 32767.0, -1.0) : v; }
      case 5123: { std::uint16_t v; std::memcpy(&v, src, 2); return normalized ? v / 65535.0 : v; }
      case 5125: { std::uint32_t v; std::memcpy(&v, src, 4); return v; }
      case 5126: { float v; std::memcpy(&v, src, 4); return v; }
    }
    return 0.0;
  }

  // All elements of an accessor as doubles, components flattened, sparse substitution applied.
  std::vector<double> readAccessor(int accessorIndex) const {
    const auto& a = accessors_[static_cast<std::size_t>(accessorIndex)];
    const auto p = child("/accessors", static_cast<std::size_t>(accessorIndex));
    std::vector<double> out(a.count * static_cast<std::size_t>(a.components), 0.0);
    const int cb = componentBytes(a.componentType);
    if (a.bufferView >= 0) {
      const auto& view = bufferViews_[static_cast<std::size_t>(a.bufferView)];
      const char* base = buffers_[static_cast<std::size_t>(view.buffer)].data() + view.offset + a.byteOffset;
      const std::size_t stride = view.stride ? view.stride : elementBytes(a);
      const int columns = a.type.starts_with("MAT") ? (a.type == "MAT2" ? 2 : a.type == "MAT3" ? 3 : 4) : 1;
      const int rows = a.components / columns;
      const std::size_t columnStride = a.type.starts_with("MAT") ? ((static_cast<std::size_t>(rows * cb) + 3) & ~std::size_t{3}) : 0;
      for (std::size_t e = 0; e < a.count; ++e) {
        const char* element = base + e * stride;
        for (int c = 0; c < columns; ++c)
          for (int r = 0; r < rows; ++r)
            out[e * a.components + static_cast<std::size_t>(c * rows + r)] =
                componentValue(element + c * columnStride + r * cb, a.componentType, a.normalized);
      }
    }
    const json& accessorJson = root_["accessors"][static_cast<std::size_t>(accessorIndex)];
    if (const json* sparse = member(accessorJson, "sparse")) readSparse(*sparse, a, child(p, "sparse"), out);
    return out;
  }

  void readSparse(const json& sparse, const AccessorInfo& a, const std::string& p, std::vector<double>& out) const {
    if (!sparse.is_object()) invalid(p, "expected an object");
    const std::size_t count = unsignedInt(sparse, "count", p, 0, true);
    const json* indices = member(sparse, "indices");
    const json* values = member(sparse, "values");
    if (!indices || !indices->is_object()) invalid(child(p, "indices"), "missing");
    if (!values || !values->is_object()) invalid(child(p, "values"), "missing");
    const auto ip = child(p, "indices"), vp = child(p, "values");
    const int iView = index(*indices, "bufferView", ip, bufferViews_.size(), "bufferView", true);
    const int iType = static_cast<int>(unsignedInt(*indices, "componentType", ip, 0, true));
    if (iType != 5121 && iType != 5123 && iType != 5125)
      invalid(child(ip, "componentType"), "sparse indices must be 5121, 5123 or 5125");
    const int vView = index(*values, "bufferView", vp, bufferViews_.size(), "bufferView", true);
    const std::size_t iOffset = unsignedInt(*indices, "byteOffset", ip, 0);
    const std::size_t vOffset = unsignedInt(*values, "byteOffset", vp, 0);
    const auto& iv = bufferViews_[static_cast<std::size_t>(iView)];
    const auto& vv = bufferViews_[static_cast<std::size_t>(vView)];
    const int ib = componentBytes(iType), cb = componentBytes(a.componentType);
    if (count > a.count) invalid(child(p, "count"), fmt::format("{} sparse values for an accessor of {} elements", count, a.count));
    if (iOffset + count * static_cast<std::size_t>(ib) > iv.length)
      invalid(ip, fmt::format("{} indices do not fit in bufferView {} ({} bytes)", count, iView, iv.length));
    if (vOffset + count * static_cast<std::size_t>(cb * a.components) > vv.length)
      invalid(vp, fmt::format("{} values do not fit in bufferView {} ({} bytes)", count, vView, vv.length));
    const char* ibase = buffers_[static_cast<std::size_t>(iv.buffer)].data() + iv.offset + iOffset;
    const char* vbase = buffers_[static_cast<std::size_t>(vv.buffer)].data() + vv.offset + vOffset;
    for (std::size_t k = 0; k < count; ++k) {
      const auto target = static_cast<std::size_t>(componentValue(ibase + k * ib, iType, false));
      if (target >= a.count)
        invalid(ip, fmt::format("sparse index {} at position {} is out of range (count {})", target, k, a.count));
      for (int c = 0; c < a.components; ++c)
        out[target * a.components + c] =
            componentValue(vbase + (k * a.components + c) * cb, a.componentType, a.normalized);
    }
  }

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

  void readImages() {
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

  TextureRef textureRef(const json& object, std::string_view key, std::string_view pointer) const {
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

  void readMaterials() {
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

  void readMeshes() {
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

  Primitive readPrimitive(const json& pr, const std::string& p) {
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

  void readCameras() {
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
  static constexpr double kPiRadians = 3.14159265358979323846;

  void readLights() {
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
  void readEnvironment() {
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

  void readNodes() {
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

  void readSkins() {
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

  void readScenes() {
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

  // Parses "/nodes/N/extensions/KHR_node_visibility/visible"; -1 for any other pointer.
  static int visibilityPointerNode(const std::string& pointer) {
    static constexpr std::string_view prefix = "/nodes/";
    static constexpr std::string_view suffix = "/extensions/KHR_node_visibility/visible";
    if (!pointer.starts_with(prefix) || !pointer.ends_with(suffix)) return -1;
    const auto digits = pointer.substr(prefix.size(), pointer.size() - prefix.size() - suffix.size());
    if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), ::isdigit)) return -1;
    return std::stoi(digits);
  }

  void readAnimations() {
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
          if (node < 0) {
            scene_.warnings.push_back(fmt::format("{}: {}: animation pointer '{}' is ignored (dynbench animates only "
                                                  "node transforms, morph weights and KHR_node_visibility)", display_, cp, pointer));
            continue;
          }
          if (static_cast<std::size_t>(node) >= scene_.nodes.size())
            invalid(tp, fmt::format("pointer '{}' names node {} but the file has {} nodes", pointer, node, scene_.nodes.size()));
          channel.node = node;
          channel.path = AnimationPath::kVisibility;
          components = 1;
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

  Sampler readSampler(const json& s, const std::string& p, int components, const std::string& use) {
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

}  // namespace

Expected<Scene> loadGltf(const std::filesystem::path& path) {
  Scene scene;
  try {
    GltfReader(path, scene).read();
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  } catch (const nlohmann::json::exception& e) {
    return fail(ErrorCode::kInvalidData, "{}: {}", path.string(), e.what());
  } catch (const std::bad_alloc&) {
    return fail(ErrorCode::kInvalidData, "{}: out of memory while reading (a count or length is implausibly large)",
                path.string());
  } catch (const std::length_error&) {
    return fail(ErrorCode::kInvalidData, "{}: a count or length is implausibly large", path.string());
  }
  return scene;
}

std::string percentDecodeUri(std::string_view uri) { return percentDecode(uri); }

}  // namespace dynbench::scene
