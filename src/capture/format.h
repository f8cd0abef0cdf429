#pragma once
// Shared by the capture writer (SDK) and reader: version lines, string escaping, number text.
// The format itself: docs/capture-format.md.
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace dynbench::capture {

// Version 2 added the lights' range and the map's lighting (`L`); captures of version 1 also
// predate the adapters' signed normals, so they are refused, not converted. Version 3 (this one)
// added vertex animation: a mesh's key frames (ModelMesh version 2: `K`, `P`, `N`) and a
// capturable's key-frame pose each frame (`v`); version 2 captures and version 1 ModelMesh files
// read as before. ModelMesh version 3 added a mesh's material beyond its maps (`f`, `r`, `e`, `E`)
// and vertex colours (`c`); versions 1 and 2 read as before.
inline constexpr std::string_view kCaptureVersionLine = "dynbench-capture:3";
inline constexpr std::string_view kCaptureVersion2Line = "dynbench-capture:2";
inline constexpr std::string_view kModelMeshVersionLine = "dynbench-modelmesh:3";
inline constexpr std::string_view kModelMeshVersion2Line = "dynbench-modelmesh:2";
inline constexpr std::string_view kModelMeshVersion1Line = "dynbench-modelmesh:1";
inline constexpr std::string_view kCaptureFile = "Capture.txt";
inline constexpr std::string_view kModelsFolder = "models";

// What a capturable is; one id keeps one kind for its whole life.
enum class CapturableKind { kCamera, kStaticModel, kModel, kLight };

inline const char* capturableKindName(CapturableKind kind) {
  switch (kind) {
    case CapturableKind::kCamera: return "camera";
    case CapturableKind::kStaticModel: return "static map model";
    case CapturableKind::kModel: return "model";
    case CapturableKind::kLight: return "light";
  }
  return "?";
}

// '%', ':', CR and LF percent-encoded so that a string never splits a record.
inline std::string escapeField(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '%': out += "%25"; break;
      case ':': out += "%3A"; break;
      case '\r': out += "%0D"; break;
      case '\n': out += "%0A"; break;
      default: out += c;
    }
  }
  return out;
}

// The inverse of escapeField; false when a '%' is not followed by two hex digits.
inline bool unescapeField(std::string_view text, std::string& out) {
  auto hex = [](char c) { return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1; };
  out.clear();
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '%') {
      out += text[i];
      continue;
    }
    if (i + 2 >= text.size() || hex(text[i + 1]) < 0 || hex(text[i + 2]) < 0) return false;
    out += static_cast<char>(hex(text[i + 1]) * 16 + hex(text[i + 2]));
    i += 2;
  }
  return true;
}

// Floats with 9 significant digits read back to the same float; times (double) with 17.
inline void appendFloat(std::string& line, float value) { fmt::format_to(std::back_inserter(line), ":{:.9g}", value); }
inline void appendDouble(std::string& line, double value) { fmt::format_to(std::back_inserter(line), ":{:.17g}", value); }

}  // namespace dynbench::capture
