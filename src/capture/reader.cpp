#include "capture/reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include "capture/format.h"
#include "capture/record_lexer.h"

namespace dynbench::capture {

namespace fs = std::filesystem;
using Kind = CapturableKind;

namespace {

// The records whose fields stand alone (the capture format's table, docs/capture-format.md); the
// frame loop below checks what they claim against the capturables and models seen before.
CameraRecord cameraRecord(const Line& l) {
  l.expectFields(7, "id:x:y:z:pitch:yaw:roll");
  CameraRecord c;
  c.id = l.integer<std::uint64_t>(1, "id");
  c.position = {l.real(2, "x"), l.real(3, "y"), l.real(4, "z")};
  c.pitch = l.real(5, "pitch");
  c.yaw = l.real(6, "yaw");
  c.roll = l.real(7, "roll");
  return c;
}

CameraCutRecord cutRecord(const Line& l) {
  l.expectFields(2, "id:reason");
  CameraCutRecord c;
  c.id = l.integer<std::uint64_t>(1, "id");
  c.reason = l.text(2);
  return c;
}

LightRecord lightRecord(const Line& l) {
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
  else if (falloff == "windowed_inverse_square") r.falloff = LightFalloff::kWindowedInverseSquare;
  else if (falloff != "none")
    l.fail(fmt::format("light falloff '{}'; expected none, linear, quadratic, inverse_square or windowed_inverse_square", falloff));
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
  return r;
}

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

namespace {

// The records inside a frame (docs/capture-format.md's table), one handler each, checked against
// the capturables and models seen before: a capturable keeps its kind and model for the whole
// capture, and joints and key frames follow their model's transform in the same frame.
class FrameRecords {
 public:
  FrameRecords(CaptureReader::Impl& impl, const CaptureReader& reader, CaptureFrame& frame, const Line& l)
      : impl_(impl), reader_(reader), frame_(frame), l_(l) {}

  void camera() {
    const CameraRecord c = cameraRecord(l_);
    claim(c.id, Kind::kCamera, -1);
    frame_.cameras.push_back(c);
  }

  void cut() {
    CameraCutRecord c = cutRecord(l_);
    if (std::none_of(frame_.cameras.begin(), frame_.cameras.end(), [&](const CameraRecord& r) { return r.id == c.id; }))
      l_.fail(fmt::format("cut of camera {}, which has no camera transform ('t') earlier in this frame", c.id));
    frame_.cuts.push_back(std::move(c));
  }

  void staticModel() { frame_.staticModels.push_back(modelRecord(Kind::kStaticModel)); }

  void model() {
    ModelRecord r = modelRecord(Kind::kModel);
    impl_.modelsThisFrame.insert(r.id);
    frame_.models.push_back(std::move(r));
  }

  void joints() {
    if (l_.size() < 4) l_.fail("record 'j' needs id:joint_count:8 numbers per joint:model_path", ErrorCode::kParse);
    JointsRecord r;
    r.id = l_.integer<std::uint64_t>(1, "id");
    const auto count = l_.integer<std::size_t>(2, "joint_count");
    if (l_.size() != 4 + 8 * count)
      l_.fail(fmt::format("record 'j' with {} joints needs {} fields, got {}", count, 3 + 8 * count, l_.size() - 1), ErrorCode::kParse);
    r.model = modelAt(3 + 8 * count);
    const auto& model = reader_.models()[static_cast<std::size_t>(r.model)];
    if (count != model.joints.size())
      l_.fail(fmt::format("{} joints for model '{}', which has {} joints", count, model.path, model.joints.size()));
    followsItsTransform(r.id, r.model, "joints");
    r.joints.reserve(count);
    for (std::size_t k = 0; k < count; ++k) r.joints.push_back(l_.dualQuat(3 + 8 * k));
    frame_.joints.push_back(std::move(r));
  }

