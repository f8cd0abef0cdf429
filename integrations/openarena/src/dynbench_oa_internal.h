/* What the files of dynbench's OpenArena adapter share:
 *   dynbench_oa.c         the adapter's state, identities and the hooks (dynbench_oa.h);
 *   dynbench_oa_assets.c  the game's file system, shader scripts and their textures, the mesh builder;
 *   dynbench_oa_bsp.c     the map: world surfaces, brush models and the map's lighting;
 *   dynbench_oa_md3.c     MD3 models and their key frames.
 * Everything here is hidden: the client game module exports only dynbench_oa.h's hooks, as when
 * this was one file of static functions. */
#ifndef DYNBENCH_OA_INTERNAL_H
#define DYNBENCH_OA_INTERNAL_H

#include "cg_local.h"
#include "../qcommon/qfiles.h"
#include "dynbench_oa.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <dynbench/capture.h>

#define MAX_HANDLES 4096
#define MAX_PENDING 2048
#define ID_TABLE_SIZE (1 << 16)
#define SHADER_TABLE_SIZE (1 << 14)
#define PATCH_LEVEL 8 /* each 3x3 Bezier sub-patch becomes 8 x 8 quads */
#define UNOWNED_SLOT (DYNBENCH_LOCAL_SLOT * 2 - 1) /* drawn outside an entity (effects) */
#define MAX_STATIC_LIGHTS 4096
#define MAX_MAP_SURFACE_LIGHTS 256
#define RESTART_AT 2000 /* ms of server time: the level restarts then, the client connected by then */

typedef struct {
  refEntity_t entity;
  int slot, serial, occurrence;
} pending_entity_t;

typedef struct {
  float origin[3], intensity, rgb[3];
  int slot, serial, occurrence, entity_type;
} pending_light_t;

typedef struct {
  int used;
  int slot, serial, model, skin, occurrence; /* model -1: a light */
  uint64_t id;
} identity_t;

typedef struct {
  char name[MAX_QPATH];
  char image[MAX_QPATH];
  float surface_light;   /* q3map_surfacelight */
  float light_rgb[3];    /* q3map_lightRGB, or white */
  int has_sun;
  float sun[6];          /* q3map_sun r g b intensity degrees elevation */
  int nodraw, sky, fog;
  int translucent; /* its first stage blends onto what is behind (effects, glass, decals) */
  int used;
} shader_info_t;

typedef struct {
  int active;
  dbc_session* session;
  char dir[1024];
  double seconds, warmup;
  char follow[32];
  int total_frames;
  int frame;
  int frame_ms, clock_base, clock_resets;
  int started;
  int start_time;
  int finished;
  int spectate_sent_at, follow_sent_at, next_sent_for_death;
  int restart_sent, restarted, connected_at;
  int record;       /* 0: play the same match without writing anything (the overhead benchmark) */
  char game_frames[1024]; /* ",60,120,": recorded frames whose own image the game keeps in game/ */
  int pending_game_frame; /* a recorded frame whose own image is read once its scene is drawn, or -1 */
  int window_start; /* wall-clock ms when recording started */
  int follow_target;
  uint64_t camera_id;
  int last_client, last_teleport, last_dead, have_last;
  float last_position[3];
  float camera_fov;
  int fov_change_reported; /* the note that the view's field of view changed was printed */
  int last_camera_width, last_camera_height;
  char map[MAX_QPATH];        /* "oa_dm1" */
  char world_path[MAX_QPATH]; /* "maps/oa_dm1" */
  char model_names[MAX_HANDLES][MAX_QPATH];
  char skin_names[MAX_HANDLES][MAX_QPATH];
  /* who draws */
  int owner_slot, owner_type;
  int owner_serial[DYNBENCH_LOCAL_SLOT * 2];
  int owner_signature[DYNBENCH_LOCAL_SLOT * 2];
  int owner_last_frame[DYNBENCH_LOCAL_SLOT * 2]; /* render pass the slot was last drawn in */
  int owner_models[DYNBENCH_LOCAL_SLOT * 2][8];
  int owner_model_count[DYNBENCH_LOCAL_SLOT * 2][8];
  int owner_lights[DYNBENCH_LOCAL_SLOT * 2];
  int pass;
  pending_entity_t entities[MAX_PENDING];
  int entity_count;
  pending_light_t lights[MAX_PENDING];
  int light_count;
  identity_t ids[ID_TABLE_SIZE];
  shader_info_t* shaders; /* hash table, SHADER_TABLE_SIZE */
  /* the map's surface lights, recorded in the first frame (lights are frame records) */
  float static_lights[MAX_STATIC_LIGHTS][8]; /* position, rgb, range, falloff */
  int static_light_count;
  /* the map's lights from dynbench (DYNBENCH_CAPTURE_MAP_LIGHTS, src/maplight/fit.h) */
  int have_map_lights;
  int map_sun;
  float map_sun_towards[3], map_sun_rgb[3];
  int map_surface_count;
  char map_surface_shader[MAX_MAP_SURFACE_LIGHTS][MAX_QPATH];
  float map_surface_emission[MAX_MAP_SURFACE_LIGHTS][3];
} dynbench_oa_state_t;

