// glTF 2.0 reader (.gltf with external or embedded buffers, .glb).
//
// Why our own reader on nlohmann::json instead of tinygltf: every error must name the JSON pointer
// of the offending value (tinygltf's messages do not carry one); buffer and image URIs must be
// checked for leaving the dataset's folder before any file is opened (tinygltf resolves them inside
// its own loader); and stats must never read or decode texture images, only stat their size.
// JSON parsing itself is nlohmann::json's. Inside this file errors are thrown as Failure (core/error.h) and turned
// into an Expected at the public entry point; nothing escapes as an exception.
#include "scene/gltf_reader.h"

namespace dynbench::scene {
namespace gltf_detail {

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

void GltfReader::read() {
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

void GltfReader::fail(ErrorCode code, std::string_view pointer, std::string_view message) const {
  throw Failure{Error{code, fmt::format("{}: {}: {}", display_, pointer.empty() ? "/" : pointer, message)}};
}

void GltfReader::invalid(std::string_view pointer, std::string_view message) const {
  fail(ErrorCode::kInvalidData, pointer, message);
}

void GltfReader::addSourceFile(const fs::path& p, std::uint64_t bytes) {
  const auto normal = p.lexically_normal();
  for (const auto& f : scene_.source.files)
    if (f.path == normal) return;
  scene_.source.files.push_back({normal, bytes});
}

std::string_view GltfReader::parseGlbContainer() {
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

void GltfReader::parseJson(std::string_view text) {
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

}  // namespace gltf_detail

Expected<Scene> loadGltf(const std::filesystem::path& path) {
  Scene scene;
  try {
    gltf_detail::GltfReader(path, scene).read();
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

std::string percentDecodeUri(std::string_view uri) { return gltf_detail::percentDecode(uri); }

}  // namespace dynbench::scene
