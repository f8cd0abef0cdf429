#include "camera/merge_camera.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "capture/reader.h"
#include "convert/gltf_writer.h"
#include "core/files.h"
#include "core/math.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace dynbench::camera {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
// The one glTF writer (convert/gltf_writer.h) writes the merged dataset.
using convert::BinaryBuffer, convert::addDataAccessor, convert::kFloat, convert::writeDataset;

Expected<std::vector<CameraPoseKey>> readCaptureRun(const fs::path& dir) {
  auto reader = capture::CaptureReader::open(dir);
  if (!reader) return std::unexpected(reader.error());
  std::vector<CameraPoseKey> keys;
  std::optional<std::uint64_t> camera;
  capture::CaptureFrame frame;
  while (true) {
    auto more = (*reader)->next(frame);
    if (!more) return std::unexpected(more.error());
    if (!*more) break;
    for (const auto& c : frame.cameras) {
      if (!camera) camera = c.id;
      if (c.id != *camera) continue;
      keys.push_back({frame.time, c.position, quatFromYawPitchRoll(radians(c.yaw), radians(c.pitch), radians(c.roll))});
    }
  }
  if (keys.empty()) return fail(ErrorCode::kInvalidData, "{}: the capture has no camera records", dir.string());
  return keys;
}

}  // namespace

Expected<std::vector<CameraPoseKey>> readPoseCsv(const fs::path& file, const PoseCsvRules& rules) {
  std::ifstream in(file);
  if (!in) return fail(ErrorCode::kIo, "{}: cannot open", file.string());
  std::vector<CameraPoseKey> keys;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> values;
    std::stringstream fields(line);
    std::string field;
    bool numeric = true;
    while (std::getline(fields, field, ',')) {
      const auto start = field.find_first_not_of(" \t"), end = field.find_last_not_of(" \t");
      field = start == std::string::npos ? "" : field.substr(start, end - start + 1);
      double v = 0;
      const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
      if (ec != std::errc() || ptr != field.data() + field.size() || field.empty()) {
        numeric = false;
        break;
      }
      values.push_back(v);
    }
    if (!numeric) {
      if (keys.empty() && number == 1) continue;  // a header line
      return fail(ErrorCode::kParse, "{}:{}: '{}' is not a number; expected time,x,y,z,qx,qy,qz,qw", file.string(), number, field);
    }
    if (values.size() != 8)
      return fail(ErrorCode::kParse, "{}:{}: {} fields; expected 8 (time,x,y,z,qx,qy,qz,qw)", file.string(), number, values.size());
    for (double v : values)
      if (!std::isfinite(v)) return fail(ErrorCode::kInvalidData, "{}:{}: values must be finite", file.string(), number);
    const glm::dquat q(values[7], values[4], values[5], values[6]);
    if (glm::length(q) < 1e-6) return fail(ErrorCode::kInvalidData, "{}:{}: the quaternion has zero length", file.string(), number);
    if (std::abs(glm::length(q) - 1.0) > rules.unitTolerance)
      return fail(ErrorCode::kInvalidData, "{}:{}: the quaternion (qx,qy,qz,qw) has length {:.6f}; expected a unit quaternion (within {})",
                  file.string(), number, glm::length(q), rules.unitTolerance);
    if (!keys.empty() && !(values[0] > keys.back().time))
      return fail(ErrorCode::kInvalidData, "{}:{}: time {} is not after {}; times must increase", file.string(), number, values[0],
                  keys.back().time);
    keys.push_back({values[0], {values[1], values[2], values[3]}, glm::normalize(q)});
  }
  if (keys.empty()) return fail(ErrorCode::kInvalidData, "{}: no pose lines", file.string());
  if (keys.size() < rules.minimumPoses)
    return fail(ErrorCode::kInvalidData, "{}: {} pose lines; expected at least {}", file.string(), keys.size(), rules.minimumPoses);
  return keys;
}

Expected<AnimatedCamera> loadAnimatedCamera(const fs::path& dataset, const std::string& purpose) {
  AnimatedCamera c;
  auto scene = scene::loadScene(dataset);
  if (!scene) return std::unexpected(scene.error());
  c.scene = std::move(*scene);
  auto node = scene::selectCameraNode(c.scene, std::nullopt);
  if (!node) return std::unexpected(node.error());
  if (*node < 0) return fail(ErrorCode::kInvalidData, "{}: no camera to {}", dataset.string(), purpose);
  c.node = *node;
  c.range = c.scene.timeRange();
  if (!(c.duration() > 0)) return fail(ErrorCode::kInvalidData, "{}: no animation to {}", dataset.string(), purpose);
  return c;
}

