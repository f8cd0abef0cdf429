// The capture SDK: the C API of include/dynbench/capture.h. Records go to Capture.txt one frame at
// a time: a frame's lines are collected in memory and written with one write and a flush at
// dbc_frame_end, so a crash of the host loses at most the frame in progress. ModelMesh files are
// written under a temporary name and renamed when complete.
#include "dynbench/capture.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "capture/format.h"
#include "core/files.h"

namespace {

namespace fs = std::filesystem;
using namespace dynbench::capture;

thread_local std::string lastError;

int error(int code, std::string message) {
  lastError = std::move(message);
  return code;
}

using Kind = CapturableKind;

bool finite(std::initializer_list<float> values) {
  for (float v : values)
    if (!std::isfinite(v)) return false;
  return true;
}

bool finite(const dbc_dual_quat& q) { return finite({q.rx, q.ry, q.rz, q.rw, q.dx, q.dy, q.dz, q.dw}); }

void appendDualQuat(std::string& line, const dbc_dual_quat& q) {
  for (float v : {q.rx, q.ry, q.rz, q.rw, q.dx, q.dy, q.dz, q.dw}) appendFloat(line, v);
}

}  // namespace

struct dbc_session {
  fs::path directory;
  std::FILE* capture = nullptr;
  std::map<std::string, int> modelJoints;  // complete models and their joint counts
  std::map<std::string, std::size_t> modelKeyFrames;  // complete models and their key-frame counts (0: none)
  int modelFiles = 0;
  // The model being recorded.
  bool inModel = false;
  std::string modelPath, modelText;
  int nextMesh = 0, nextJoint = 0;
  std::size_t lastMeshVertices = 0;  // of mesh nextMesh - 1
  int lastMeshWithFrames = -1;
  std::size_t keyFrames = 0;  // of the model being recorded (0: none yet)
  // Frames.
  bool inFrame = false, anyFrame = false;
  std::uint64_t lastFrame = 0, frameCount = 0;
  double lastTime = 0.0;
  std::string frameText;
  std::set<std::uint64_t> modelsThisFrame;  // ids with an `m` record in the current frame
  std::set<std::uint64_t> camerasThisFrame;  // ids with a `t` record in the current frame
  std::map<std::uint64_t, std::pair<Kind, std::string>> capturables;  // kind and model path per id
  std::uint64_t nextId = 1;

  // Settings written directly (outside frames) or into the frame (camera settings inside one).
  int writeRecord(const std::string& line) {
    if (inFrame) {
      frameText += line;
      frameText += '\n';
      return DBC_OK;
    }
    if (std::fputs(line.c_str(), capture) < 0 || std::fputc('\n', capture) == EOF || std::fflush(capture) != 0)
      return error(DBC_ERROR_IO, "cannot write " + (directory / kCaptureFile).string() + ": " + std::strerror(errno));
    return DBC_OK;
  }

  // One id, one kind and one model path for its whole life.
  int claim(std::uint64_t id, Kind kind, const std::string& path) {
    auto [it, inserted] = capturables.emplace(id, std::make_pair(kind, path));
    if (!inserted && (it->second.first != kind || it->second.second != path))
      return error(DBC_ERROR_ARGUMENT, fmt::format("capturable {} was recorded as a {} '{}'; it cannot become a {} '{}'", id,
                                                   capturableKindName(it->second.first), it->second.second, capturableKindName(kind), path));
    return DBC_OK;
  }

  int requireFrame(const char* what) const {
    if (!inFrame) return error(DBC_ERROR_ORDER, std::string(what) + " outside a frame: call dbc_frame_begin first");
    return DBC_OK;
  }

  int requireModel(const char* model_path) const {
    if (!model_path) return error(DBC_ERROR_ARGUMENT, "model path is NULL");
    if (!modelJoints.contains(model_path))
      return error(DBC_ERROR_ARGUMENT, fmt::format("unknown model '{}': record it with dbc_model_begin/end first", model_path));
    return DBC_OK;
  }
};

