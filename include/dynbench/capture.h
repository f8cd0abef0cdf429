/* dynbench capture SDK: record what an interactive program shows, frame by frame, into a capture
 * directory that `dynbench convert` turns into a glTF 2.0 benchmark dataset.
 * The format is specified in docs/capture-format.md (thesis Tables 5.1 and 5.2).
 *
 * A plain C API so that any engine can call it. Link with dynbench_capture.
 *
 *   dbc_session* s;
 *   if (dbc_open("capture/", "my engine 1.0", &s) != DBC_OK) puts(dbc_last_error());
 *   dbc_set_camera_settings(s, 16.0f / 9, 60.0f, 0.1f, 1000.0f);
 *   dbc_model_begin(s, "models/crate"); dbc_model_mesh(s, &mesh); dbc_model_end(s);
 *   uint64_t crate = dbc_new_id(s);
 *   for each frame:
 *     dbc_frame_begin(s, frame, seconds);
 *     dbc_camera(s, camera_id, position, pitch, yaw, roll);
 *     dbc_model(s, crate, "models/crate", pose);
 *     dbc_frame_end(s);          // the frame is on disk now: a crash later cannot lose it
 *   dbc_close(s);
 *
 * Every function returns DBC_OK (0) or an error code; dbc_last_error() then says what went wrong
 * (per thread). Nothing is written for a call that fails. Not thread-safe: one thread per session.
 */
#ifndef DYNBENCH_CAPTURE_H
#define DYNBENCH_CAPTURE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct dbc_session dbc_session;

enum dbc_status {
  DBC_OK = 0,
  DBC_ERROR_IO = 1,       /* a file could not be created or written */
  DBC_ERROR_ARGUMENT = 2, /* NaN, a null pointer, a count out of range, an unknown model path */
  DBC_ERROR_ORDER = 3     /* a call out of sequence (a record outside a frame, a model inside one) */
};

/* A rigid transform as a unit dual quaternion: real part r = rotation (x, y, z, w), dual part
 * d = 1/2 (t, 0) r for the translation t (docs/capture-format.md). */
typedef struct dbc_dual_quat {
  float rx, ry, rz, rw;
  float dx, dy, dz, dw;
} dbc_dual_quat;

typedef enum dbc_light_type { DBC_LIGHT_POINT = 0, DBC_LIGHT_SPOT = 1, DBC_LIGHT_DIRECTIONAL = 2 } dbc_light_type;
/* How a light with a range fades, as the engine's light does: colour x (1 - d/range) (LINEAR: Cube
 * 2's lightmaps) or colour x (1 - (d/range)^2) (QUADRATIC: Cube 2's dynamic lights), nothing beyond
 * the range; or colour x (range/d)^2 (INVERSE_SQUARE: a physical point light, id Tech 3's map
 * lights as q3map2 bakes them), where the range is the distance at which it gives `rgb`, and no end;
 * or colour x (range/d)^2 x max(0, 1 - (d/range)^4) (WINDOWED_INVERSE_SQUARE: KHR_lights_punctual's
 * point light with a range, which ends there; id Tech 3's map lights ended at q3map2's envelope),
 * `rgb` being the inverse square's light at the range before the window. */
typedef enum dbc_light_falloff {
  DBC_FALLOFF_LINEAR = 0,
  DBC_FALLOFF_QUADRATIC = 1,
  DBC_FALLOFF_INVERSE_SQUARE = 2,
  DBC_FALLOFF_WINDOWED_INVERSE_SQUARE = 3
} dbc_light_falloff;

/* One mesh of a model. Arrays hold vertex_count elements of the given width; normals, uvs,
 * joints and weights may be NULL. joints/weights: 4 per vertex, unused influences have weight 0
 * (at least one per vertex must be non-zero when given). */
typedef struct dbc_mesh {
  int mesh_id;              /* 0, 1, 2, ... in the order meshes are given */
  const char* name;         /* may be NULL */
  const char* texture;      /* base colour map, relative to the data root; may be NULL */
  const char* mask_texture; /* mask map; may be NULL */
  size_t vertex_count;
  const float* positions;   /* 3 per vertex */
  const float* normals;     /* 3 per vertex */
  const float* uvs;         /* 2 per vertex */
  const uint16_t* joints;   /* 4 per vertex */
  const float* weights;     /* 4 per vertex */
  size_t triangle_count;
  const uint32_t* indices;  /* 3 per triangle */
  /* The surface's material beyond its maps (ModelMesh version 3); NULL for the defaults. */
  const float* base_color;        /* 4: linear RGBA multiplying the texture map (default 1, 1, 1, 1) */
  const float* metallic_roughness; /* 2: metallic, roughness in [0, 1] (default: from the mask map, or 0 and 0.8) */
  const float* emission;          /* 3: light the surface gives off, in the light colours' units (1: as bright
                                     as a white surface under the engine's full light); default none */
  const char* emission_texture;   /* emission map multiplying `emission`, relative to the data root */
  int emission_texture_mean_one;  /* 1: `emission` is the surface's mean emission and the map only shapes it
                                     (the converter scales the map to a mean of 1: record m, not E) */
  const float* colors;            /* 4 per vertex: linear RGBA multiplying base_color; an alpha below 1 (here
                                     or in base_color) becomes glTF's alphaMode BLEND */
} dbc_mesh;

