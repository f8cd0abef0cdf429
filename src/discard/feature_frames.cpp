#include "discard/feature_frames.h"

#include <algorithm>
#include <map>
#include <regex>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/files.h"
#include "core/image_io.h"

namespace dynbench::discard {
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

}  // namespace

Expected<std::vector<FrameEntry>> listFrames(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail(ErrorCode::kIo, "{}: not a folder of frames", dir.string());
  const std::regex pattern(R"(frame_(\d+)\.(exr|json))");
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
  std::vector<FrameEntry> out;
  for (auto& [f, entry] : frames) {
    if (entry.image.empty())
      return fail(ErrorCode::kInvalidData, "{}: has no {} beside it (every sidecar needs its frame)", entry.sidecar.string(),
                  fmt::format("frame_{:05d}.exr", f));
    if (entry.sidecar.empty())
      return fail(ErrorCode::kInvalidData, "{}: has no {} beside it (the camera sidecar; an interrupted render?)", entry.image.string(),
                  fmt::format("frame_{:05d}.json", f));
    out.push_back(entry);
  }
  if (out.size() < 2) return fail(ErrorCode::kInvalidData, "{}: needs at least two frames (found {})", dir.string(), out.size());
  return out;
}

Expected<FeatureFrame> readFeatureFrame(const FrameEntry& entry, bool needVariance) {
  auto text = readWholeFile(entry.sidecar);
  if (!text) return std::unexpected(text.error());
  json j;
  try {
    j = json::parse(*text);
  } catch (const json::parse_error& e) {
    return fail(ErrorCode::kParse, "{}: not valid JSON: {}", entry.sidecar.string(), e.what());
  }
  FeatureFrame f;
  f.frame = entry.frame;
  for (const char* key : {"width", "height"})
    if (!j.contains(key) || !j[key].is_number_integer() || j[key].get<int>() <= 0)
      return fail(ErrorCode::kInvalidData, "{}: /{}: expected a positive whole number", entry.sidecar.string(), key);
  f.camera.width = j["width"].get<int>();
  f.camera.height = j["height"].get<int>();
  if (j.contains("time") && j["time"].is_number()) f.time = j["time"].get<double>();
  auto view = matrixAt(j, entry.sidecar, "/camera/view");
  if (!view) return std::unexpected(view.error());
  auto projection = matrixAt(j, entry.sidecar, "/camera/projection");
  if (!projection) return std::unexpected(projection.error());
  f.camera.view = *view;
  f.camera.projection = *projection;

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
  struct Wanted {
    std::vector<std::string> names;
    std::vector<float>* target;
    bool required;
  };
  const std::vector<Wanted> wanted{{{"P.X", "P.Y", "P.Z"}, &f.position, true},
                                   {{"N.X", "N.Y", "N.Z"}, &f.normal, true},
                                   {{"direct.R", "direct.G", "direct.B"}, &f.direct, true},
                                   {{"indirect.R", "indirect.G", "indirect.B"}, &f.indirect, true},
                                   {{"hit"}, &f.hit, true},
                                   {{"direct.var"}, &f.directVariance, needVariance},
                                   {{"indirect.var"}, &f.indirectVariance, needVariance}};
  const auto pixels = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height);
  for (const auto& w : wanted) {
    std::vector<int> at;
    for (const auto& n : w.names) at.push_back(channel(n));
    if (std::find(at.begin(), at.end(), -1) != at.end()) {
      if (!w.required) continue;
      std::string missing;
      for (std::size_t k = 0; k < at.size(); ++k)
        if (at[k] < 0) missing += (missing.empty() ? "" : ", ") + w.names[k];
      return fail(ErrorCode::kInvalidData, "{}: lacks the channel(s) {} (docs/feature-buffers.md lists the contract)", entry.image.string(),
                  missing);
    }
    w.target->resize(pixels * at.size());
    for (std::size_t p = 0; p < pixels; ++p)
      for (std::size_t k = 0; k < at.size(); ++k)
        (*w.target)[p * at.size() + k] = image->pixels[p * static_cast<std::size_t>(image->channels) + static_cast<std::size_t>(at[k])];
  }
  return f;
}

}  // namespace dynbench::discard