extern "C" {

const char* dbc_last_error(void) { return lastError.c_str(); }

int dbc_open(const char* directory, const char* source_name, dbc_session** session) {
  if (!directory || !session) return error(DBC_ERROR_ARGUMENT, "dbc_open: directory and session must not be NULL");
  *session = nullptr;
  auto s = std::make_unique<dbc_session>();
  s->directory = directory;
  std::error_code ec;
  fs::create_directories(s->directory / kModelsFolder, ec);
  if (ec) return error(DBC_ERROR_IO, "cannot create " + (s->directory / kModelsFolder).string() + ": " + ec.message());
  const fs::path file = s->directory / kCaptureFile;
  s->capture = std::fopen(file.c_str(), "wb");
  if (!s->capture) return error(DBC_ERROR_IO, "cannot create " + file.string() + ": " + std::strerror(errno));
  if (int rc = s->writeRecord(std::string(kCaptureVersionLine)); rc != DBC_OK) return rc;
  if (source_name)
    if (int rc = s->writeRecord("s:" + escapeField(source_name)); rc != DBC_OK) return rc;
  *session = s.release();
  return DBC_OK;
}

int dbc_close(dbc_session* session) {
  if (!session) return error(DBC_ERROR_ARGUMENT, "dbc_close: session is NULL");
  std::unique_ptr<dbc_session> s(session);
  int rc = DBC_OK;
  if (s->inFrame) rc = dbc_frame_end(s.get());
  if (rc == DBC_OK) rc = s->writeRecord(fmt::format("z:{}", s->frameCount));
  if (std::fclose(s->capture) != 0 && rc == DBC_OK) rc = error(DBC_ERROR_IO, std::string("closing Capture.txt: ") + std::strerror(errno));
  return rc;
}

int dbc_set_data_root(dbc_session* s, const char* path) {
  if (!s || !path) return error(DBC_ERROR_ARGUMENT, "dbc_set_data_root: NULL argument");
  if (s->inFrame) return error(DBC_ERROR_ORDER, "dbc_set_data_root inside a frame");
  return s->writeRecord("d:" + escapeField(path));
}

int dbc_set_metres_per_unit(dbc_session* s, float metres) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_set_metres_per_unit: session is NULL");
  if (!(metres > 0) || !std::isfinite(metres)) return error(DBC_ERROR_ARGUMENT, "metres per unit must be positive and finite");
  if (s->inFrame) return error(DBC_ERROR_ORDER, "dbc_set_metres_per_unit inside a frame");
  std::string line = "k";
  appendFloat(line, metres);
  return s->writeRecord(line);
}

int dbc_set_map(dbc_session* s, const char* map_name, const float offset[3]) {
  if (!s || !map_name || !offset) return error(DBC_ERROR_ARGUMENT, "dbc_set_map: NULL argument");
  if (!finite({offset[0], offset[1], offset[2]})) return error(DBC_ERROR_ARGUMENT, "dbc_set_map: offset is not finite");
  if (s->inFrame) return error(DBC_ERROR_ORDER, "dbc_set_map inside a frame");
  std::string line = "u";
  for (int i = 0; i < 3; ++i) appendFloat(line, offset[i]);
  return s->writeRecord(line + ":" + escapeField(map_name));
}

int dbc_set_lighting(dbc_session* s, const float sunDirection[3], const float sunRgb[3], const float ambientRgb[3], const float skyRgb[3]) {
  if (!s || !sunDirection || !sunRgb || !ambientRgb || !skyRgb) return error(DBC_ERROR_ARGUMENT, "dbc_set_lighting: NULL argument");
  if (s->inFrame) return error(DBC_ERROR_ORDER, "dbc_set_lighting inside a frame");
  const std::initializer_list<float> values = {sunDirection[0], sunDirection[1], sunDirection[2], sunRgb[0], sunRgb[1], sunRgb[2],
                                               ambientRgb[0], ambientRgb[1], ambientRgb[2], skyRgb[0], skyRgb[1], skyRgb[2]};
  if (!finite(values)) return error(DBC_ERROR_ARGUMENT, "dbc_set_lighting: a value is not finite");
  for (std::size_t k = 3; k < values.size(); ++k)
    if (values.begin()[k] < 0) return error(DBC_ERROR_ARGUMENT, "dbc_set_lighting: colours must not be negative");
  const bool sun = sunRgb[0] > 0 || sunRgb[1] > 0 || sunRgb[2] > 0;
  if (sun && !(sunDirection[0] != 0 || sunDirection[1] != 0 || sunDirection[2] != 0))
    return error(DBC_ERROR_ARGUMENT, "dbc_set_lighting: a sun needs a direction");
  std::string line = "L";
  for (float v : values) appendFloat(line, v);
  return s->writeRecord(line);
}

