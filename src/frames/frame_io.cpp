#include "frames/frame_io.h"

#include <algorithm>
#include <map>
#include <regex>

#include <glm/gtc/packing.hpp>

#include <fmt/format.h>

#include "core/files.h"
#include "core/image_io.h"

namespace dynbench::frames {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

Expected<glm::dmat4> matrixAt(const json& j, const fs::path& file, const std::string& pointer) {
  const json::json_pointer ptr(pointer);
  if (!j.contains(ptr) || !j.at(ptr).is_array() || j.at(ptr).size() != 16)
    return fail(ErrorCode::kInvalidData, "{}: {}: expected an array of 16 numbers (a column-major matrix)", file.string(), pointer);
  glm::dmat4 m;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      const json& v = j.at(ptr)[static_cast<std::size_t>(4 * c + r)];
      if (!v.is_number()) return fail(ErrorCode::kInvalidData, "{}: {}/{}: expected a number", file.string(), pointer, 4 * c + r);
      m[c][r] = v.get<double>();
    }
  return m;
}

Expected<double> numberAt(const json& j, const fs::path& file, const std::string& pointer, double fallback) {
  const json::json_pointer ptr(pointer);
  if (!j.contains(ptr)) return fallback;
  if (!j.at(ptr).is_number()) return fail(ErrorCode::kInvalidData, "{}: {}: expected a number", file.string(), pointer);
  return j.at(ptr).get<double>();
}

}  // namespace

json matrixJson(const glm::dmat4& m) {
  json a = json::array();
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) a.push_back(m[c][r]);
  return a;
}

json sidecarJson(long frame, double time, const FrameCamera& camera, const json& render) {
  json j;
  j["format"] = kSidecarFormat;
  j["version"] = kSidecarVersion;
  j["frame"] = frame;
  j["time"] = time;
  j["width"] = camera.width;
  j["height"] = camera.height;
  j["camera"] = {
      {"world", matrixJson(camera.world)},
      {"view", matrixJson(camera.view)},
      {"projection", matrixJson(camera.projection)},
      {"position", {camera.position.x, camera.position.y, camera.position.z}},
      {"yfov", camera.yfov},
      {"aspect", static_cast<double>(camera.width) / camera.height},
      {"znear", camera.znear},
      {"zfar", camera.zfar},
      {"jitter", {camera.jitter.x, camera.jitter.y}},
  };
  j["conventions"] = {
      {"matrices", "column-major, 16 numbers (glTF order); clip = projection * view * world_point"},
      {"view_space", "right-handed, camera looks down -Z, +Y up (glTF / OpenGL)"},
      {"clip_space", "OpenGL: NDC x, y, z in [-1, 1], depth -1 at znear"},
      {"pixels", "pixel (x, y) covers [x, x+1) x [y, y+1), row 0 at the top; x = (ndc.x + 1) / 2 * width, "
                 "y = (1 - ndc.y) / 2 * height"},
      {"motion", "previous-frame pixel position of the surface point at this pixel's sample, minus the sample's position "
                 "(the centre plus camera.jitter), in pixels"},
      {"units", "lengths in the dataset's units; radiance in the dataset's photometric units (cd/m2)"},
  };
  j["render"] = render;
  return j;
}

json samplingJson(const SamplingSummary& s) {
  json j = {{"adaptive", s.adaptive},
          {"tolerance", s.tolerance},
          {"direct_target", s.directTarget},
          {"indirect_target", s.indirectTarget},
          {"min_spp", s.minSamples},
          {"max_spp", s.maxSamples},
          {"mean_spp", s.meanSamples},
          {"capped_pixels", s.cappedPixels},
          {"lights_per_point", s.lightsPerPoint}};
  if (s.pairCap > 0) {
    j["pair_cap"] = s.pairCap;
    j["max_pairs"] = s.maxPairs;
    j["mean_pairs"] = s.meanPairs;
    j["undecided_pixels"] = s.undecidedPixels;
  }
  return j;
}