/* Session. dbc_open creates the directory (and models/) and writes the version line. */
int dbc_open(const char* directory, const char* source_name, dbc_session** session);
/* Writes the closing record and frees the session (also on error). */
int dbc_close(dbc_session* session);
/* What the last failing call on this thread said. */
const char* dbc_last_error(void);

/* Capture-wide settings (before or between frames; the camera settings once, before the first frame). */
int dbc_set_data_root(dbc_session* session, const char* path);
int dbc_set_metres_per_unit(dbc_session* session, float metres);
int dbc_set_map(dbc_session* session, const char* map_name, const float offset[3]);
int dbc_set_camera_settings(dbc_session* session, float aspect, float yfov_degrees, float znear, float zfar);
/* The map's own lighting, in the light colours' units (1: the engine's full light, as a light of
 * colour 1 gives a surface beside it): sun_direction points towards the sun (need not be unit;
 * sun_rgb all 0 when the map has no sun), ambient_rgb the light every surface gets at least, and
 * sky_rgb what a surface open to the whole sky gets (0 when the engine has no sky light). The
 * converter calibrates the dataset's sky against the lights with it (docs/dataset.md). */
int dbc_set_lighting(dbc_session* session, const float sun_direction[3], const float sun_rgb[3], const float ambient_rgb[3],
                     const float sky_rgb[3]);

/* Models (outside frames). A model is recorded once; dbc_has_model tells whether it already is. */
int dbc_has_model(const dbc_session* session, const char* model_path);
int dbc_model_begin(dbc_session* session, const char* model_path);
int dbc_model_mesh(dbc_session* session, const dbc_mesh* mesh);
/* Vertex animation (key-framed meshes such as id Tech 3's MD3): the positions of every vertex of
 * mesh `mesh_id` at each of frame_count key frames, key frame after key frame (3 x vertex_count
 * floats each), and their normals the same way (may be NULL). Right after that mesh's
 * dbc_model_mesh; every vertex-animated mesh of a model has the same frame_count. A model may not
 * have both joints and key frames. */
int dbc_model_mesh_frames(dbc_session* session, int mesh_id, size_t frame_count, const float* positions, const float* normals);
/* Joints in order 0..J-1, parents first (parent -1 for a root). */
int dbc_model_joint(dbc_session* session, int joint_id, const char* name, int parent, dbc_dual_quat bind_pose,
                    dbc_dual_quat inverse_bind_pose);
int dbc_model_end(dbc_session* session);

/* A fresh capturable id (running, never reused). */
uint64_t dbc_new_id(dbc_session* session);

/* Frames. */
int dbc_frame_begin(dbc_session* session, uint64_t frame_number, double time_seconds);
int dbc_camera(dbc_session* session, uint64_t id, const float position[3], float pitch_degrees, float yaw_degrees,
               float roll_degrees);
/* The camera's transform this frame does not continue from its previous one (a respawn, a switch
 * to another player, a teleporter): temporal methods reset their history here. After the camera's
 * dbc_camera call in the same frame. reason: free text such as "respawn", "switch", "teleport". */
int dbc_camera_cut(dbc_session* session, uint64_t camera_id, const char* reason);
int dbc_static_model(dbc_session* session, uint64_t id, const char* model_path, dbc_dual_quat pose);
int dbc_model(dbc_session* session, uint64_t id, const char* model_path, dbc_dual_quat pose);
int dbc_joints(dbc_session* session, uint64_t id, const char* model_path, size_t joint_count,
               const dbc_dual_quat* joints);
/* The key-frame pose of a vertex-animated model this frame: every vertex at (1 - fraction) x key
 * frame `from` + fraction x key frame `to` (MD3's interpolation), fraction in [0, 1]. After the
 * capturable's dbc_model in the same frame. */
int dbc_vertex_frames(dbc_session* session, uint64_t id, const char* model_path, uint32_t from, uint32_t to, float fraction);
/* A light. rgb: its colour as the engine has it (1: the engine's full light); range: the distance
 * (capture units) at which the engine's light falls to nothing (its radius), with `falloff` on
 * the way; 0 when it has none: the engine does not attenuate it at all (falloff is ignored; the
 * converter gives a static one the engine's irradiance at the map's centre, docs/dataset.md). */
int dbc_light(dbc_session* session, uint64_t id, const float position[3], const float rgb[3], float range,
              dbc_light_falloff falloff, dbc_light_type type, int dynamic, const char* model_type);
/* Writes the end-of-frame record and flushes: the frame is complete on disk. */
int dbc_frame_end(dbc_session* session);

#ifdef __cplusplus
}
#endif

#endif /* DYNBENCH_CAPTURE_H */