int dbc_set_camera_settings(dbc_session* s, float aspect, float yfov_degrees, float znear, float zfar) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_set_camera_settings: session is NULL");
  // Capture.txt's lens is one record of its header (docs/capture-format.md): readers refuse a
  // second one between frames, so it is refused here, before the capture is left unreadable.
  if (s->anyFrame) return error(DBC_ERROR_ORDER, "dbc_set_camera_settings after the first frame: the camera's lens is set once, before any frame");
  if (!finite({aspect, yfov_degrees, znear, zfar}) || !(aspect > 0) || !(yfov_degrees > 0 && yfov_degrees < 180) ||
      !(znear > 0) || !(zfar > znear))
    return error(DBC_ERROR_ARGUMENT, fmt::format("camera settings need aspect > 0, 0 < yfov < 180, 0 < znear < zfar "
                                                 "(got {}, {}, {}, {})", aspect, yfov_degrees, znear, zfar));
  std::string line = "C";
  for (float v : {aspect, yfov_degrees, znear, zfar}) appendFloat(line, v);
  return s->writeRecord(line);
}

int dbc_has_model(const dbc_session* s, const char* model_path) {
  return s && model_path && s->modelJoints.contains(model_path) ? 1 : 0;
}

int dbc_model_begin(dbc_session* s, const char* model_path) {
  if (!s || !model_path) return error(DBC_ERROR_ARGUMENT, "dbc_model_begin: NULL argument");
  if (s->inFrame || s->inModel) return error(DBC_ERROR_ORDER, "dbc_model_begin inside a frame or another model");
  if (s->modelJoints.contains(model_path)) return error(DBC_ERROR_ARGUMENT, fmt::format("model '{}' is already recorded", model_path));
  s->inModel = true;
  s->modelPath = model_path;
  s->modelText = fmt::format("{}\no:{}\n", kModelMeshVersionLine, escapeField(model_path));
  s->nextMesh = s->nextJoint = 0;
  s->lastMeshVertices = 0, s->lastMeshWithFrames = -1, s->keyFrames = 0;
  return DBC_OK;
}