namespace {

Expected<SamplingSummary> readSampling(const json& j, const fs::path& path) {
  SamplingSummary s;
  const json& o = j["sampling"];
  if (!o.is_object()) return fail(ErrorCode::kInvalidData, "{}: /sampling: expected an object", path.string());
  if (o.contains("adaptive")) {
    if (!o["adaptive"].is_boolean()) return fail(ErrorCode::kInvalidData, "{}: /sampling/adaptive: expected true or false", path.string());
    s.adaptive = o["adaptive"].get<bool>();
  }
  for (auto [key, target] : {std::pair{"tolerance", &s.tolerance}, {"direct_target", &s.directTarget}, {"indirect_target", &s.indirectTarget},
                             {"mean_spp", &s.meanSamples}, {"mean_pairs", &s.meanPairs}}) {
    auto v = numberAt(j, path, std::string("/sampling/") + key, 0.0);
    if (!v) return std::unexpected(v.error());
    *target = *v;
  }
  for (auto [key, target] : {std::pair{"min_spp", &s.minSamples}, {"max_spp", &s.maxSamples}, {"lights_per_point", &s.lightsPerPoint},
                             {"pair_cap", &s.pairCap}, {"max_pairs", &s.maxPairs}}) {
    auto v = numberAt(j, path, std::string("/sampling/") + key, 0.0);
    if (!v) return std::unexpected(v.error());
    *target = static_cast<int>(*v);
  }
  auto capped = numberAt(j, path, "/sampling/capped_pixels", 0.0);
  if (!capped) return std::unexpected(capped.error());
  s.cappedPixels = static_cast<long>(*capped);
  auto undecided = numberAt(j, path, "/sampling/undecided_pixels", 0.0);
  if (!undecided) return std::unexpected(undecided.error());
  s.undecidedPixels = static_cast<long>(*undecided);
  return s;
}

}  // namespace

Expected<Sidecar> readSidecar(const fs::path& path) {
  auto text = readWholeFile(path);
  if (!text) return std::unexpected(text.error());
  json j = json::parse(*text, nullptr, false);
  if (j.is_discarded()) return fail(ErrorCode::kParse, "{}: not valid JSON", path.string());
  if (!j.is_object()) return fail(ErrorCode::kInvalidData, "{}: /: expected a JSON object (a frame sidecar)", path.string());
  if (!j.contains("format") || j["format"] != kSidecarFormat)
    return fail(ErrorCode::kInvalidData, "{}: /format: expected \"{}\" (docs/feature-buffers.md)", path.string(), kSidecarFormat);
  if (!j.contains("version") || !j["version"].is_number_integer())
    return fail(ErrorCode::kInvalidData, "{}: /version: expected a whole number", path.string());
  if (const int version = j["version"].get<int>(); version != kSidecarVersion)
    return fail(ErrorCode::kUnsupported, "{}: /version: {} is not a sidecar version this dynbench reads (it reads {})", path.string(),
                version, kSidecarVersion);
  Sidecar s;
  for (const char* key : {"width", "height"})
    if (!j.contains(key) || !j[key].is_number_integer() || j[key].get<long long>() <= 0 || j[key].get<long long>() > 65536)
      return fail(ErrorCode::kInvalidData, "{}: /{}: expected a whole number from 1 to 65536", path.string(), key);
  s.camera.width = j["width"].get<int>();
  s.camera.height = j["height"].get<int>();
  if (j.contains("frame")) {
    if (!j["frame"].is_number_integer()) return fail(ErrorCode::kInvalidData, "{}: /frame: expected a whole number", path.string());
    s.frame = j["frame"].get<long>();
  }
  auto time = numberAt(j, path, "/time", 0.0);
  if (!time) return std::unexpected(time.error());
  s.time = *time;
  auto view = matrixAt(j, path, "/camera/view");
  if (!view) return std::unexpected(view.error());
  auto projection = matrixAt(j, path, "/camera/projection");
  if (!projection) return std::unexpected(projection.error());
  s.camera.view = *view;
  s.camera.projection = *projection;
  if (j.contains("/camera/world"_json_pointer)) {
    auto world = matrixAt(j, path, "/camera/world");
    if (!world) return std::unexpected(world.error());
    s.camera.world = *world;
  } else {
    s.camera.world = glm::inverse(s.camera.view);
  }
  s.camera.position = glm::dvec3(s.camera.world[3]);
  for (auto [pointer, target] : {std::pair{"/camera/yfov", &s.camera.yfov}, {"/camera/znear", &s.camera.znear}, {"/camera/zfar", &s.camera.zfar}}) {
    auto v = numberAt(j, path, pointer, 0.0);
    if (!v) return std::unexpected(v.error());
    *target = *v;
  }
  if (j.contains("/camera/jitter"_json_pointer)) {
    const json& jitter = j["camera"]["jitter"];
    if (!jitter.is_array() || jitter.size() != 2 || !jitter[0].is_number() || !jitter[1].is_number())
      return fail(ErrorCode::kInvalidData, "{}: /camera/jitter: expected two numbers (pixels)", path.string());
    s.camera.jitter = {jitter[0].get<double>(), jitter[1].get<double>()};
  }
  if (j.contains("cut")) {
    if (!j["cut"].is_boolean()) return fail(ErrorCode::kInvalidData, "{}: /cut: expected true or false", path.string());
    s.cut = j["cut"].get<bool>();
  }
  if (j.contains("render")) s.render = j["render"];
  if (j.contains("sampling")) {
    auto sampling = readSampling(j, path);
    if (!sampling) return std::unexpected(sampling.error());
    s.sampling = *sampling;
  }
  return s;
}

