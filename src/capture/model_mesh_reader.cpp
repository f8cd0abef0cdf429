// models/*.txt (docs/capture-format.md): a captured model's meshes, skeleton and key frames.
#include <algorithm>
#include <set>

#include "capture/format.h"
#include "capture/reader.h"
#include "capture/record_lexer.h"

namespace dynbench::capture {

namespace fs = std::filesystem;

namespace {

// What a ModelMesh file declares as it goes, checked against what it holds at its end.
struct Declared {
  std::vector<std::size_t> vertices, triangles;   // per mesh (M records)
  std::vector<std::vector<int>> influenceCounts;  // per mesh, per vertex: joints listed by `j`
  std::set<int> bound, inverseBound;              // joints with a `b` record, with an `x` record
};

// The whole model against its declarations: a name, both poses of every joint, joints or key
// frames, every mesh's per-vertex records as many as its vertices, its triangles as declared and
// in range, every joint a vertex uses in the model. `where` is file:last line.
Expected<void> checkModel(const CapturedModel& model, const Declared& declared, const std::string& where) {
  const auto invalid = [&](const std::string& what) { return std::unexpected(Error{ErrorCode::kInvalidData, where + ": " + what}); };
  if (model.path.empty()) return invalid("no 'o' record naming the model");
  if (declared.bound != declared.inverseBound) return invalid("every joint needs both a 'b' and an 'x' record");
  if (model.keyFrames > 0 && !model.joints.empty()) return invalid("a model has joints or key frames ('K'), not both");
  for (const auto& mesh : model.meshes) {
    const std::size_t n = declared.vertices[static_cast<std::size_t>(mesh.id)];
    // Each per-vertex record as many as the vertices (an optional one may be absent altogether).
    const auto vertexRecords = [&](std::size_t count, const std::string& what, bool optional) -> Expected<void> {
      if (count == n || (optional && count == 0)) return {};
      return invalid(fmt::format("mesh {} declares {} vertices but has {} {} records", mesh.id, n, count, what));
    };
    for (const auto& [count, what, optional] : {std::tuple{mesh.positions.size(), "'p'", false}, {mesh.normals.size(), "'n'", true},
                                                {mesh.uvs.size(), "'t'", true}, {mesh.colors.size(), "'c'", true},
                                                {mesh.joints.size(), "'j'", true}, {mesh.weights.size(), "'w'", true}})
      if (auto ok = vertexRecords(count, what, optional); !ok) return ok;
    const std::size_t triangles = declared.triangles[static_cast<std::size_t>(mesh.id)];
    if (mesh.indices.size() != 3 * triangles)
      return invalid(fmt::format("mesh {} declares {} triangles but has {} 'i' records", mesh.id, triangles, mesh.indices.size() / 3));
    for (std::size_t f = 0; f < mesh.keyPositions.size(); ++f) {
      if (auto ok = vertexRecords(mesh.keyPositions[f].size(), fmt::format("'P' (key frame {})", f), false); !ok) return ok;
      if (mesh.keyNormals.empty()) continue;
      if (auto ok = vertexRecords(mesh.keyNormals[f].size(), fmt::format("'N' (key frame {})", f), false); !ok) return ok;
    }
    for (std::uint32_t index : mesh.indices)
      if (index >= n) return invalid(fmt::format("mesh {} has a triangle using vertex {} of {}", mesh.id, index, n));
    for (std::size_t v = 0; v < mesh.joints.size(); ++v)
      for (int k = 0; k < declared.influenceCounts[static_cast<std::size_t>(mesh.id)][v]; ++k)
        if (mesh.joints[v][k] >= model.joints.size())
          return invalid(fmt::format("mesh {} vertex {} uses joint {} but the model has {} joints", mesh.id, v, mesh.joints[v][k], model.joints.size()));
  }
  return {};
}

}  // namespace

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
  Declared declared;
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
      declared.vertices.push_back(l.integer<std::size_t>(2, "vertex_count"));
      declared.triangles.push_back(l.integer<std::size_t>(3, "triangle_count"));
      model.meshes.push_back(std::move(mesh));
      declared.influenceCounts.emplace_back();
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
      auto& counts = declared.influenceCounts[static_cast<std::size_t>(mesh.id)];
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
        declared.bound.insert(id);
      } else {
        if (id < 0 || static_cast<std::size_t>(id) >= model.joints.size()) l.fail(fmt::format("inverse bind pose of joint {} before its bind pose", id));
        if (parent != model.joints[static_cast<std::size_t>(id)].parent) l.fail(fmt::format("joint {}: parent {} differs from the bind pose's", id, parent));
        model.joints[static_cast<std::size_t>(id)].inverseBindPose = l.dualQuat(3);
        declared.inverseBound.insert(id);
      }
    } else {
      l.fail(fmt::format("unknown record '{}'; a ModelMesh file has o, M, p, n, t, c, j, w, i, a, g, f, r, e, E, m, b, x, K, P, N", token),
             ErrorCode::kParse);
    }
  }
  if (auto ok = checkModel(model, declared, fmt::format("{}:{}", file, source.number())); !ok) raise(ok.error());
  return model;
}



Expected<CapturedModel> readModelMesh(const fs::path& file) {
  try {
    return parseModelMesh(file);
  } catch (const Failure& f) {
    return std::unexpected(f.error);
  }
}

}  // namespace dynbench::capture