int dbc_model_mesh(dbc_session* s, const dbc_mesh* m) {
  if (!s || !m) return error(DBC_ERROR_ARGUMENT, "dbc_model_mesh: NULL argument");
  if (!s->inModel) return error(DBC_ERROR_ORDER, "dbc_model_mesh outside dbc_model_begin/end");
  if (m->mesh_id != s->nextMesh) return error(DBC_ERROR_ARGUMENT, fmt::format("mesh_id {} given; expected {} (meshes in order)", m->mesh_id, s->nextMesh));
  if (!m->positions || !m->indices) return error(DBC_ERROR_ARGUMENT, "a mesh needs positions and indices");
  if ((m->joints == nullptr) != (m->weights == nullptr)) return error(DBC_ERROR_ARGUMENT, "joints and weights come together");
  std::string text = fmt::format("M:{}:{}:{}:{}\n", m->mesh_id, m->vertex_count, m->triangle_count, escapeField(m->name ? m->name : ""));
  if (m->texture) text += fmt::format("a:{}:{}\n", m->mesh_id, escapeField(m->texture));
  if (m->mask_texture) text += fmt::format("g:{}:{}\n", m->mesh_id, escapeField(m->mask_texture));
  // The material beyond the maps: each value finite and in its range, checked before anything is kept.
  auto factors = [&](char token, const float* data, std::size_t width, float high) {
    if (!data) return true;
    std::string line = fmt::format("{}:{}", token, m->mesh_id);
    for (std::size_t c = 0; c < width; ++c) {
      if (!std::isfinite(data[c]) || data[c] < 0 || data[c] > high) return false;
      appendFloat(line, data[c]);
    }
    text += line + "\n";
    return true;
  };
  if (!factors('f', m->base_color, 4, 1.0f))
    return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: base_color needs 4 finite values in [0, 1]", m->mesh_id));
  if (!factors('r', m->metallic_roughness, 2, 1.0f))
    return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: metallic_roughness needs 2 finite values in [0, 1]", m->mesh_id));
  if (!factors('e', m->emission, 3, std::numeric_limits<float>::max()))
    return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: emission needs 3 finite values >= 0", m->mesh_id));
  if (m->emission_texture)
    text += fmt::format("{}:{}:{}\n", m->emission_texture_mean_one ? 'm' : 'E', m->mesh_id, escapeField(m->emission_texture));
  auto row = [&](char token, const float* data, std::size_t width, std::size_t v) {
    std::string line = fmt::format("{}:{}", token, m->mesh_id);
    for (std::size_t c = 0; c < width; ++c) {
      if (!std::isfinite(data[v * width + c])) return false;
      appendFloat(line, data[v * width + c]);
    }
    text += line;
    text += '\n';
    return true;
  };
  for (std::size_t v = 0; v < m->vertex_count; ++v) {
    if (!row('p', m->positions, 3, v) || (m->normals && !row('n', m->normals, 3, v)) || (m->uvs && !row('t', m->uvs, 2, v)))
      return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: vertex {} has a value that is not finite", m->mesh_id, v));
    if (m->colors) {
      const float* c = m->colors + 4 * v;
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(c[k]) || c[k] < 0 || c[k] > 1)
          return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: vertex {} has a colour outside [0, 1]", m->mesh_id, v));
      row('c', m->colors, 4, v);
    }
    if (m->joints) {
      std::string j = fmt::format("j:{}", m->mesh_id), w = fmt::format("w:{}", m->mesh_id);
      int influences = 0;
      for (int k = 0; k < 4; ++k) {
        const float weight = m->weights[v * 4 + static_cast<std::size_t>(k)];
        if (!std::isfinite(weight) || weight < 0) return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: vertex {} has a bad weight", m->mesh_id, v));
        if (weight == 0) continue;
        fmt::format_to(std::back_inserter(j), ":{}", m->joints[v * 4 + static_cast<std::size_t>(k)]);
        appendFloat(w, weight);
        ++influences;
      }
      if (influences == 0) return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: vertex {} has no joint influence", m->mesh_id, v));
      text += j + "\n" + w + "\n";
    }
  }
  for (std::size_t t = 0; t < m->triangle_count; ++t) {
    const std::uint32_t* tri = m->indices + 3 * t;
    for (int k = 0; k < 3; ++k)
      if (tri[k] >= m->vertex_count)
        return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: triangle {} uses vertex {} of {}", m->mesh_id, t, tri[k], m->vertex_count));
    text += fmt::format("i:{}:{}:{}:{}\n", m->mesh_id, tri[0], tri[1], tri[2]);
  }
  s->modelText += text;
  ++s->nextMesh;
  s->lastMeshVertices = m->vertex_count;
  return DBC_OK;
}

int dbc_model_mesh_frames(dbc_session* s, int mesh_id, size_t frame_count, const float* positions, const float* normals) {
  if (!s || !positions) return error(DBC_ERROR_ARGUMENT, "dbc_model_mesh_frames: NULL argument");
  if (!s->inModel) return error(DBC_ERROR_ORDER, "dbc_model_mesh_frames outside dbc_model_begin/end");
  if (mesh_id != s->nextMesh - 1 || mesh_id == s->lastMeshWithFrames)
    return error(DBC_ERROR_ORDER, fmt::format("dbc_model_mesh_frames for mesh {}: call it once, right after that mesh's dbc_model_mesh", mesh_id));
  if (s->nextJoint > 0) return error(DBC_ERROR_ARGUMENT, "a model has joints or key frames, not both");
  if (frame_count == 0) return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: frame_count must be at least 1", mesh_id));
  if (s->keyFrames != 0 && frame_count != s->keyFrames)
    return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: {} key frames, but the model's other meshes have {}", mesh_id, frame_count, s->keyFrames));
  const std::size_t n = s->lastMeshVertices;
  std::string text = fmt::format("K:{}:{}\n", mesh_id, frame_count);
  for (std::size_t f = 0; f < frame_count; ++f)
    for (auto [token, data] : {std::pair{'P', positions}, std::pair{'N', normals}}) {
      if (!data) continue;
      for (std::size_t v = 0; v < n; ++v) {
        std::string line = fmt::format("{}:{}:{}", token, mesh_id, f);
        for (int c = 0; c < 3; ++c) {
          const float value = data[(f * n + v) * 3 + static_cast<std::size_t>(c)];
          if (!std::isfinite(value)) return error(DBC_ERROR_ARGUMENT, fmt::format("mesh {}: key frame {} vertex {} is not finite", mesh_id, f, v));
          appendFloat(line, value);
        }
        text += line;
        text += '\n';
      }
    }
  s->modelText += text;
  s->keyFrames = frame_count;
  s->lastMeshWithFrames = mesh_id;
  return DBC_OK;
}