typedef struct {
  float* positions; float* normals; float* uvs; uint32_t* indices;
  size_t vertices, vertex_capacity, triangles, triangle_capacity;
} mesh_builder_t;

/* Inline, as in the one-file adapter: the game is built with -ffast-math, under which a call
 * instead of inlined code rounds differently, and the captures stay byte-identical to it. */
static inline void to_capture(const float in[3], float out[3]) {
  const float x = in[0], y = in[1], z = in[2];
  out[0] = -y;
  out[1] = z;
  out[2] = -x;
}

static inline void mesh_reserve(mesh_builder_t* m, size_t vertices, size_t triangles) {
  if (m->vertices + vertices > m->vertex_capacity) {
    m->vertex_capacity = (m->vertices + vertices) * 2;
    m->positions = realloc(m->positions, m->vertex_capacity * 3 * sizeof(float));
    m->normals = realloc(m->normals, m->vertex_capacity * 3 * sizeof(float));
    m->uvs = realloc(m->uvs, m->vertex_capacity * 2 * sizeof(float));
  }
  if (m->triangles + triangles > m->triangle_capacity) {
    m->triangle_capacity = (m->triangles + triangles) * 2;
    m->indices = realloc(m->indices, m->triangle_capacity * 3 * sizeof(uint32_t));
  }
}

static inline void mesh_vertex(mesh_builder_t* m, const float xyz[3], const float normal[3], const float st[2]) {
  to_capture(xyz, &m->positions[m->vertices * 3]);
  float n[3] = {normal[0], normal[1], normal[2]};
  const float length = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (length > 1e-6f) { n[0] /= length; n[1] /= length; n[2] /= length; } else { n[0] = 0; n[1] = 0; n[2] = 1; }
  to_capture(n, &m->normals[m->vertices * 3]);
  m->uvs[m->vertices * 2 + 0] = st[0];
  m->uvs[m->vertices * 2 + 1] = st[1];
  ++m->vertices;
}

/* id Tech 3's clockwise front faces become glTF's counter-clockwise ones. */
static inline void mesh_triangle(mesh_builder_t* m, uint32_t a, uint32_t b, uint32_t c) {
  m->indices[m->triangles * 3 + 0] = a;
  m->indices[m->triangles * 3 + 1] = c;
  m->indices[m->triangles * 3 + 2] = b;
  ++m->triangles;
}

#pragma GCC visibility push(hidden)

extern dynbench_oa_state_t g_db;

/* dynbench_oa.c */
void db_fail(const char* what); /* reports the SDK's last error, stops capturing and quits the game */

/* dynbench_oa_assets.c */
int make_directories(const char* path);
char* read_game_file(const char* path, int* length);
shader_info_t* shader_slot(const char* name, int create);
void load_shader_scripts(void);
const char* shader_texture(const char* shader_name);
int record_mesh(int mesh_id, const char* name, const char* texture, const mesh_builder_t* m, const float* emission);
void mesh_free(mesh_builder_t* m);

/* dynbench_oa_bsp.c */
int load_bsp(void);
void free_bsp(void);
int record_bsp_model(int index, const char* model_path);
void record_map_lighting(void);

/* dynbench_oa_md3.c */
int record_md3(const char* file, const char* skin, const char* model_path);

#pragma GCC visibility pop

#endif