Expected<std::vector<CameraPoseKey>> readCameraRun(const fs::path& run) {
  std::error_code ec;
  if (fs::is_directory(run, ec)) return readCaptureRun(run);
  return readPoseCsv(run);
}

Expected<void> writeCameraRunCsv(const fs::path& csv, const std::vector<CameraPoseKey>& keys) {
  std::string out = "time,x,y,z,qx,qy,qz,qw\n";
  for (const CameraPoseKey& k : keys)
    out += fmt::format("{},{},{},{},{},{},{},{}\n", k.time, k.position.x, k.position.y, k.position.z, k.rotation.x, k.rotation.y, k.rotation.z,
                       k.rotation.w);
  return writeFileAtomic(csv, out);
}

Expected<MergeCameraReport> mergeCamera(const MergeCameraOptions& options) {
  const fs::path datasetDir = fs::absolute(options.dataset).parent_path().lexically_normal();
  const fs::path outputDir = fs::absolute(options.output).parent_path().lexically_normal();
  if (options.dataset.extension() != ".gltf" || options.output.extension() != ".gltf")
    return fail(ErrorCode::kUsage, "merge-camera reads and writes .gltf files (with an external .bin)");
  if (datasetDir != outputDir)
    return fail(ErrorCode::kUsage, "-o {}: write the output beside {} (same folder) so that its textures stay reachable",
                options.output.string(), options.dataset.string());
  // Validates the dataset and finds its camera with the same rules as `stats`.
  auto scene = scene::loadScene(options.dataset);
  if (!scene) return std::unexpected(scene.error());
  auto node = scene::selectCameraNode(*scene, options.camera);
  if (!node) return std::unexpected(node.error());
  if (*node < 0) return fail(ErrorCode::kInvalidData, "{}: the dataset has no camera", options.dataset.string());
  auto run = readCameraRun(options.run);
  if (!run) return std::unexpected(run.error());

  auto text = readWholeFile(options.dataset);
  if (!text) return std::unexpected(text.error());
  json doc = json::parse(*text);  // valid: loadScene read it
  if (doc["buffers"].size() != 1 || !doc["buffers"][0].contains("uri") ||
      doc["buffers"][0]["uri"].get<std::string>().rfind("data:", 0) == 0)
    return fail(ErrorCode::kUnsupported, "{}: merge-camera needs a dataset with one external .bin buffer (as convert writes)",
                options.dataset.string());
  const fs::path bin = datasetDir / scene::percentDecodeUri(doc["buffers"][0]["uri"].get<std::string>());

  // The run's poses are world poses; the channels are the camera node's local ones. Under a parent
  // the local pose is parent_world(t)^-1 * world, with the parent as animated at that key's time.
  const int parent = scene->nodes[static_cast<std::size_t>(*node)].parent;
  const scene::Evaluator evaluator(*scene);

  // New keys in dataset time: the run's first key lands on the dataset's start, plus the offset.
  const double start = scene->timeRange().start + options.offsetSeconds - run->front().time;
  std::vector<float> times, translations, rotations;
  glm::dquat previous(1, 0, 0, 0);
  for (const auto& key : *run) {
    const double t = key.time + start;
    if (t < 0) return fail(ErrorCode::kUsage, "--offset {}: the run would start before time 0", options.offsetSeconds);
    if (!times.empty() && !(static_cast<float>(t) > times.back()))
      return fail(ErrorCode::kInvalidData, "{}: two poses {} s apart collapse into one float key time", options.run.string(),
                  key.time - (times.back() - start));
    glm::dvec3 position = key.position;
    glm::dquat q = key.rotation;
    if (parent >= 0) {
      const glm::dmat4 parentWorld = evaluator.worldMatrix(parent, t);
      const glm::dvec3 scale(glm::length(glm::dvec3(parentWorld[0])), glm::length(glm::dvec3(parentWorld[1])),
                             glm::length(glm::dvec3(parentWorld[2])));
      if (glm::any(glm::greaterThan(glm::abs(scale - 1.0), glm::dvec3(1e-6))))
        return fail(ErrorCode::kUnsupported, "{}: the camera's parent is scaled ({}, {}, {}) at t = {} s; merge-camera writes rigid camera keys",
                    options.dataset.string(), scale.x, scale.y, scale.z, t);
      const RigidPose parentPose = decomposeRigid(parentWorld);
      const glm::dquat inverse = glm::inverse(parentPose.rotation);
      position = inverse * (position - parentPose.position);
      q = inverse * q;
    }
    if (glm::dot(previous, q) < 0) q = -q;  // shortest arc between keys
    previous = q;
    times.push_back(static_cast<float>(t));
    translations.insert(translations.end(), {float(position.x), float(position.y), float(position.z)});
    rotations.insert(rotations.end(), {float(q.x), float(q.y), float(q.z), float(q.w)});
  }

  // The new buffer: a copy of the old one with the camera keys appended (gltf_writer.h).
  const fs::path tmpBin = temporarySibling(outputDir / (options.output.stem().string() + ".bin"));
  std::error_code ec;
  fs::copy_file(bin, tmpBin, fs::copy_options::overwrite_existing, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot copy to {}: {}", bin.string(), tmpBin.string(), ec.message());
  BinaryBuffer buffer(tmpBin, BinaryBuffer::Mode::kAppend);
  const int input = addDataAccessor(doc, buffer, times, kFloat, "SCALAR", 0, json::array({times.front()}), json::array({times.back()}));
  const std::map<std::string, int> outputs{{"translation", addDataAccessor(doc, buffer, translations, kFloat, "VEC3")},
                                           {"rotation", addDataAccessor(doc, buffer, rotations, kFloat, "VEC4")}};
  if (auto ok = buffer.finish(); !ok) {
    fs::remove(tmpBin, ec);
    return std::unexpected(ok.error());
  }
  const std::uint64_t binBytes = buffer.size();
  // Repoint the camera's translation and rotation samplers; add channels where there were none.
  if (!doc.contains("animations") || doc["animations"].empty())
    doc["animations"] = {{{"name", "camera"}, {"samplers", json::array()}, {"channels", json::array()}}};
  std::set<std::string> done;
  for (auto& animation : doc["animations"])
    for (auto& channel : animation["channels"]) {
      const auto& target = channel["target"];
      if (!target.contains("node") || target["node"] != *node) continue;
      const std::string path = target.value("path", "");
      if (!outputs.contains(path)) continue;
      // A sampler may be shared with another node; it must not change under it: give this channel its own.
      animation["samplers"].push_back({{"input", input}, {"output", outputs.at(path)}, {"interpolation", "LINEAR"}});
      channel["sampler"] = animation["samplers"].size() - 1;
      done.insert(path);
    }
  for (const auto& [path, output] : outputs) {
    if (done.contains(path)) continue;
    auto& animation = doc["animations"][0];
    animation["samplers"].push_back({{"input", input}, {"output", output}, {"interpolation", "LINEAR"}});
    animation["channels"].push_back({{"sampler", animation["samplers"].size() - 1}, {"target", {{"node", *node}, {"path", path}}}});
  }
  // The old camera's cuts were jumps of its motion, which the run replaces: they go with it.
  auto& cameraNode = doc["nodes"][static_cast<std::size_t>(*node)];
  if (!options.keepCuts && cameraNode.contains("extras") && cameraNode["extras"].is_object()) {
    cameraNode["extras"].erase("dynbench_camera_cuts");
    if (cameraNode["extras"].empty()) cameraNode.erase("extras");
  }
  auto written = writeDataset(std::move(doc), tmpBin, binBytes, options.output, false);
  if (!written) return std::unexpected(written.error());
  return MergeCameraReport{*node, times.size(), times.front(), times.back()};
}

Expected<metrics::CameraMotion> mergeAndMeasure(const fs::path& dataset, const fs::path& csv, const fs::path& output, double fps) {
  MergeCameraOptions merge;
  merge.dataset = dataset;
  merge.run = csv;
  merge.output = output;
  if (auto merged = mergeCamera(merge); !merged) return std::unexpected(merged.error());
  auto scene = scene::loadScene(output);
  if (!scene) return std::unexpected(scene.error());
  return metrics::measureCameraMotion(*scene, fps, std::nullopt);
}

}  // namespace dynbench::camera