namespace {
const std::regex& frameFilePattern() {
  static const std::regex pattern(R"(frame_(\d{1,18})\.(exr|json))");
  return pattern;
}
}  // namespace

Expected<FrameEntry> frameEntry(const fs::path& file) {
  std::smatch m;
  const std::string name = file.filename().string();
  if (!std::regex_match(name, m, frameFilePattern()))
    return fail(ErrorCode::kUsage, "{}: not a frame (expected frame_NNNNN.exr or frame_NNNNN.json, docs/feature-buffers.md)", file.string());
  FrameEntry entry;
  entry.frame = std::stol(m[1].str());
  entry.image = fs::path(file).replace_extension(".exr"), entry.sidecar = fs::path(file).replace_extension(".json");
  return entry;
}

Expected<std::vector<FrameEntry>> listFrames(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(ErrorCode::kIo, "{}: not a folder of frames", dir.string());
  const std::regex& pattern = frameFilePattern();
  std::map<long, FrameEntry> frames;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (!std::regex_match(name, m, pattern)) continue;
    const long f = std::stol(m[1].str());
    auto& entry = frames[f];
    entry.frame = f;
    (m[2] == "exr" ? entry.image : entry.sidecar) = e.path();
  }
  if (ec) return fail(ErrorCode::kIo, "{}: cannot list: {}", dir.string(), ec.message());
  std::vector<FrameEntry> out;
  for (auto& [f, entry] : frames) {
    if (entry.image.empty())
      return fail(ErrorCode::kInvalidData, "{}: has no {} beside it (every sidecar needs its frame)", entry.sidecar.string(),
                  frameImagePath({}, f).string());
    if (entry.sidecar.empty())
      return fail(ErrorCode::kInvalidData, "{}: has no {} beside it (the camera sidecar; an interrupted render?)", entry.image.string(),
                  frameSidecarPath({}, f).string());
    out.push_back(entry);
  }
  return out;
}

Expected<FeatureFrame> readFrame(const FrameEntry& entry, const ReadOptions& options) {
  auto sidecar = readSidecar(entry.sidecar);
  if (!sidecar) return std::unexpected(sidecar.error());
  FeatureFrame f;
  f.frame = entry.frame;
  f.time = sidecar->time;
  f.camera = sidecar->camera;
  f.sampling = sidecar->sampling;
  f.cut = sidecar->cut;

  auto image = readImage(entry.image);
  if (!image) return std::unexpected(image.error());
  if (image->width != f.camera.width || image->height != f.camera.height)
    return fail(ErrorCode::kInvalidData, "{}: is {}x{} but its sidecar says {}x{}", entry.image.string(), image->width, image->height,
                f.camera.width, f.camera.height);
  f.width = image->width;
  f.height = image->height;
  auto channel = [&](const std::string& name) -> int {
    const auto it = std::find(image->channelNames.begin(), image->channelNames.end(), name);
    return it == image->channelNames.end() ? -1 : static_cast<int>(it - image->channelNames.begin());
  };
  const std::size_t pixels = f.pixelCount();
  for (const auto& spec : contractBuffers()) {
    std::vector<int> at;
    for (const auto& n : spec.channels) at.push_back(channel(n));
    const bool variance = spec.member == &FeatureFrame::directVariance || spec.member == &FeatureFrame::indirectVariance;
    if (std::find(at.begin(), at.end(), -1) != at.end()) {
      if (!spec.required && !(variance && options.requireVariance)) continue;
      std::string missing;
      for (std::size_t k = 0; k < at.size(); ++k)
        if (at[k] < 0) missing += (missing.empty() ? "" : ", ") + spec.channels[k];
      return fail(ErrorCode::kInvalidData, "{}: lacks the channel(s) {} (docs/feature-buffers.md lists the contract)", entry.image.string(),
                  missing);
    }
    auto& target = f.*spec.member;
    target.resize(pixels * at.size());
    for (std::size_t p = 0; p < pixels; ++p)
      for (std::size_t k = 0; k < at.size(); ++k)
        target[p * at.size() + k] = image->pixels[p * static_cast<std::size_t>(image->channels) + static_cast<std::size_t>(at[k])];
  }
  return f;
}

