#pragma once
// The capture format's lines (docs/capture-format.md): a record split at ':' with typed access to
// its fields, and a buffered line source that notices a last line cut short. Every failure throws
// Failure naming file:line, caught where a reader returns its Expected. Shared by the capture
// reader and the model-mesh reader; not for use outside src/capture.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "capture/format.h"
#include "capture/reader.h"
#include "core/error.h"

namespace dynbench::capture {

// One line split at ':' with typed access; every failure names file:line.
class Line {
 public:
  Line(const std::string& file, std::size_t number, std::string_view text) : file_(file), number_(number) {
    std::size_t start = 0;
    while (true) {
      const auto colon = text.find(':', start);
      fields_.push_back(text.substr(start, colon == std::string_view::npos ? std::string_view::npos : colon - start));
      if (colon == std::string_view::npos) break;
      start = colon + 1;
    }
  }

  [[noreturn]] void fail(const std::string& message, ErrorCode code = ErrorCode::kInvalidData) const {
    throw Failure{Error{code, fmt::format("{}:{}: {}", file_, number_, message)}};
  }

  std::string_view token() const { return fields_[0]; }
  std::size_t size() const { return fields_.size(); }  // fields after the token + 1
  std::size_t number() const { return number_; }

  void expectFields(std::size_t count, const char* layout) const {
    if (fields_.size() != count + 1)
      fail(fmt::format("record '{}' needs {} fields ({}), got {}", token(), count, layout, fields_.size() - 1), ErrorCode::kParse);
  }

  double real(std::size_t i, const char* what) const {
    const auto f = fields_.at(i);
    double v = 0;
    const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
    if (ec != std::errc() || end != f.data() + f.size() || f.empty())
      fail(fmt::format("field {} ({}) is '{}', not a number", i, what, f), ErrorCode::kParse);
    if (!std::isfinite(v)) fail(fmt::format("field {} ({}) is {}; values must be finite", i, what, f));
    return v;
  }

  template <typename Int>
  Int integer(std::size_t i, const char* what) const {
    const auto f = fields_.at(i);
    Int v = 0;
    const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
    if (ec != std::errc() || end != f.data() + f.size() || f.empty())
      fail(fmt::format("field {} ({}) is '{}', not an integer in range", i, what, f), ErrorCode::kParse);
    return v;
  }

  std::string text(std::size_t i) const {
    std::string out;
    if (!unescapeField(fields_.at(i), out)) fail(fmt::format("field {} has a '%' not followed by two hex digits", i), ErrorCode::kParse);
    return out;
  }

  DualQuaternion dualQuat(std::size_t first) const {
    DualQuaternion q;
    q.real = glm::dquat(real(first + 3, "rw"), real(first, "rx"), real(first + 1, "ry"), real(first + 2, "rz"));
    q.dual = glm::dquat(real(first + 7, "dw"), real(first + 4, "dx"), real(first + 5, "dy"), real(first + 6, "dz"));
    if (glm::length(q.real) < 1e-6) fail(fmt::format("the dual quaternion at field {} has a zero rotation part", first));
    return q;
  }

 private:
  const std::string& file_;
  std::size_t number_;
  std::vector<std::string_view> fields_;
};

// Reads lines and tells whether the last one ended with a newline (a line without one was cut).
class LineSource {
 public:
  explicit LineSource(const std::filesystem::path& path) : buffer_(1 << 20) {
    // A large buffer, set before opening (libstdc++ honours it only then).
    in_.rdbuf()->pubsetbuf(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    in_.open(path, std::ios::binary);
  }
  bool ok() const { return static_cast<bool>(in_) || in_.eof(); }
  bool opened() const { return in_.is_open(); }
  // False at the end. `complete` is false for a last line without its newline.
  bool next(std::string& line, bool& complete) {
    if (!std::getline(in_, line)) return false;
    ++number_;
    complete = !in_.eof();
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }
  std::size_t number() const { return number_; }

 private:
  std::vector<char> buffer_;
  std::ifstream in_;
  std::size_t number_ = 0;
};

inline bool isComment(const std::string& line) { return line.empty() || line[0] == '#'; }


// The `C` record's four fields: aspect, vertical field of view, near and far.
inline CameraSettings cameraSettings(const Line& l) {
  l.expectFields(4, "aspect:yfov:znear:zfar");
  CameraSettings c{l.real(1, "aspect"), l.real(2, "yfov"), l.real(3, "znear"), l.real(4, "zfar")};
  if (!(c.aspect > 0) || !(c.yfovDegrees > 0 && c.yfovDegrees < 180) || !(c.znear > 0) || !(c.zfar > c.znear))
    l.fail("camera settings need aspect > 0, 0 < yfov < 180 degrees and 0 < znear < zfar");
  return c;
}

// A models/*.txt file (model_mesh_reader.cpp), throwing Failure: what readModelMesh returns, and
// what the capture reader reads each declared model with.
CapturedModel parseModelMesh(const std::filesystem::path& path);

}  // namespace dynbench::capture
