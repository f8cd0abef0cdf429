#include "capture/reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include "capture/format.h"

namespace dynbench::capture {
namespace {

namespace fs = std::filesystem;

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
  explicit LineSource(const fs::path& path) : buffer_(1 << 20) {
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

bool isComment(const std::string& line) { return line.empty() || line[0] == '#'; }

CameraSettings cameraSettings(const Line& l) {
  l.expectFields(4, "aspect:yfov:znear:zfar");
  CameraSettings c{l.real(1, "aspect"), l.real(2, "yfov"), l.real(3, "znear"), l.real(4, "zfar")};
  if (!(c.aspect > 0) || !(c.yfovDegrees > 0 && c.yfovDegrees < 180) || !(c.znear > 0) || !(c.zfar > c.znear))
    l.fail("camera settings need aspect > 0, 0 < yfov < 180 degrees and 0 < znear < zfar");
  return c;
}

CapturedModel parseModelMesh(const fs::path& path) {
  const std::string file = path.string();
  LineSource source(path);
  if (!source.opened()) throw Failure{Error{ErrorCode::kIo, file + ": cannot open"}};
  CapturedModel model;
  model.file = path;
  std::string text;
  bool complete = true;
  if (!source.next(text, complete) || (text != kModelMeshVersionLine && text != kModelMeshVersion2Line && text != kModelMeshVersion1Line))
    throw Failure{Error{ErrorCode::kParse, fmt::format("{}:1: expected the version line '{}' (or '{}', '{}')", file, kModelMeshVersionLine,
                                                       kModelMeshVersion2Line, kModelMeshVersion1Line)}};
  std::vector<std::size_t> declaredVertices, declaredTriangles;
  std::vector<std::vector<int>> influenceCounts;  // per mesh, per vertex: joints listed by `j`
  std::set<int> bound, inverseBound;
  while (source.next(text, complete)) {
    if (isComment(text)) continue;
    const Line l(file, source.number(), text);
    if (!complete) l.fail("the file ends in the middle of this line", ErrorCode::kParse);
    const auto token = l.token();
    auto meshAt = [&](std::size_t field) -> CapturedMesh& {
      const int id = l.integer<int>(field, "mesh_id");
      if (id < 0 || static_cast<std::size_t>(id) >= model.meshes.size())
        l.fail(fmt::format("mesh {} is not declared (declare it with an M record first)", id));
      return model.meshes[static_cast<std::size_t>(id)];
    };
    if (token == "o") {
      l.expectFields(1, "model_path");
      if (!model.path.empty()) l.fail("a second 'o' record; a ModelMesh file holds one model");
      model.path = l.text(1);
    } else if (token == "M") {
      l.expectFields(4, "mesh_id:vertex_count:triangle_count:name");
      const int id = l.integer<int>(1, "mesh_id");
      if (id != static_cast<int>(model.meshes.size())) l.fail(fmt::format("mesh {} declared; expected {} (meshes in order)", id, model.meshes.size()));
      CapturedMesh mesh;
      mesh.id = id;
      mesh.name = l.text(4);
      declaredVertices.push_back(l.integer<std::size_t>(2, "vertex_count"));
      declaredTriangles.push_back(l.integer<std::size_t>(3, "triangle_count"));
      model.meshes.push_back(std::move(mesh));
      influenceCounts.emplace_back();
    } else if (token == "p" || token == "n") {
      l.expectFields(4, "mesh_id:x:y:z");
      auto& mesh = meshAt(1);
      (token == "p" ? mesh.positions : mesh.normals).push_back(glm::vec3(l.real(2, "x"), l.real(3, "y"), l.real(4, "z")));
    } else if (token == "t") {
      l.expectFields(3, "mesh_id:u:v");
      meshAt(1).uvs.push_back(glm::vec2(l.real(2, "u"), l.real(3, "v")));
    } else if (token == "j" || token == "w") {
      if (l.size() < 3 || l.size() > 6) l.fail(fmt::format("record '{}' needs a mesh_id and 1 to 4 values, got {} fields", token, l.size() - 1), ErrorCode::kParse);
      auto& mesh = meshAt(1);
      const int count = static_cast<int>(l.size()) - 2;
      auto& counts = influenceCounts[static_cast<std::size_t>(mesh.id)];
      if (token == "j") {
        glm::u16vec4 j(0);
        for (int k = 0; k < count; ++k) j[k] = l.integer<std::uint16_t>(static_cast<std::size_t>(2 + k), "joint");
        mesh.joints.push_back(j);
        counts.push_back(count);
      } else {
        if (mesh.weights.size() >= mesh.joints.size()) l.fail("a 'w' record without the 'j' record of its vertex before it");
        if (counts[mesh.weights.size()] != count)
          l.fail(fmt::format("{} weights for {} joints", count, counts[mesh.weights.size()]));
        glm::vec4 w(0.0f);
        for (int k = 0; k < count; ++k) w[k] = static_cast<float>(l.real(static_cast<std::size_t>(2 + k), "weight"));
        mesh.weights.push_back(w);
      }
    } else if (token == "i") {
      l.expectFields(4, "mesh_id:a:b:c");
      auto& mesh = meshAt(1);
      for (std::size_t k = 2; k <= 4; ++k) mesh.indices.push_back(l.integer<std::uint32_t>(k, "vertex index"));
    } else if (token == "a" || token == "g" || token == "E" || token == "m") {
      l.expectFields(2, "mesh_id:texture");
      (token == "a" ? meshAt(1).texture : token == "g" ? meshAt(1).maskTexture : meshAt(1).emissionTexture) = l.text(2);
      if (token == "m") meshAt(1).emissionTextureMeanOne = true;
    } else if (token == "f" || token == "c") {
      l.expectFields(5, "mesh_id:r:g:b:a");
      const glm::vec4 rgba(l.real(2, "r"), l.real(3, "g"), l.real(4, "b"), l.real(5, "a"));
      if (glm::any(glm::lessThan(rgba, glm::vec4(0.0f))) || glm::any(glm::greaterThan(rgba, glm::vec4(1.0f))))
        l.fail("colour components must lie in [0, 1]");
      if (token == "f") meshAt(1).baseColor = rgba;
      else meshAt(1).colors.push_back(rgba);
    } else if (token == "r") {
      l.expectFields(3, "mesh_id:metallic:roughness");
      const glm::vec2 mr(l.real(2, "metallic"), l.real(3, "roughness"));
      if (mr.x < 0 || mr.x > 1 || mr.y < 0 || mr.y > 1) l.fail("metallic and roughness must lie in [0, 1]");
      meshAt(1).metallicRoughness = mr;
    } else if (token == "e") {
      l.expectFields(4, "mesh_id:r:g:b");
      const glm::vec3 e(l.real(2, "r"), l.real(3, "g"), l.real(4, "b"));
      if (glm::any(glm::lessThan(e, glm::vec3(0.0f)))) l.fail("emission must not be negative");
      meshAt(1).emission = e;
    } else if (token == "K") {
      l.expectFields(2, "mesh_id:frame_count");
      auto& mesh = meshAt(1);
      const auto count = l.integer<std::size_t>(2, "frame_count");
      if (!mesh.keyPositions.empty()) l.fail(fmt::format("mesh {} has a second 'K' record", mesh.id));
      if (count == 0) l.fail("frame_count must be at least 1");
      if (model.keyFrames != 0 && count != model.keyFrames)
        l.fail(fmt::format("mesh {}: {} key frames, but the model's other meshes have {}", mesh.id, count, model.keyFrames));
      model.keyFrames = count;
      mesh.keyPositions.resize(count);
    } else if (token == "P" || token == "N") {
      l.expectFields(5, "mesh_id:frame:x:y:z");
      auto& mesh = meshAt(1);
      const auto frame = l.integer<std::size_t>(2, "frame");
      if (frame >= mesh.keyPositions.size())
        l.fail(fmt::format("key frame {} of mesh {}, which declares {} ('K' record first)", frame, mesh.id, mesh.keyPositions.size()));
      if (token == "N" && mesh.keyNormals.empty()) mesh.keyNormals.resize(mesh.keyPositions.size());
      (token == "P" ? mesh.keyPositions : mesh.keyNormals)[frame].push_back(glm::vec3(l.real(3, "x"), l.real(4, "y"), l.real(5, "z")));
    } else if (token == "b" || token == "x") {
      l.expectFields(11, "joint_id:parent:rx:ry:rz:rw:dx:dy:dz:dw:name");
      const int id = l.integer<int>(1, "joint_id");
      const int parent = l.integer<int>(2, "parent");
      if (token == "b") {
        if (id != static_cast<int>(model.joints.size())) l.fail(fmt::format("joint {} given; expected {} (joints in order)", id, model.joints.size()));
        if (parent < -1 || parent >= id) l.fail(fmt::format("joint {}: parent {} must be -1 or an earlier joint", id, parent));
        CapturedJoint joint;
        joint.id = id;
        joint.parent = parent;
        joint.name = l.text(11);
        joint.bindPose = l.dualQuat(3);
        model.joints.push_back(std::move(joint));
        bound.insert(id);
      } else {
        if (id < 0 || static_cast<std::size_t>(id) >= model.joints.size()) l.fail(fmt::format("inverse bind pose of joint {} before its bind pose", id));
        if (parent != model.joints[static_cast<std::size_t>(id)].parent) l.fail(fmt::format("joint {}: parent {} differs from the bind pose's", id, parent));
        model.joints[static_cast<std::size_t>(id)].inverseBindPose = l.dualQuat(3);
        inverseBound.insert(id);
      }
    } else {
      l.fail(fmt::format("unknown record '{}'; a ModelMesh file has o, M, p, n, t, c, j, w, i, a, g, f, r, e, E, m, b, x, K, P, N", token),
             ErrorCode::kParse);
    }
  }
  const auto where = fmt::format("{}:{}", file, source.number());
  if (model.path.empty()) throw Failure{Error{ErrorCode::kInvalidData, where + ": no 'o' record naming the model"}};
  if (bound != inverseBound) throw Failure{Error{ErrorCode::kInvalidData, where + ": every joint needs both a 'b' and an 'x' record"}};
  if (model.keyFrames > 0 && !model.joints.empty())
    throw Failure{Error{ErrorCode::kInvalidData, where + ": a model has joints or key frames ('K'), not both"}};
  for (const auto& mesh : model.meshes) {
    const std::size_t n = declaredVertices[static_cast<std::size_t>(mesh.id)];
    auto check = [&](std::size_t count, const char* what, bool optional) {
      if (count != n && !(optional && count == 0))
        throw Failure{Error{ErrorCode::kInvalidData, fmt::format("{}: mesh {} declares {} vertices but has {} {} records", where, mesh.id, n, count, what)}};
    };
    check(mesh.positions.size(), "'p'", false);
    check(mesh.normals.size(), "'n'", true);
    check(mesh.uvs.size(), "'t'", true);
    check(mesh.colors.size(), "'c'", true);
    check(mesh.joints.size(), "'j'", true);
    check(mesh.weights.size(), "'w'", true);
    if (mesh.indices.size() != 3 * declaredTriangles[static_cast<std::size_t>(mesh.id)])
      throw Failure{Error{ErrorCode::kInvalidData, fmt::format("{}: mesh {} declares {} triangles but has {} 'i' records", where, mesh.id,
                                                              declaredTriangles[static_cast<std::size_t>(mesh.id)], mesh.indices.size() / 3)}};
    for (std::size_t f = 0; f < mesh.keyPositions.size(); ++f) {
      check(mesh.keyPositions[f].size(), fmt::format("'P' (key frame {})", f).c_str(), false);
      if (!mesh.keyNormals.empty()) check(mesh.keyNormals[f].size(), fmt::format("'N' (key frame {})", f).c_str(), false);
    }
    for (std::uint32_t index : mesh.indices)
      if (index >= n) throw Failure{Error{ErrorCode::kInvalidData, fmt::format("{}: mesh {} has a triangle using vertex {} of {}", where, mesh.id, index, n)}};
    for (std::size_t v = 0; v < mesh.joints.size(); ++v)
      for (int k = 0; k < influenceCounts[static_cast<std::size_t>(mesh.id)][v]; ++k)
        if (mesh.joints[v][k] >= model.joints.size())
          throw Failure{Error{ErrorCode::kInvalidData, fmt::format("{}: mesh {} vertex {} uses joint {} but the model has {} joints", where,
                                                                  mesh.id, v, mesh.joints[v][k], model.joints.size())}};
  }
  return model;
}

using Kind = CapturableKind;

}  // namespace

void CaptureFrame::clear() {
  cameraSettings.reset();
  cameras.clear();
  cuts.clear();
  staticModels.clear();
  models.clear();
  joints.clear();
  vertexFrames.clear();
  lights.clear();
}

Expected<CapturedModel> readModelMesh(const fs::path& file) {
  try {
    return parseModelMesh(file);
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  }
}

struct CaptureReader::Impl {
  explicit Impl(const fs::path& path) : file(path.string()), source(path) {}
  std::string file;
  LineSource source;
  std::string text;
  std::optional<std::string> pending;  // an `f` line read while looking for the first frame
  std::size_t pendingLine = 0;
  bool anyFrame = false;
  std::uint64_t lastFrame = 0;
  double lastTime = 0;
  std::map<std::uint64_t, std::pair<Kind, int>> capturables;  // kind and model index per id
  std::set<std::uint64_t> modelsThisFrame;
};

CaptureReader::CaptureReader() = default;
CaptureReader::~CaptureReader() = default;

int CaptureReader::modelIndex(const std::string& path) const {
  auto it = modelByPath_.find(path);
  return it == modelByPath_.end() ? -1 : it->second;
}

Expected<std::unique_ptr<CaptureReader>> CaptureReader::open(const fs::path& directory) {
  std::unique_ptr<CaptureReader> reader(new CaptureReader);
  try {
    const fs::path capture = directory / kCaptureFile;
    std::error_code ec;
    if (!fs::is_regular_file(capture, ec))
      return fail(ErrorCode::kIo, "{}: not a capture directory (no {})", directory.string(), kCaptureFile);
    std::vector<fs::path> modelFiles;
    if (fs::is_directory(directory / kModelsFolder, ec))
      for (const auto& entry : fs::directory_iterator(directory / kModelsFolder))
        if (entry.is_regular_file() && entry.path().extension() == ".txt") modelFiles.push_back(entry.path());
    std::sort(modelFiles.begin(), modelFiles.end());
    for (const auto& f : modelFiles) {
      CapturedModel model = parseModelMesh(f);
      auto [it, inserted] = reader->modelByPath_.emplace(model.path, static_cast<int>(reader->models_.size()));
      if (!inserted)
        return fail(ErrorCode::kInvalidData, "{}: model '{}' is already declared by {}", f.string(), model.path,
                    reader->models_[static_cast<std::size_t>(it->second)].file.string());
      reader->models_.push_back(std::move(model));
    }
    reader->impl_ = std::make_unique<Impl>(capture);
    Impl& impl = *reader->impl_;
    bool complete = true;
    if (!impl.source.next(impl.text, complete) || (impl.text != kCaptureVersionLine && impl.text != kCaptureVersion2Line)) {
      if (impl.text.starts_with("dynbench-capture:"))
        return fail(ErrorCode::kParse,
                    "{}:1: capture format version {} is not supported; this dynbench reads versions {} and {} (version 1 captures lack "
                    "the lights' range and predate the signed normals: capture again)",
                    impl.file, impl.text.substr(17), kCaptureVersion2Line.substr(17), kCaptureVersionLine.substr(17));
      return fail(ErrorCode::kParse, "{}:1: expected the version line '{}'", impl.file, kCaptureVersionLine);
    }
    while (impl.source.next(impl.text, complete)) {
      if (isComment(impl.text)) continue;
      const Line l(impl.file, impl.source.number(), impl.text);
      if (!complete) {
        reader->warnings_.push_back(fmt::format("{}:{}: the capture ends in the middle of a line; it is ignored", impl.file, l.number()));
        break;
      }
      const auto token = l.token();
      if (token == "f") {
        impl.pending = impl.text;
        impl.pendingLine = impl.source.number();
        break;
      }
      if (token == "s") {
        l.expectFields(1, "source");
        reader->settings_.source = l.text(1);
      } else if (token == "d") {
        l.expectFields(1, "path");
        reader->settings_.dataRoot = l.text(1);
      } else if (token == "k") {
        l.expectFields(1, "metres_per_unit");
        reader->settings_.metresPerUnit = l.real(1, "metres_per_unit");
        if (!(reader->settings_.metresPerUnit > 0)) l.fail("metres per unit must be positive");
      } else if (token == "u") {
        l.expectFields(4, "x:y:z:map_name");
        reader->settings_.mapOffset = {l.real(1, "x"), l.real(2, "y"), l.real(3, "z")};
        reader->settings_.mapName = l.text(4);
      } else if (token == "C") {
        reader->settings_.camera = cameraSettings(l);
      } else if (token == "L") {
        l.expectFields(12, "sun_x:sun_y:sun_z:sun_r:sun_g:sun_b:ambient_r:ambient_g:ambient_b:sky_r:sky_g:sky_b");
        MapLighting m;
        const glm::dvec3 direction{l.real(1, "sun_x"), l.real(2, "sun_y"), l.real(3, "sun_z")};
        m.sun = {l.real(4, "sun_r"), l.real(5, "sun_g"), l.real(6, "sun_b")};
        m.ambient = {l.real(7, "ambient_r"), l.real(8, "ambient_g"), l.real(9, "ambient_b")};
        m.sky = {l.real(10, "sky_r"), l.real(11, "sky_g"), l.real(12, "sky_b")};
        for (const glm::dvec3& c : {m.sun, m.ambient, m.sky})
          if (c.r < 0 || c.g < 0 || c.b < 0) l.fail("lighting colours must not be negative");
        if (m.hasSun()) {
          if (!(glm::length(direction) > 0)) l.fail("a sun needs a direction");
          m.sunDirection = glm::normalize(direction);
        }
        reader->settings_.lighting = m;
      } else if (token == "z") {
        l.expectFields(1, "frame_count");
        reader->closed_ = true;
      } else {
        l.fail(fmt::format("unknown or misplaced record '{}' before the first frame; expected s, d, k, u, C, L or f", token), ErrorCode::kParse);
      }
    }
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  } catch (const fs::filesystem_error& e) {
    return fail(ErrorCode::kIo, "{}: {}", directory.string(), e.what());
  }
  return reader;
}

Expected<bool> CaptureReader::next(CaptureFrame& frame) {
  Impl& impl = *impl_;
  frame.clear();
  try {
    bool inFrame = false;
    bool complete = true;
    std::string line;
    std::size_t number = 0;
    while (true) {
      if (impl.pending) {
        line = std::move(*impl.pending);
        number = impl.pendingLine;
        impl.pending.reset();
      } else if (impl.source.next(line, complete)) {
        number = impl.source.number();
      } else {
        if (inFrame)
          warnings_.push_back(fmt::format("{}:{}: frame {} has no end record (the capture was cut short); it is dropped", impl.file,
                                          frame.line, frame.number));
        else if (!closed_)
          warnings_.push_back(fmt::format("{}: no closing record: the capture was not closed (host stopped early?)", impl.file));
        return false;
      }
      if (isComment(line)) continue;
      const Line l(impl.file, number, line);
      if (!complete) {
        warnings_.push_back(fmt::format("{}:{}: the capture ends in the middle of a line{}", impl.file, number,
                                        inFrame ? fmt::format("; frame {} is dropped", frame.number) : std::string()));
        return false;
      }
      const auto token = l.token();
      if (closed_) l.fail("a record after the closing 'z' record");
      if (!inFrame) {
        if (token == "z") {
          l.expectFields(1, "frame_count");
          closed_ = true;
          continue;
        }
        if (token != "f") l.fail(fmt::format("record '{}' outside a frame; expected 'f' (frame) or 'z' (end of capture)", token));
        l.expectFields(2, "frame_number:time");
        frame.number = l.integer<std::uint64_t>(1, "frame_number");
        frame.time = l.real(2, "time");
        frame.line = number;
        if (impl.anyFrame && frame.number <= impl.lastFrame)
          l.fail(fmt::format("frame {} after frame {}; frame numbers must increase", frame.number, impl.lastFrame));
        if (impl.anyFrame && frame.time < impl.lastTime)
          l.fail(fmt::format("frame time {} after {}; time must not go back", frame.time, impl.lastTime));
        impl.modelsThisFrame.clear();
        inFrame = true;
        continue;
      }
      auto claim = [&](std::uint64_t id, Kind kind, int model) {
        auto [it, inserted] = impl.capturables.emplace(id, std::make_pair(kind, model));
        if (!inserted && it->second != std::make_pair(kind, model))
          l.fail(fmt::format("capturable {} was a {}{}; it cannot become a {}{}", id, capturableKindName(it->second.first),
                             it->second.second >= 0 ? " of '" + models_[static_cast<std::size_t>(it->second.second)].path + "'" : "",
                             capturableKindName(kind), model >= 0 ? " of '" + models_[static_cast<std::size_t>(model)].path + "'" : ""));
      };
      auto modelAt = [&](std::size_t field) {
        const std::string path = l.text(field);
        const int index = modelIndex(path);
        if (index < 0) l.fail(fmt::format("unknown model '{}': no file in {} declares it", path, kModelsFolder));
        return index;
      };
      if (token == "e") {
        l.expectFields(1, "frame_number");
        if (l.integer<std::uint64_t>(1, "frame_number") != frame.number)
          l.fail(fmt::format("end record for frame {} inside frame {}", l.integer<std::uint64_t>(1, "frame_number"), frame.number));
        impl.anyFrame = true;
        impl.lastFrame = frame.number;
        impl.lastTime = frame.time;
        return true;
      } else if (token == "f") {
        l.fail(fmt::format("frame starts before frame {} (line {}) ended", frame.number, frame.line));
      } else if (token == "t") {
        l.expectFields(7, "id:x:y:z:pitch:yaw:roll");
        CameraRecord c;
        c.id = l.integer<std::uint64_t>(1, "id");
        c.position = {l.real(2, "x"), l.real(3, "y"), l.real(4, "z")};
        c.pitch = l.real(5, "pitch");
        c.yaw = l.real(6, "yaw");
        c.roll = l.real(7, "roll");
        claim(c.id, Kind::kCamera, -1);
        frame.cameras.push_back(c);
      } else if (token == "c") {
        l.expectFields(2, "id:reason");
        CameraCutRecord c;
        c.id = l.integer<std::uint64_t>(1, "id");
        c.reason = l.text(2);
        if (std::none_of(frame.cameras.begin(), frame.cameras.end(), [&](const CameraRecord& r) { return r.id == c.id; }))
          l.fail(fmt::format("cut of camera {}, which has no camera transform ('t') earlier in this frame", c.id));
        frame.cuts.push_back(std::move(c));
      } else if (token == "p" || token == "m") {
        l.expectFields(10, "id:rx:ry:rz:rw:dx:dy:dz:dw:model_path");
        ModelRecord r;
        r.id = l.integer<std::uint64_t>(1, "id");
        r.pose = l.dualQuat(2);
        r.model = modelAt(10);
        claim(r.id, token == "p" ? Kind::kStaticModel : Kind::kModel, r.model);
        if (token == "m") impl.modelsThisFrame.insert(r.id);
        (token == "p" ? frame.staticModels : frame.models).push_back(std::move(r));
      } else if (token == "j") {
        if (l.size() < 4) l.fail("record 'j' needs id:joint_count:8 numbers per joint:model_path", ErrorCode::kParse);
        JointsRecord r;
        r.id = l.integer<std::uint64_t>(1, "id");
        const auto count = l.integer<std::size_t>(2, "joint_count");
        if (l.size() != 4 + 8 * count)
          l.fail(fmt::format("record 'j' with {} joints needs {} fields, got {}", count, 3 + 8 * count, l.size() - 1), ErrorCode::kParse);
        r.model = modelAt(3 + 8 * count);
        const auto& model = models_[static_cast<std::size_t>(r.model)];
        if (count != model.joints.size())
          l.fail(fmt::format("{} joints for model '{}', which has {} joints", count, model.path, model.joints.size()));
        if (!impl.modelsThisFrame.contains(r.id))
          l.fail(fmt::format("joints of capturable {}, which has no model transform ('m') earlier in this frame", r.id));
        if (impl.capturables.at(r.id).second != r.model)
          l.fail(fmt::format("joints of capturable {} name model '{}', its transform another", r.id, model.path));
        r.joints.reserve(count);
        for (std::size_t k = 0; k < count; ++k) r.joints.push_back(l.dualQuat(3 + 8 * k));
        frame.joints.push_back(std::move(r));
      } else if (token == "v") {
        l.expectFields(5, "id:from:to:fraction:model_path");
        VertexFramesRecord r;
        r.id = l.integer<std::uint64_t>(1, "id");
        r.from = l.integer<std::uint32_t>(2, "from"), r.to = l.integer<std::uint32_t>(3, "to");
        r.fraction = l.real(4, "fraction");
        r.model = modelAt(5);
        const auto& model = models_[static_cast<std::size_t>(r.model)];
        if (model.keyFrames == 0) l.fail(fmt::format("key frames of model '{}', which has none ('K' records)", model.path));
        if (r.from >= model.keyFrames || r.to >= model.keyFrames)
          l.fail(fmt::format("key frames {} and {} of model '{}', which has {}", r.from, r.to, model.path, model.keyFrames));
        if (!(r.fraction >= 0 && r.fraction <= 1)) l.fail(fmt::format("fraction {} is not in [0, 1]", r.fraction));
        if (!impl.modelsThisFrame.contains(r.id))
          l.fail(fmt::format("key frames of capturable {}, which has no model transform ('m') earlier in this frame", r.id));
        if (impl.capturables.at(r.id).second != r.model)
          l.fail(fmt::format("key frames of capturable {} name model '{}', its transform another", r.id, model.path));
        frame.vertexFrames.push_back(r);
      } else if (token == "l") {
        l.expectFields(12, "id:x:y:z:r:g:b:range:falloff:type:dynamic:model_type");
        LightRecord r;
        r.id = l.integer<std::uint64_t>(1, "id");
        r.position = {l.real(2, "x"), l.real(3, "y"), l.real(4, "z")};
        r.color = {l.real(5, "r"), l.real(6, "g"), l.real(7, "b")};
        r.range = l.real(8, "range");
        if (r.range < 0) l.fail("a light's range must be 0 (none) or positive");
        const std::string falloff = l.text(9);
        if (falloff == "linear") r.falloff = LightFalloff::kLinear;
        else if (falloff == "quadratic") r.falloff = LightFalloff::kQuadratic;
        else if (falloff == "inverse_square") r.falloff = LightFalloff::kInverseSquare;
        else if (falloff != "none") l.fail(fmt::format("light falloff '{}'; expected none, linear, quadratic or inverse_square", falloff));
        if ((r.range > 0) != (r.falloff != LightFalloff::kNone)) l.fail("a light has a falloff exactly when it has a range");
        const std::string type = l.text(10);
        if (type == "point") r.type = LightType::kPoint;
        else if (type == "spot") r.type = LightType::kSpot;
        else if (type == "directional") r.type = LightType::kDirectional;
        else l.fail(fmt::format("light type '{}'; expected point, spot or directional", type));
        const int dynamic = l.integer<int>(11, "dynamic");
        if (dynamic != 0 && dynamic != 1) l.fail("the dynamic flag must be 0 or 1");
        r.dynamic = dynamic == 1;
        r.modelType = l.text(12);
        claim(r.id, Kind::kLight, -1);
        frame.lights.push_back(std::move(r));
      } else if (token == "C") {
        frame.cameraSettings = cameraSettings(l);
      } else {
        l.fail(fmt::format("unknown record '{}' in a frame; expected t, c, p, m, j, v, l, C or e", token), ErrorCode::kParse);
      }
    }
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  }
}

}  // namespace dynbench::capture