int dbc_model_joint(dbc_session* s, int joint_id, const char* name, int parent, dbc_dual_quat bind, dbc_dual_quat inverse_bind) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_model_joint: session is NULL");
  if (!s->inModel) return error(DBC_ERROR_ORDER, "dbc_model_joint outside dbc_model_begin/end");
  if (joint_id != s->nextJoint) return error(DBC_ERROR_ARGUMENT, fmt::format("joint_id {} given; expected {} (joints in order)", joint_id, s->nextJoint));
  if (parent < -1 || parent >= joint_id) return error(DBC_ERROR_ARGUMENT, fmt::format("joint {}: parent {} must be -1 or an earlier joint", joint_id, parent));
  if (s->keyFrames > 0) return error(DBC_ERROR_ARGUMENT, "a model has joints or key frames, not both");
  if (!finite(bind) || !finite(inverse_bind)) return error(DBC_ERROR_ARGUMENT, fmt::format("joint {}: pose is not finite", joint_id));
  for (auto [token, q] : {std::pair{'b', bind}, std::pair{'x', inverse_bind}}) {
    std::string line = fmt::format("{}:{}:{}", token, joint_id, parent);
    appendDualQuat(line, q);
    s->modelText += line + ":" + escapeField(name ? name : "") + "\n";
  }
  ++s->nextJoint;
  return DBC_OK;
}

int dbc_model_end(dbc_session* s) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_model_end: session is NULL");
  if (!s->inModel) return error(DBC_ERROR_ORDER, "dbc_model_end without dbc_model_begin");
  s->inModel = false;
  const fs::path file = s->directory / kModelsFolder / fmt::format("{:05}.txt", s->modelFiles);
  if (auto ok = dynbench::writeFileAtomic(file, s->modelText); !ok) return error(DBC_ERROR_IO, ok.error().message);
  ++s->modelFiles;
  s->modelJoints[s->modelPath] = s->nextJoint;
  s->modelKeyFrames[s->modelPath] = s->keyFrames;
  s->modelText.clear();
  return DBC_OK;
}

uint64_t dbc_new_id(dbc_session* s) { return s ? s->nextId++ : 0; }

int dbc_frame_begin(dbc_session* s, uint64_t frame_number, double time_seconds) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_frame_begin: session is NULL");
  if (s->inFrame || s->inModel) return error(DBC_ERROR_ORDER, "dbc_frame_begin inside a frame or a model");
  if (!std::isfinite(time_seconds)) return error(DBC_ERROR_ARGUMENT, "frame time is not finite");
  if (s->anyFrame && frame_number <= s->lastFrame)
    return error(DBC_ERROR_ARGUMENT, fmt::format("frame number {} after {}: numbers must increase", frame_number, s->lastFrame));
  if (s->anyFrame && time_seconds < s->lastTime)
    return error(DBC_ERROR_ARGUMENT, fmt::format("frame time {} after {}: time must not go back", time_seconds, s->lastTime));
  s->inFrame = true;
  s->frameText = fmt::format("f:{}", frame_number);
  appendDouble(s->frameText, time_seconds);
  s->frameText += '\n';
  s->lastFrame = frame_number;
  s->lastTime = time_seconds;
  s->anyFrame = true;
  s->modelsThisFrame.clear();
  s->camerasThisFrame.clear();
  return DBC_OK;
}