  void vertexFrames() {
    l_.expectFields(5, "id:from:to:fraction:model_path");
    VertexFramesRecord r;
    r.id = l_.integer<std::uint64_t>(1, "id");
    r.from = l_.integer<std::uint32_t>(2, "from"), r.to = l_.integer<std::uint32_t>(3, "to");
    r.fraction = l_.real(4, "fraction");
    r.model = modelAt(5);
    const auto& model = reader_.models()[static_cast<std::size_t>(r.model)];
    if (model.keyFrames == 0) l_.fail(fmt::format("key frames of model '{}', which has none ('K' records)", model.path));
    if (r.from >= model.keyFrames || r.to >= model.keyFrames)
      l_.fail(fmt::format("key frames {} and {} of model '{}', which has {}", r.from, r.to, model.path, model.keyFrames));
    if (!(r.fraction >= 0 && r.fraction <= 1)) l_.fail(fmt::format("fraction {} is not in [0, 1]", r.fraction));
    followsItsTransform(r.id, r.model, "key frames");
    frame_.vertexFrames.push_back(r);
  }

  void light() {
    LightRecord r = lightRecord(l_);
    claim(r.id, Kind::kLight, -1);
    frame_.lights.push_back(std::move(r));
  }

  void cameraSettings() { frame_.cameraSettings = capture::cameraSettings(l_); }

 private:
  // A 'p' (static) or 'm' (moving) model's transform.
  ModelRecord modelRecord(Kind kind) {
    l_.expectFields(10, "id:rx:ry:rz:rw:dx:dy:dz:dw:model_path");
    ModelRecord r;
    r.id = l_.integer<std::uint64_t>(1, "id");
    r.pose = l_.dualQuat(2);
    r.model = modelAt(10);
    claim(r.id, kind, r.model);
    return r;
  }

  // Joints ('j') and key frames ('v') animate a model whose transform ('m') came earlier in the
  // frame, and name the model that transform names.
  void followsItsTransform(std::uint64_t id, int model, std::string_view what) {
    if (!impl_.modelsThisFrame.contains(id))
      l_.fail(fmt::format("{} of capturable {}, which has no model transform ('m') earlier in this frame", what, id));
    if (impl_.capturables.at(id).second != model)
      l_.fail(fmt::format("{} of capturable {} name model '{}', its transform another", what, id,
                          reader_.models()[static_cast<std::size_t>(model)].path));
  }

  void claim(std::uint64_t id, Kind kind, int model) {
    auto [it, inserted] = impl_.capturables.emplace(id, std::make_pair(kind, model));
    if (!inserted && it->second != std::make_pair(kind, model))
      l_.fail(fmt::format("capturable {} was a {}{}; it cannot become a {}{}", id, capturableKindName(it->second.first), ofModel(it->second.second),
                          capturableKindName(kind), ofModel(model)));
  }

  std::string ofModel(int model) const {
    return model >= 0 ? " of '" + reader_.models()[static_cast<std::size_t>(model)].path + "'" : "";
  }

  int modelAt(std::size_t field) const {
    const std::string path = l_.text(field);
    const int index = reader_.modelIndex(path);
    if (index < 0) l_.fail(fmt::format("unknown model '{}': no file in {} declares it", path, kModelsFolder));
    return index;
  }

