// A Utah-style OBJ key-frame sequence: one OBJ file per key frame, same topology in every file,
// played as a morph animation at a fixed rate. Frame 0 is the base mesh; frame k (k >= 1) becomes
// morph target k-1 (its positions and normals minus frame 0's), and one LINEAR weights channel per
// mesh node moves a single unit weight from target to target: at t = k / rate only target k-1 is
// on, so the mesh equals frame k exactly and blends linearly between key frames.
// Each OBJ (with its .mtl) is read through loadWithAssimp.
#include <algorithm>
#include <cctype>
#include <fnmatch.h>

#include "core/files.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

namespace fs = std::filesystem;

// "frame2.obj" before "frame10.obj": compares digit runs by value.
bool naturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t i2 = i, j2 = j;
      while (i2 < a.size() && std::isdigit(static_cast<unsigned char>(a[i2]))) ++i2;
      while (j2 < b.size() && std::isdigit(static_cast<unsigned char>(b[j2]))) ++j2;
      const auto da = a.substr(i, i2 - i), db = b.substr(j, j2 - j);
      const auto ta = da.substr(std::min(da.find_first_not_of('0'), da.size()));
      const auto tb = db.substr(std::min(db.find_first_not_of('0'), db.size()));
      if (ta.size() != tb.size()) return ta.size() < tb.size();
      if (ta != tb) return ta < tb;
      i = i2;
      j = j2;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

bool isObj(const fs::path& p) {
  return lowercaseExtension(p) == ".obj";
}

}  // namespace

Expected<std::vector<fs::path>> expandObjSequence(const fs::path& path) {
  std::vector<fs::path> files;
  const std::string text = path.string();
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    for (const auto& entry : fs::directory_iterator(path, ec))
      if (entry.is_regular_file() && isObj(entry.path())) files.push_back(entry.path());
    if (files.empty()) return fail(ErrorCode::kIo, "{}: the folder holds no .obj files", text);
  } else if (text.find_first_of("*?[") != std::string::npos) {
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    const std::string pattern = path.filename().string();
    if (dir.string().find_first_of("*?[") != std::string::npos)
      return fail(ErrorCode::kUsage, "{}: only the file name part of a glob may hold wildcards", text);
    for (const auto& entry : fs::directory_iterator(dir, ec))
      if (entry.is_regular_file() && ::fnmatch(pattern.c_str(), entry.path().filename().c_str(), 0) == 0)
        files.push_back(entry.path());
    if (ec) return fail(ErrorCode::kIo, "{}: cannot list the folder: {}", dir.string(), ec.message());
    if (files.empty()) return fail(ErrorCode::kIo, "{}: no file matches", text);
  } else {
    return files;
  }
  std::sort(files.begin(), files.end(),
            [](const fs::path& a, const fs::path& b) { return naturalLess(a.filename().string(), b.filename().string()); });
  return files;
}

Expected<Scene> loadObjSequence(const std::vector<fs::path>& frames, const fs::path& displayPath, double rate) {
  if (frames.empty()) return fail(ErrorCode::kUsage, "{}: an OBJ sequence needs at least one file", displayPath.string());
  if (!(rate > 0)) return fail(ErrorCode::kUsage, "{}: the sequence rate must be positive (got {})", displayPath.string(), rate);
  auto first = loadWithAssimp(frames[0]);
  if (!first) return first;
  Scene scene = std::move(*first);
  scene.source.path = displayPath;
  scene.source.format = "OBJ sequence";
  const std::size_t keyCount = frames.size();
  const std::size_t targetCount = keyCount - 1;
  for (auto& mesh : scene.meshes)
    for (auto& prim : mesh.primitives) prim.targets.resize(targetCount);

  for (std::size_t k = 1; k < keyCount; ++k) {
    auto frame = loadWithAssimp(frames[k]);
    if (!frame) return frame;
    for (const auto& f : frame->source.files)
      if (std::none_of(scene.source.files.begin(), scene.source.files.end(), [&](const SourceFile& s) { return s.path == f.path; }))
        scene.source.files.push_back(f);
    if (frame->meshes.size() != scene.meshes.size())
      return fail(ErrorCode::kInvalidData, "{}: has {} meshes but {} has {}; every file of an OBJ sequence must share one topology",
                  frames[k].string(), frame->meshes.size(), frames[0].string(), scene.meshes.size());
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
      auto& base = scene.meshes[m];
      const auto& now = frame->meshes[m];
      if (now.primitives.size() != base.primitives.size())
        return fail(ErrorCode::kInvalidData, "{}: mesh {} has {} parts but {} has {}", frames[k].string(), m,
                    now.primitives.size(), frames[0].string(), base.primitives.size());
      for (std::size_t p = 0; p < base.primitives.size(); ++p) {
        auto& bp = base.primitives[p];
        const auto& np = now.primitives[p];
        if (np.positions.size() != bp.positions.size() || np.indices != bp.indices)
          return fail(ErrorCode::kInvalidData,
                      "{}: mesh {} part {} has {} vertices / {} indices but {} has {} / {}; every file of an OBJ "
                      "sequence must share one topology",
                      frames[k].string(), m, p, np.positions.size(), np.indices.size(), frames[0].string(),
                      bp.positions.size(), bp.indices.size());
        MorphTarget& target = bp.targets[k - 1];
        target.positionDeltas.resize(bp.positions.size());
        for (std::size_t v = 0; v < bp.positions.size(); ++v) target.positionDeltas[v] = np.positions[v] - bp.positions[v];
        if (!bp.normals.empty() && np.normals.size() == bp.normals.size()) {
          target.normalDeltas.resize(bp.normals.size());
          for (std::size_t v = 0; v < bp.normals.size(); ++v) target.normalDeltas[v] = np.normals[v] - bp.normals[v];
        }
      }
    }
  }
  for (auto& mesh : scene.meshes) mesh.defaultWeights.assign(targetCount, 0.0f);
  if (targetCount == 0) return scene;

  // One shared sampler: key k has weight 1 on target k-1 and 0 elsewhere (key 0: all zero).
  Animation animation;
  animation.name = "OBJ sequence";
  Sampler sampler;
  sampler.interpolation = Interpolation::kLinear;
  sampler.components = static_cast<int>(targetCount);
  sampler.values.assign(keyCount * targetCount, 0.0f);
  for (std::size_t k = 0; k < keyCount; ++k) {
    sampler.times.push_back(static_cast<float>(static_cast<double>(k) / rate));
    if (k > 0) sampler.values[k * targetCount + (k - 1)] = 1.0f;
  }
  animation.samplers.push_back(std::move(sampler));
  for (std::size_t n = 0; n < scene.nodes.size(); ++n)
    if (scene.nodes[n].mesh >= 0) animation.channels.push_back({0, static_cast<int>(n), AnimationPath::kWeights});
  scene.animations.push_back(std::move(animation));
  return scene;
}

}  // namespace dynbench::scene