namespace {

// Whether a buffer of these values is stored as half (Storage's rules).
bool storedAsHalf(const BufferSpec& spec, const std::vector<float>& values) {
  constexpr float kHalfMax = 65504.0f;  // the largest finite half
  const float limit = std::min(spec.halfLimit, kHalfMax);
  switch (spec.storage) {
    case Storage::kFloat32:
      return false;
    case Storage::kFloat16:
      return std::all_of(values.begin(), values.end(), [limit](float v) { return !std::isfinite(v) || std::abs(v) <= limit; });
    case Storage::kFloat16WhenExact:
      return std::all_of(values.begin(), values.end(), [](float v) { return glm::unpackHalf1x16(glm::packHalf1x16(v)) == v; });
  }
  return false;
}

}  // namespace

Expected<FloatImage> frameImage(const FeatureFrame& frame, const WriteOptions& options) {
  FloatImage image;
  // ZIP (zlib over 16 scanlines, with OpenEXR's predictor): lossless, and the smallest of
  // OpenEXR's lossless codecs on these buffers (docs/feature-buffers.md has the measurements).
  image.compression = "zip";
  image.width = frame.width;
  image.height = frame.height;
  std::vector<const std::vector<float>*> present;
  std::vector<std::size_t> widths;
  const std::size_t pixels = frame.pixelCount();
  for (const auto& spec : contractBuffers()) {
    const auto& buffer = frame.*spec.member;
    if (buffer.empty()) {
      if (spec.required) return fail(ErrorCode::kInvalidData, "frame {}: the {} buffer is required by the contract", frame.frame, spec.name);
      continue;
    }
    if (buffer.size() != pixels * spec.channels.size())
      return fail(ErrorCode::kInvalidData, "frame {}: the {} buffer has {} values, expected {}", frame.frame, spec.name, buffer.size(),
                  pixels * spec.channels.size());
    image.channelNames.insert(image.channelNames.end(), spec.channels.begin(), spec.channels.end());
    const bool half = !options.float32 && storedAsHalf(spec, buffer);
    image.formats.insert(image.formats.end(), spec.channels.size(), half ? SampleFormat::kFloat16 : SampleFormat::kFloat32);
    present.push_back(&buffer);
    widths.push_back(spec.channels.size());
  }
  image.channels = static_cast<int>(image.channelNames.size());
  image.pixels.resize(pixels * image.channelNames.size());
  float* out = image.pixels.data();
  for (std::size_t i = 0; i < pixels; ++i)
    for (std::size_t b = 0; b < present.size(); ++b)
      for (std::size_t c = 0; c < widths[b]; ++c) *out++ = (*present[b])[i * widths[b] + c];
  return image;
}

Expected<void> writeFrame(const fs::path& dir, const FeatureFrame& frame, const json& render, const WriteOptions& options) {
  auto image = frameImage(frame, options);
  if (!image) return std::unexpected(image.error());
  if (auto w = writeImage(frameImagePath(dir, frame.frame), *image); !w) return w;
  // The sidecar last: its presence marks the frame complete.
  json sidecar = sidecarJson(frame.frame, frame.time, frame.camera, render);
  if (frame.sampling) sidecar["sampling"] = samplingJson(*frame.sampling);
  if (frame.cut) sidecar["cut"] = true;
  return writeFileAtomic(frameSidecarPath(dir, frame.frame), sidecar.dump(2) + "\n");
}

bool frameComplete(const fs::path& dir, long frame, const json& render) {
  std::error_code ec;
  if (!fs::is_regular_file(frameImagePath(dir, frame), ec)) return false;
  auto sidecar = readSidecar(frameSidecarPath(dir, frame));
  return sidecar && sidecar->render == render;
}

}  // namespace dynbench::frames