  CaptureReader::Impl& impl_;
  const CaptureReader& reader_;
  CaptureFrame& frame_;
  const Line& l_;
};

struct FrameRecordEntry {
  std::string_view token;
  void (FrameRecords::*read)();
};
constexpr FrameRecordEntry kFrameRecords[] = {
    {"t", &FrameRecords::camera},      {"c", &FrameRecords::cut},          {"p", &FrameRecords::staticModel},
    {"m", &FrameRecords::model},       {"j", &FrameRecords::joints},       {"v", &FrameRecords::vertexFrames},
    {"l", &FrameRecords::light},       {"C", &FrameRecords::cameraSettings},
};

// The tokens of kFrameRecords and the end record, as an error message lists them: "t, c, ... or e".
std::string expectedFrameTokens() {
  std::string list;
  for (const FrameRecordEntry& e : kFrameRecords) list += std::string(e.token) + ", ";
  return list.substr(0, list.size() - 2) + " or e";
}

}  // namespace

// The next line that is not a comment: false at the end of the file (or at a last line cut
// short), with the warning the end deserves.
bool CaptureReader::nextLine(std::string& line, std::size_t& number, bool inFrame, const CaptureFrame& frame) {
  Impl& impl = *impl_;
  while (true) {
    bool complete = true;
    if (impl.pending) {
      line = std::move(*impl.pending);
      number = impl.pendingLine;
      impl.pending.reset();
    } else if (impl.source.next(line, complete)) {
      number = impl.source.number();
    } else {
      if (inFrame)
        warnings_.push_back(
            fmt::format("{}:{}: frame {} has no end record (the capture was cut short); it is dropped", impl.file, frame.line, frame.number));
      else if (!closed_)
        warnings_.push_back(fmt::format("{}: no closing record: the capture was not closed (host stopped early?)", impl.file));
      return false;
    }
    if (isComment(line)) continue;
    if (!complete) {
      warnings_.push_back(fmt::format("{}:{}: the capture ends in the middle of a line{}", impl.file, number,
                                      inFrame ? fmt::format("; frame {} is dropped", frame.number) : std::string()));
      return false;
    }
    return true;
  }
}

// Between frames: the closing 'z' record (false), or the 'f' record that opens the next frame (true).
bool CaptureReader::startFrame(const Line& l, CaptureFrame& frame) {
  Impl& impl = *impl_;
  const auto token = l.token();
  if (token == "z") {
    l.expectFields(1, "frame_count");
    closed_ = true;
    return false;
  }
  if (token != "f") l.fail(fmt::format("record '{}' outside a frame; expected 'f' (frame) or 'z' (end of capture)", token));
  l.expectFields(2, "frame_number:time");
  frame.number = l.integer<std::uint64_t>(1, "frame_number");
  frame.time = l.real(2, "time");
  frame.line = l.number();
  if (impl.anyFrame && frame.number <= impl.lastFrame)
    l.fail(fmt::format("frame {} after frame {}; frame numbers must increase", frame.number, impl.lastFrame));
  if (impl.anyFrame && frame.time < impl.lastTime)
    l.fail(fmt::format("frame time {} after {}; time must not go back", frame.time, impl.lastTime));
  impl.modelsThisFrame.clear();
  return true;
}

Expected<bool> CaptureReader::next(CaptureFrame& frame) {
  Impl& impl = *impl_;
  frame.clear();
  try {
    bool inFrame = false;
    std::string line;
    std::size_t number = 0;
    while (nextLine(line, number, inFrame, frame)) {
      const Line l(impl.file, number, line);
      const auto token = l.token();
      if (closed_) l.fail("a record after the closing 'z' record");
      if (!inFrame) {
        inFrame = startFrame(l, frame);
        continue;
      }
      if (token == "e") {
        l.expectFields(1, "frame_number");
        if (l.integer<std::uint64_t>(1, "frame_number") != frame.number)
          l.fail(fmt::format("end record for frame {} inside frame {}", l.integer<std::uint64_t>(1, "frame_number"), frame.number));
        impl.anyFrame = true;
        impl.lastFrame = frame.number;
        impl.lastTime = frame.time;
        return true;
      }
      if (token == "f") l.fail(fmt::format("frame starts before frame {} (line {}) ended", frame.number, frame.line));
      const auto entry = std::find_if(std::begin(kFrameRecords), std::end(kFrameRecords),
                                      [&](const FrameRecordEntry& e) { return e.token == token; });
      if (entry == std::end(kFrameRecords))
        l.fail(fmt::format("unknown record '{}' in a frame; expected {}", token, expectedFrameTokens()), ErrorCode::kParse);
      FrameRecords records(impl, *this, frame, l);
      (records.*(entry->read))();
    }
    return false;
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  }
}

}  // namespace dynbench::capture