int dbc_camera(dbc_session* s, uint64_t id, const float p[3], float pitch, float yaw, float roll) {
  if (!s || !p) return error(DBC_ERROR_ARGUMENT, "dbc_camera: NULL argument");
  if (int rc = s->requireFrame("dbc_camera"); rc != DBC_OK) return rc;
  if (!finite({p[0], p[1], p[2], pitch, yaw, roll})) return error(DBC_ERROR_ARGUMENT, fmt::format("camera {}: a value is not finite", id));
  if (int rc = s->claim(id, Kind::kCamera, ""); rc != DBC_OK) return rc;
  std::string line = fmt::format("t:{}", id);
  for (float v : {p[0], p[1], p[2], pitch, yaw, roll}) appendFloat(line, v);
  s->camerasThisFrame.insert(id);
  return s->writeRecord(line);
}

int dbc_camera_cut(dbc_session* s, uint64_t id, const char* reason) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_camera_cut: NULL session");
  if (int rc = s->requireFrame("dbc_camera_cut"); rc != DBC_OK) return rc;
  if (!s->camerasThisFrame.contains(id))
    return error(DBC_ERROR_ORDER, fmt::format("dbc_camera_cut: camera {} has no dbc_camera record earlier in this frame", id));
  const std::string text = reason && *reason ? reason : "cut";
  return s->writeRecord(fmt::format("c:{}:{}", id, escapeField(text)));
}

static int modelRecord(dbc_session* s, char token, Kind kind, uint64_t id, const char* model_path, const dbc_dual_quat& pose) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "NULL session");
  if (int rc = s->requireFrame(token == 'p' ? "dbc_static_model" : "dbc_model"); rc != DBC_OK) return rc;
  if (int rc = s->requireModel(model_path); rc != DBC_OK) return rc;
  if (!finite(pose)) return error(DBC_ERROR_ARGUMENT, fmt::format("capturable {}: pose is not finite", id));
  if (int rc = s->claim(id, kind, model_path); rc != DBC_OK) return rc;
  std::string line = fmt::format("{}:{}", token, id);
  appendDualQuat(line, pose);
  if (token == 'm') s->modelsThisFrame.insert(id);
  return s->writeRecord(line + ":" + escapeField(model_path));
}

int dbc_static_model(dbc_session* s, uint64_t id, const char* model_path, dbc_dual_quat pose) {
  if (s && s->capturables.contains(id)) return DBC_OK;  // static: the first record holds for good
  return modelRecord(s, 'p', Kind::kStaticModel, id, model_path, pose);
}

int dbc_model(dbc_session* s, uint64_t id, const char* model_path, dbc_dual_quat pose) {
  return modelRecord(s, 'm', Kind::kModel, id, model_path, pose);
}

int dbc_joints(dbc_session* s, uint64_t id, const char* model_path, size_t joint_count, const dbc_dual_quat* joints) {
  if (!s || (!joints && joint_count)) return error(DBC_ERROR_ARGUMENT, "dbc_joints: NULL argument");
  if (int rc = s->requireFrame("dbc_joints"); rc != DBC_OK) return rc;
  if (int rc = s->requireModel(model_path); rc != DBC_OK) return rc;
  const int expected = s->modelJoints.at(model_path);
  if (joint_count != static_cast<size_t>(expected))
    return error(DBC_ERROR_ARGUMENT, fmt::format("model '{}' has {} joints; {} given", model_path, expected, joint_count));
  if (!s->modelsThisFrame.contains(id))
    return error(DBC_ERROR_ORDER, fmt::format("capturable {}: record its model transform (dbc_model) before its joints", id));
  std::string line = fmt::format("j:{}:{}", id, joint_count);
  for (size_t k = 0; k < joint_count; ++k) {
    if (!finite(joints[k])) return error(DBC_ERROR_ARGUMENT, fmt::format("capturable {}: joint {} is not finite", id, k));
    appendDualQuat(line, joints[k]);
  }
  return s->writeRecord(line + ":" + escapeField(model_path));
}

int dbc_vertex_frames(dbc_session* s, uint64_t id, const char* model_path, uint32_t from, uint32_t to, float fraction) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_vertex_frames: NULL session");
  if (int rc = s->requireFrame("dbc_vertex_frames"); rc != DBC_OK) return rc;
  if (int rc = s->requireModel(model_path); rc != DBC_OK) return rc;
  const std::size_t frames = s->modelKeyFrames.at(model_path);
  if (frames == 0) return error(DBC_ERROR_ARGUMENT, fmt::format("model '{}' has no key frames (dbc_model_mesh_frames)", model_path));
  if (from >= frames || to >= frames)
    return error(DBC_ERROR_ARGUMENT, fmt::format("capturable {}: key frames {} and {} of model '{}', which has {}", id, from, to, model_path, frames));
  if (!(fraction >= 0.0f && fraction <= 1.0f)) return error(DBC_ERROR_ARGUMENT, fmt::format("capturable {}: fraction {} is not in [0, 1]", id, fraction));
  if (!s->modelsThisFrame.contains(id))
    return error(DBC_ERROR_ORDER, fmt::format("capturable {}: record its model transform (dbc_model) before its key frames", id));
  if (s->capturables.at(id).second != model_path)
    return error(DBC_ERROR_ARGUMENT, fmt::format("capturable {} is a '{}', not a '{}'", id, s->capturables.at(id).second, model_path));
  std::string line = fmt::format("v:{}:{}:{}", id, from, to);
  appendFloat(line, fraction);
  return s->writeRecord(line + ":" + escapeField(model_path));
}

int dbc_light(dbc_session* s, uint64_t id, const float p[3], const float rgb[3], float range, dbc_light_falloff falloff,
              dbc_light_type type, int dynamic, const char* model_type) {
  if (!s || !p || !rgb) return error(DBC_ERROR_ARGUMENT, "dbc_light: NULL argument");
  if (int rc = s->requireFrame("dbc_light"); rc != DBC_OK) return rc;
  if (!finite({p[0], p[1], p[2], rgb[0], rgb[1], rgb[2], range})) return error(DBC_ERROR_ARGUMENT, fmt::format("light {}: a value is not finite", id));
  if (range < 0) return error(DBC_ERROR_ARGUMENT, fmt::format("light {}: range must be 0 (none) or positive (got {})", id, range));
  if (falloff != DBC_FALLOFF_LINEAR && falloff != DBC_FALLOFF_QUADRATIC && falloff != DBC_FALLOFF_INVERSE_SQUARE &&
      falloff != DBC_FALLOFF_WINDOWED_INVERSE_SQUARE)
    return error(DBC_ERROR_ARGUMENT, fmt::format("light {}: unknown falloff {}", id, static_cast<int>(falloff)));
  if (type != DBC_LIGHT_POINT && type != DBC_LIGHT_SPOT && type != DBC_LIGHT_DIRECTIONAL)
    return error(DBC_ERROR_ARGUMENT, fmt::format("light {}: unknown type {}", id, static_cast<int>(type)));
  if (!dynamic && s->capturables.contains(id)) return DBC_OK;  // static: the first record holds for good
  const std::string kindText = model_type && *model_type ? model_type : "none";
  if (int rc = s->claim(id, Kind::kLight, ""); rc != DBC_OK) return rc;
  std::string line = fmt::format("l:{}", id);
  for (float v : {p[0], p[1], p[2], rgb[0], rgb[1], rgb[2], range}) appendFloat(line, v);
  static const char* typeNames[] = {"point", "spot", "directional"};
  const char* falloffName = !(range > 0)                        ? "none"
                            : falloff == DBC_FALLOFF_LINEAR         ? "linear"
                            : falloff == DBC_FALLOFF_INVERSE_SQUARE ? "inverse_square"
                            : falloff == DBC_FALLOFF_WINDOWED_INVERSE_SQUARE ? "windowed_inverse_square"
                                                                    : "quadratic";
  return s->writeRecord(line + fmt::format(":{}:{}:{}:{}", falloffName, typeNames[type], dynamic ? 1 : 0, escapeField(kindText)));
}

int dbc_frame_end(dbc_session* s) {
  if (!s) return error(DBC_ERROR_ARGUMENT, "dbc_frame_end: session is NULL");
  if (!s->inFrame) return error(DBC_ERROR_ORDER, "dbc_frame_end without dbc_frame_begin");
  s->frameText += fmt::format("e:{}\n", s->lastFrame);
  s->inFrame = false;
  ++s->frameCount;
  if (std::fwrite(s->frameText.data(), 1, s->frameText.size(), s->capture) != s->frameText.size() || std::fflush(s->capture) != 0)
    return error(DBC_ERROR_IO, "cannot write " + (s->directory / kCaptureFile).string() + ": " + std::strerror(errno));
  s->frameText.clear();
  return DBC_OK;
}

}  // extern "C"
