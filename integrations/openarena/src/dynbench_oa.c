/* dynbench capture adapter for OpenArena (id Tech 3 game code, ioquake3 engine), built into the
 * client game module (cgame) by integrations/openarena/build.sh and linked with the *installed*
 * capture SDK (pkg-config dynbench-capture).
 *
 * What it records, all from the game's own render calls (the hooks in dynbench_oa.h):
 *   - the world: the BSP's drawn surfaces (planar faces, triangle soups, Bezier patches
 *     tessellated here) as one static model with a mesh per shader; brush entities (doors, lifts)
 *     as their own models, moved as the game moves them;
 *   - every drawn model entity (players as their three tagged MD3 parts, weapons, projectiles,
 *     items, gibs): its transform and its MD3 key frames (frame, oldframe, backlerp: `v` records),
 *     the MD3's every key frame once, as vertex animation (capture format 3);
 *   - dynamic lights (muzzle flashes, rockets, explosions) and the map's lighting (its sky
 *     shader's sun, its light grid's mean ambient, its light-emitting shaders' surfaces as lights);
 *   - the camera (the view the game renders: the followed bot's eyes) and its cuts.
 * Coordinates: id Tech 3 is Z-up, X forward at yaw 0, Y to the left. The capture format is Y-up
 * and right-handed; the adapter uses (x, y, z) -> (-y, z, -x), a rotation, under which the game's
 * forward (+x) is the camera's -Z and its left (+y) is -X: what the player saw is kept.
 * Triangles: id Tech 3 draws clockwise faces as front faces; glTF's are counter-clockwise, so each
 * triangle's winding is reversed.
 */
#include "cg_local.h"
#include "../qcommon/qfiles.h"
#include "dynbench_oa.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <GL/gl.h>

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


static struct {
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
} g_db;

/* ---------------------------------------------------------------------------------------------- */
/* small helpers */

static void db_fail(const char* what) {
  fprintf(stderr, "dynbench-capture: error: %s: %s\n", what, dbc_last_error());
  fflush(stderr);
  g_db.active = 0;
  trap_SendConsoleCommand("quit\n");
}

static void to_capture(const float in[3], float out[3]) {
  const float x = in[0], y = in[1], z = in[2];
  out[0] = -y;
  out[1] = z;
  out[2] = -x;
}

static uint32_t hash_string(const char* s) {
  uint32_t h = 2166136261u;
  for (; *s; ++s) h = (h ^ (uint32_t)(unsigned char)tolower((unsigned char)*s)) * 16777619u;
  return h;
}

static int make_directories(const char* path) { /* mkdir -p of path's parent directories */
  char buffer[1400];
  Q_strncpyz(buffer, path, sizeof(buffer));
  for (char* p = buffer + 1; *p; ++p) {
    if (*p != '/') continue;
    *p = 0;
    if (mkdir(buffer, 0755) != 0 && errno != EEXIST) return 0;
    *p = '/';
  }
  return 1;
}

/* The whole of a file in the game's file system (pk3 archives included), NUL-terminated; NULL if
 * there is none. Free with free(). */
static char* read_game_file(const char* path, int* length) {
  fileHandle_t f;
  const int size = trap_FS_FOpenFile(path, &f, FS_READ);
  if (size <= 0 || !f) {
    if (f) trap_FS_FCloseFile(f);
    return NULL;
  }
  char* data = malloc((size_t)size + 1);
  trap_FS_Read(data, size, f);
  trap_FS_FCloseFile(f);
  data[size] = 0;
  if (length) *length = size;
  return data;
}

static int game_file_exists(const char* path) {
  fileHandle_t f;
  const int size = trap_FS_FOpenFile(path, &f, FS_READ);
  if (f) trap_FS_FCloseFile(f);
  return size > 0;
}

/* ---------------------------------------------------------------------------------------------- */
/* shaders: the scripts' first image stage and light parameters; textures copied out of the paks */

static shader_info_t* shader_slot(const char* name, int create) {
  uint32_t h = hash_string(name) & (SHADER_TABLE_SIZE - 1);
  for (int probe = 0; probe < SHADER_TABLE_SIZE; ++probe, h = (h + 1) & (SHADER_TABLE_SIZE - 1)) {
    shader_info_t* s = &g_db.shaders[h];
    if (!s->used) {
      if (!create) return NULL;
      memset(s, 0, sizeof(*s));
      s->used = 1;
      Q_strncpyz(s->name, name, sizeof(s->name));
      s->light_rgb[0] = s->light_rgb[1] = s->light_rgb[2] = 1.0f;
      return s;
    }
    if (!Q_stricmp(s->name, name)) return s;
  }
  return NULL;
}

/* A shader script: shader name, then a block of keyword lines and stage blocks. A keyword's
 * arguments are the tokens on its line; braces may share a line with them ("{ map x.tga }"), so
 * they are counted wherever they appear. */
static void parse_shader_script(char* text) {
  char* p = text;
  for (;;) {
    char* token = COM_ParseExt(&p, qtrue);
    if (!token[0]) return;
    shader_info_t* shader = shader_slot(token, 1);
    token = COM_ParseExt(&p, qtrue);
    if (strcmp(token, "{") || !shader) return; /* not a shader script the game could read either */
    const int defined_before = shader->image[0] != 0 || shader->surface_light > 0; /* the first definition wins, as in the renderer */
    int depth = 1, stage = 0;
    while (depth > 0) {
      token = COM_ParseExt(&p, qtrue);
      if (!token[0]) return;
      if (!strcmp(token, "{")) { ++depth; ++stage; continue; }
      if (!strcmp(token, "}")) { --depth; continue; }
      char keyword[MAX_QPATH], args[8][MAX_QPATH];
      int count = 0;
      Q_strncpyz(keyword, token, sizeof(keyword));
      for (;;) { /* the rest of the line */
        token = COM_ParseExt(&p, qfalse);
        if (!token[0]) break;
        if (!strcmp(token, "{")) { ++depth; ++stage; break; }
        if (!strcmp(token, "}")) { --depth; break; }
        if (count < 8) Q_strncpyz(args[count++], token, MAX_QPATH);
      }
      if (defined_before) continue;
      const int in_stage = depth == 2 || (depth == 1 && !strcmp(token, "}")); /* a stage closed on this line */
      if (in_stage) {
        if (stage == 1 && !Q_stricmp(keyword, "blendfunc")) {
          /* id Tech 3 draws the first stage over the frame buffer with this blend: anything but
           * (GL_ONE, GL_ZERO) shows what is behind it, which a path tracer of opaque surfaces
           * cannot, so such surfaces are left out rather than drawn as solid (the health spheres,
           * muzzle flashes, lightning, decals) */
          shader->translucent = count < 2 || Q_stricmp(args[0], "gl_one") || Q_stricmp(args[1], "gl_zero");
        } else if ((!Q_stricmp(keyword, "map") || !Q_stricmp(keyword, "clampmap")) && !shader->image[0] && count >= 1) {
          if (args[0][0] != '$') Q_strncpyz(shader->image, args[0], sizeof(shader->image));
        } else if (!Q_stricmp(keyword, "animmap") && !shader->image[0] && count >= 2) {
          Q_strncpyz(shader->image, args[1], sizeof(shader->image));
        }
      } else if (depth == 1 || depth == 0) {
        if (!Q_stricmp(keyword, "q3map_surfacelight") && count >= 1) {
          shader->surface_light = atof(args[0]);
        } else if (!Q_stricmp(keyword, "q3map_lightrgb") && count >= 3) {
          for (int i = 0; i < 3; ++i) shader->light_rgb[i] = atof(args[i]);
        } else if ((!Q_stricmp(keyword, "q3map_sun") || !Q_stricmp(keyword, "q3map_sunext")) && count >= 6) {
          for (int i = 0; i < 6; ++i) shader->sun[i] = atof(args[i]);
          shader->has_sun = 1;
        } else if (!Q_stricmp(keyword, "surfaceparm") && count >= 1) {
          if (!Q_stricmp(args[0], "nodraw")) shader->nodraw = 1;
          if (!Q_stricmp(args[0], "sky")) shader->sky = 1;
          if (!Q_stricmp(args[0], "fog")) shader->fog = 1;
        }
      }
    }
  }
}

/* The shader scripts the game module listed (qagame has the file list the client game lacks). */
static void load_shader_scripts(void) {
  g_db.shaders = calloc(SHADER_TABLE_SIZE, sizeof(shader_info_t));
  char* list = read_game_file("dynbench-shader-scripts.txt", NULL);
  if (!list) {
    fprintf(stderr, "dynbench-capture: warning: no shader script list from the game module; textures from shader names only\n");
    return;
  }
  int scripts = 0;
  for (char* line = strtok(list, "\n"); line; line = strtok(NULL, "\n")) {
    char path[MAX_QPATH * 2];
    Com_sprintf(path, sizeof(path), "scripts/%s", line);
    char* text = read_game_file(path, NULL);
    if (!text) continue;
    parse_shader_script(text);
    free(text);
    ++scripts;
  }
  free(list);
  fprintf(stderr, "dynbench-capture: %d shader scripts read\n", scripts);
}

/* The image file the renderer would load for `name` (it tries .tga, then .jpg, then .png,
 * whatever the name's extension), as a path in the game's file system, or "" when none exists. */
static void find_image(const char* name, char out[MAX_QPATH]) {
  static const char* extensions[] = {".tga", ".jpg", ".png", ".jpeg"};
  char base[MAX_QPATH];
  out[0] = 0;
  Q_strncpyz(base, name, sizeof(base));
  for (char* c = base; *c; ++c)
    if (*c == '\\') *c = '/'; /* some MD3s name their shaders with Windows separators; the game's file system takes both */
  char* dot = strrchr(base, '.');
  char* slash = strrchr(base, '/');
  if (dot && (!slash || dot > slash)) *dot = 0;
  for (int i = 0; i < 4; ++i) {
    char candidate[MAX_QPATH];
    Com_sprintf(candidate, sizeof(candidate), "%s%s", base, extensions[i]);
    if (game_file_exists(candidate)) {
      Q_strncpyz(out, candidate, MAX_QPATH);
      return;
    }
  }
}

/* The texture of a shader, copied out of the paks under the capture's data root (data/), as the
 * path the ModelMesh file names; NULL for none. */
static const char* shader_texture(const char* shader_name) {
  static char result[MAX_QPATH];
  shader_info_t* shader = shader_slot(shader_name, 1);
  if (!shader) return NULL;
  if (shader->used == 2) return shader->image[0] ? shader->image : NULL; /* resolved before */
  char file[MAX_QPATH];
  find_image(shader->image[0] ? shader->image : shader_name, file);
  if (!file[0] && shader->image[0]) find_image(shader_name, file);
  shader->used = 2;
  Q_strncpyz(shader->image, file, sizeof(shader->image));
  if (!file[0]) return NULL;
  char target[1400];
  Com_sprintf(target, sizeof(target), "%s/data/%s", g_db.dir, file);
  struct stat st;
  if (stat(target, &st) != 0) {
    int length = 0;
    char* data = read_game_file(file, &length);
    if (!data) return NULL;
    char temporary[1500];
    Com_sprintf(temporary, sizeof(temporary), "%s.part", target);
    FILE* out = make_directories(target) ? fopen(temporary, "wb") : NULL;
    const int ok = out && fwrite(data, 1, (size_t)length, out) == (size_t)length;
    if (out) fclose(out);
    free(data);
    if (!ok || rename(temporary, target) != 0) {
      fprintf(stderr, "dynbench-capture: warning: cannot write %s\n", target);
      return NULL;
    }
  }
  Q_strncpyz(result, file, sizeof(result));
  return result;
}

/* ---------------------------------------------------------------------------------------------- */
/* growing arrays for meshes */

typedef struct {
  float* positions; float* normals; float* uvs; uint32_t* indices;
  size_t vertices, vertex_capacity, triangles, triangle_capacity;
} mesh_builder_t;

static void mesh_reserve(mesh_builder_t* m, size_t vertices, size_t triangles) {
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

static void mesh_vertex(mesh_builder_t* m, const float xyz[3], const float normal[3], const float st[2]) {
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
static void mesh_triangle(mesh_builder_t* m, uint32_t a, uint32_t b, uint32_t c) {
  m->indices[m->triangles * 3 + 0] = a;
  m->indices[m->triangles * 3 + 1] = c;
  m->indices[m->triangles * 3 + 2] = b;
  ++m->triangles;
}

/* Gives the SDK a built mesh of the model being recorded; 0 when it refuses. */
static int record_mesh(int mesh_id, const char* name, const char* texture, const mesh_builder_t* m, const float* emission) {
  dbc_mesh mesh;
  memset(&mesh, 0, sizeof(mesh));
  mesh.emission = emission;
  /* the game shows a light-emitting shader's texture; q3map2 spreads its light evenly, so the
   * texture only shapes the emission, whose mean stays what dynbench's lights give (record m) */
  mesh.emission_texture = emission ? texture : NULL;
  mesh.emission_texture_mean_one = emission != NULL;
  mesh.mesh_id = mesh_id;
  mesh.name = name;
  mesh.texture = texture;
  mesh.vertex_count = m->vertices;
  mesh.positions = m->positions;
  mesh.normals = m->normals;
  mesh.uvs = m->uvs;
  mesh.triangle_count = m->triangles;
  mesh.indices = m->indices;
  return dbc_model_mesh(g_db.session, &mesh) == DBC_OK;
}

static void mesh_free(mesh_builder_t* m) {
  free(m->positions); free(m->normals); free(m->uvs); free(m->indices);
  memset(m, 0, sizeof(*m));
}

/* ---------------------------------------------------------------------------------------------- */
/* the BSP: world surfaces, brush models, lights */

typedef struct {
  char* data;
  int length;
  const dshader_t* shaders; int shader_count;
  const dmodel_t* models; int model_count;
  const drawVert_t* vertices; int vertex_count;
  const int* indices; int index_count;
  const dsurface_t* surfaces; int surface_count;
  const unsigned char* grid; int grid_bytes;
} bsp_t;

static bsp_t g_bsp;

static int load_bsp(void) {
  char path[MAX_QPATH];
  Com_sprintf(path, sizeof(path), "maps/%s.bsp", g_db.map);
  g_bsp.data = read_game_file(path, &g_bsp.length);
  if (!g_bsp.data || g_bsp.length < (int)sizeof(dheader_t)) return 0;
  const dheader_t* header = (const dheader_t*)g_bsp.data;
  if (header->ident != BSP_IDENT || header->version != BSP_VERSION) return 0;
#define LUMP(index, type, pointer, count) \
  pointer = (const type*)(g_bsp.data + header->lumps[index].fileofs); \
  count = header->lumps[index].filelen / (int)sizeof(type)
  LUMP(LUMP_SHADERS, dshader_t, g_bsp.shaders, g_bsp.shader_count);
  LUMP(LUMP_MODELS, dmodel_t, g_bsp.models, g_bsp.model_count);
  LUMP(LUMP_DRAWVERTS, drawVert_t, g_bsp.vertices, g_bsp.vertex_count);
  LUMP(LUMP_DRAWINDEXES, int, g_bsp.indices, g_bsp.index_count);
  LUMP(LUMP_SURFACES, dsurface_t, g_bsp.surfaces, g_bsp.surface_count);
  LUMP(LUMP_LIGHTGRID, unsigned char, g_bsp.grid, g_bsp.grid_bytes);
#undef LUMP
  return 1;
}

/* The emission dynbench gives a shader's surfaces (a q3map_surfacelight), or NULL. */
static const float* map_surface_emission(const char* shader) {
  for (int i = 0; i < g_db.map_surface_count; ++i)
    if (!Q_stricmp(g_db.map_surface_shader[i], shader)) return g_db.map_surface_emission[i];
  return NULL;
}

static int surface_drawn(const dsurface_t* surface) {
  if (surface->shaderNum < 0 || surface->shaderNum >= g_bsp.shader_count) return 0;
  if (surface->surfaceType == MST_FLARE || surface->surfaceType == MST_BAD) return 0;
  const dshader_t* shader = &g_bsp.shaders[surface->shaderNum];
  /* a light-emitting surface is drawn, opaque and emissive, even where the game blends it (lava,
   * flames): its light would be missing otherwise */
  if (!(shader->surfaceFlags & (SURF_NODRAW | SURF_SKY)) && map_surface_emission(shader->shader)) return 1;
  if (shader->surfaceFlags & (SURF_NODRAW | SURF_SKY)) return 0;
  if (shader->contentFlags & CONTENTS_FOG) return 0;
  const shader_info_t* info = shader_slot(shader->shader, 0);
  if (info && (info->nodraw || info->sky || info->fog || info->translucent)) return 0;
  return 1;
}

/* A biquadratic Bezier patch's point from its 3x3 control points (id Tech 3's curved surfaces). */
static void bezier(const drawVert_t* control[9], float u, float v, float xyz[3], float normal[3], float st[2]) {
  const float bu[3] = {(1 - u) * (1 - u), 2 * u * (1 - u), u * u};
  const float bv[3] = {(1 - v) * (1 - v), 2 * v * (1 - v), v * v};
  memset(xyz, 0, 3 * sizeof(float)); memset(normal, 0, 3 * sizeof(float)); memset(st, 0, 2 * sizeof(float));
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const float w = bu[i] * bv[j];
      const drawVert_t* c = control[j * 3 + i];
      for (int k = 0; k < 3; ++k) { xyz[k] += w * c->xyz[k]; normal[k] += w * c->normal[k]; }
      st[0] += w * c->st[0]; st[1] += w * c->st[1];
    }
}

static void add_surface(mesh_builder_t* m, const dsurface_t* s) {
  if (s->surfaceType == MST_PATCH) {
    const int w = s->patchWidth, h = s->patchHeight;
    if (w < 3 || h < 3 || !(w & 1) || !(h & 1)) return;
    for (int py = 0; py + 2 < h; py += 2)
      for (int px = 0; px + 2 < w; px += 2) {
        const drawVert_t* control[9];
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i) control[j * 3 + i] = &g_bsp.vertices[s->firstVert + (py + j) * w + (px + i)];
        const uint32_t base = (uint32_t)m->vertices;
        mesh_reserve(m, (PATCH_LEVEL + 1) * (PATCH_LEVEL + 1), 2 * PATCH_LEVEL * PATCH_LEVEL);
        for (int j = 0; j <= PATCH_LEVEL; ++j)
          for (int i = 0; i <= PATCH_LEVEL; ++i) {
            float xyz[3], normal[3], st[2];
            bezier(control, (float)i / PATCH_LEVEL, (float)j / PATCH_LEVEL, xyz, normal, st);
            mesh_vertex(m, xyz, normal, st);
          }
        /* rows j and columns i as the control grid's. Unlike planar faces, a patch's control
         * normals point along cross(P(i+1,j) - P(i,j), P(i,j+1) - P(i,j)) (all but 15 of 28,000
         * grid cells of OpenArena's 25 maps with patches), so the counter-clockwise triangles
         * (a, b, c) and (b, d, c) face the normals: mesh_triangle's turn is undone here */
        for (int j = 0; j < PATCH_LEVEL; ++j)
          for (int i = 0; i < PATCH_LEVEL; ++i) {
            const uint32_t a = base + j * (PATCH_LEVEL + 1) + i, b = a + 1, c = a + PATCH_LEVEL + 1, d = c + 1;
            mesh_triangle(m, a, c, b);
            mesh_triangle(m, b, c, d);
          }
      }
    return;
  }
  /* planar faces and triangle soups: indices relative to the surface's first vertex */
  if (s->firstVert < 0 || s->firstVert + s->numVerts > g_bsp.vertex_count) return;
  if (s->firstIndex < 0 || s->firstIndex + s->numIndexes > g_bsp.index_count) return;
  const uint32_t base = (uint32_t)m->vertices;
  mesh_reserve(m, (size_t)s->numVerts, (size_t)s->numIndexes / 3);
  for (int i = 0; i < s->numVerts; ++i) {
    const drawVert_t* v = &g_bsp.vertices[s->firstVert + i];
    mesh_vertex(m, v->xyz, v->normal, v->st);
  }
  for (int i = 0; i + 2 < s->numIndexes; i += 3) {
    const int* t = &g_bsp.indices[s->firstIndex + i];
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= s->numVerts || t[1] >= s->numVerts || t[2] >= s->numVerts) continue;
    mesh_triangle(m, base + (uint32_t)t[0], base + (uint32_t)t[1], base + (uint32_t)t[2]);
  }
}

/* BSP model `index` (0: the world, 1...: brush entities) as a capture model with a mesh per shader. */
static int record_bsp_model(int index, const char* model_path) {
  if (index < 0 || index >= g_bsp.model_count) return 0;
  const dmodel_t* model = &g_bsp.models[index];
  if (dbc_model_begin(g_db.session, model_path) != DBC_OK) { db_fail("model"); return 0; }
  int mesh_id = 0;
  char* done = calloc((size_t)g_bsp.shader_count, 1);
  for (int first = model->firstSurface; first < model->firstSurface + model->numSurfaces; ++first) {
    const dsurface_t* s = &g_bsp.surfaces[first];
    if (!surface_drawn(s) || done[s->shaderNum]) continue;
    done[s->shaderNum] = 1;
    mesh_builder_t m;
    memset(&m, 0, sizeof(m));
    for (int k = first; k < model->firstSurface + model->numSurfaces; ++k)
      if (g_bsp.surfaces[k].shaderNum == s->shaderNum && surface_drawn(&g_bsp.surfaces[k])) add_surface(&m, &g_bsp.surfaces[k]);
    if (m.triangles > 0) {
      const char* shader = g_bsp.shaders[s->shaderNum].shader;
      if (!record_mesh(mesh_id, shader, shader_texture(shader), &m, map_surface_emission(shader))) { mesh_free(&m); free(done); db_fail("world mesh"); return 0; }
      ++mesh_id;
    }
    mesh_free(&m);
  }
  free(done);
  if (dbc_model_end(g_db.session) != DBC_OK) { db_fail("model end"); return 0; }
  return 1;
}

/* The map's own lighting. id Tech 3 bakes it into light maps; the capture gets what made them:
 * the sky shader's sun (q3map_sun), the light grid's mean ambient light, and a static point light
 * per surface of a light-emitting shader (q3map_surfacelight), as q3map itself approximates area
 * lights by point lights. Its light at distance d is value x area / 4 / d^2 in 0-255 units
 * (q3map's areaScale 0.25), full light (1) at d_full = sqrt(value x area / 4 / 255): the light
 * gets range 3 d_full with the quadratic falloff (1 at the light, 0.89 at d_full, 0 at the range). */
static void record_map_lighting(void) {
  float sun_direction[3] = {0, 1, 0}, sun_rgb[3] = {0, 0, 0}, ambient[3] = {0, 0, 0}, sky[3] = {0, 0, 0};
  if (g_db.have_map_lights) {
    /* dynbench's lights of this map (src/maplight): no ambient floor, the light grid's ambient is
     * made of the same lights, and the renderer makes its own indirect light */
    if (g_db.map_sun) {
      to_capture(g_db.map_sun_towards, sun_direction);
      memcpy(sun_rgb, g_db.map_sun_rgb, sizeof(sun_rgb));
    }
    if (dbc_set_lighting(g_db.session, sun_direction, sun_rgb, ambient, sky) != DBC_OK) db_fail("map lighting");
    fprintf(stderr, "dynbench-capture: %d map lights, %d light-emitting shaders from dynbench\n", g_db.static_light_count, g_db.map_surface_count);
    return;
  }
  for (int i = 0; i < g_bsp.shader_count; ++i) {
    const shader_info_t* info = shader_slot(g_bsp.shaders[i].shader, 0);
    if (!info || !info->has_sun) continue;
    const float azimuth = info->sun[4] * (float)M_PI / 180.0f, elevation = info->sun[5] * (float)M_PI / 180.0f;
    const float towards[3] = {cosf(elevation) * cosf(azimuth), cosf(elevation) * sinf(azimuth), sinf(elevation)};
    to_capture(towards, sun_direction);
    float colour[3] = {info->sun[0], info->sun[1], info->sun[2]};
    const float peak = fmaxf(colour[0], fmaxf(colour[1], colour[2]));
    for (int k = 0; k < 3; ++k) sun_rgb[k] = peak > 0 ? colour[k] / peak * info->sun[3] / 100.0f : 0.0f;
    break;
  }
  /* light grid cells: ambient rgb, directed rgb, direction (8 bytes), 0-255 */
  const int cells = g_bsp.grid_bytes / 8;
  double sum[3] = {0, 0, 0};
  int lit = 0;
  for (int c = 0; c < cells; ++c) {
    const unsigned char* cell = g_bsp.grid + c * 8;
    if (cell[0] + cell[1] + cell[2] + cell[3] + cell[4] + cell[5] == 0) continue; /* inside walls */
    for (int k = 0; k < 3; ++k) sum[k] += cell[k];
    ++lit;
  }
  if (lit > 0)
    for (int k = 0; k < 3; ++k) ambient[k] = (float)(sum[k] / lit / 255.0);
  if (dbc_set_lighting(g_db.session, sun_direction, sun_rgb, ambient, sky) != DBC_OK) { db_fail("map lighting"); return; }

  int lights = 0;
  for (int first = 0; first < g_bsp.surface_count; ++first) {
    const dsurface_t* s = &g_bsp.surfaces[first];
    if (s->shaderNum < 0 || s->shaderNum >= g_bsp.shader_count) continue;
    const shader_info_t* info = shader_slot(g_bsp.shaders[s->shaderNum].shader, 0);
    if (!info || info->surface_light <= 0 || info->sky) continue;
    mesh_builder_t m;
    memset(&m, 0, sizeof(m));
    add_surface(&m, s);
    double area = 0, centre[3] = {0, 0, 0};
    for (size_t t = 0; t < m.triangles; ++t) {
      const float* a = &m.positions[m.indices[t * 3] * 3];
      const float* b = &m.positions[m.indices[t * 3 + 1] * 3];
      const float* c = &m.positions[m.indices[t * 3 + 2] * 3];
      const float u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const float cross[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
      const double triangle = 0.5 * sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
      area += triangle;
      for (int k = 0; k < 3; ++k) centre[k] += triangle * (a[k] + b[k] + c[k]) / 3.0;
    }
    /* in front of its surface by half the surface's size (at least 16 units): q3map spreads an
     * area light over the surface, and a point light against the wall would light a small spot of
     * it thousands of times brighter than the game's light map (speckle in the indirect light) */
    float normal[3] = {0, 0, 0};
    for (size_t v = 0; v < m.vertices; ++v)
      for (int k = 0; k < 3; ++k) normal[k] += m.normals[v * 3 + k];
    mesh_free(&m);
    if (area <= 0) continue;
    const float length = sqrtf(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
    float position[3];
    const float offset = (float)fmax(16.0, 0.5 * sqrt(area));
    for (int k = 0; k < 3; ++k) position[k] = (float)(centre[k] / area) + (length > 0 ? offset * normal[k] / length : 0.0f);
    const double full = sqrt(info->surface_light * area / 4.0 / 255.0);
    const float range = (float)fmin(fmax(3.0 * full, 32.0), 4096.0);
    if (g_db.static_light_count >= MAX_STATIC_LIGHTS) break;
    float* light = g_db.static_lights[g_db.static_light_count++];
    memcpy(light, position, sizeof(position));
    memcpy(light + 3, info->light_rgb, 3 * sizeof(float));
    light[6] = range;
    light[7] = (float)DBC_FALLOFF_QUADRATIC;
    ++lights;
  }
  fprintf(stderr, "dynbench-capture: %d surface lights, ambient %.3f %.3f %.3f\n", lights, ambient[0], ambient[1], ambient[2]);
}

/* ---------------------------------------------------------------------------------------------- */
/* MD3 models */

static void md3_normal(short encoded, float out[3]) {
  const float lat = ((encoded >> 8) & 0xff) * (2.0f * (float)M_PI / 255.0f);
  const float lng = (encoded & 0xff) * (2.0f * (float)M_PI / 255.0f);
  out[0] = cosf(lat) * sinf(lng);
  out[1] = sinf(lat) * sinf(lng);
  out[2] = cosf(lng);
}

/* The shader a skin file (lines "surface,shader") gives a surface, or NULL. */
static int skin_shader(const char* skin_text, const char* surface, char out[MAX_QPATH]) {
  if (!skin_text) return 0;
  const size_t n = strlen(surface);
  for (const char* line = skin_text; *line;) {
    const char* end = strchr(line, '\n');
    if (!end) end = line + strlen(line);
    if ((size_t)(end - line) > n && !Q_stricmpn(line, surface, (int)n) && line[n] == ',') {
      const char* shader = line + n + 1;
      int length = (int)(end - shader);
      while (length > 0 && (shader[length - 1] == '\r' || shader[length - 1] == ' ' || shader[length - 1] == '"')) --length;
      while (length > 0 && (*shader == ' ' || *shader == '"')) { ++shader; --length; }
      if (length <= 0 || length >= MAX_QPATH) return 0;
      memcpy(out, shader, (size_t)length);
      out[length] = 0;
      return 1;
    }
    line = *end ? end + 1 : end;
  }
  return 0;
}

/* Whether an MD3 surface is drawn as an opaque surface, and its shader (the skin's, else its own). */
static int md3_surface_drawn(const md3Surface_t* surface, const char* skin_text, char shader[MAX_QPATH]) {
  shader[0] = 0;
  if (!skin_shader(skin_text, surface->name, shader) && surface->numShaders > 0)
    Q_strncpyz(shader, ((const md3Shader_t*)((const char*)surface + surface->ofsShaders))->name, MAX_QPATH);
  if (strstr(shader, "nodraw")) return 0;
  const shader_info_t* info = shader[0] ? shader_slot(shader, 0) : NULL;
  return !(info && (info->nodraw || info->translucent));
}

/* Records an MD3 (with a skin's shaders when `skin` is given) as `model_path`: a mesh per
 * surface, and every key frame of a model with more than one. Returns the key-frame count (1 for a
 * rigid model), 0 on failure. */
static int record_md3(const char* file, const char* skin, const char* model_path) {
  int length = 0;
  char* data = read_game_file(file, &length);
  if (!data) {
    char md3[MAX_QPATH];
    COM_StripExtension(file, md3, sizeof(md3));
    Q_strcat(md3, sizeof(md3), ".md3");
    data = read_game_file(md3, &length);
  }
  if (!data || length < (int)sizeof(md3Header_t) || ((md3Header_t*)data)->ident != MD3_IDENT) {
    free(data);
    return 0;
  }
  const md3Header_t* header = (const md3Header_t*)data;
  if (header->numSurfaces <= 0 || header->numFrames <= 0) { /* nothing drawn (Angelyss's upper.md3 in pak6-patch085) */
    free(data);
    return 0;
  }
  char* skin_text = skin ? read_game_file(skin, NULL) : NULL;
  const int frames = header->numFrames;
  int drawn = 0; /* a model of effects only (a muzzle flash) is not recorded: nothing of it is drawn */
  {
    const md3Surface_t* surface = (const md3Surface_t*)(data + header->ofsSurfaces);
    for (int s = 0; s < header->numSurfaces; ++s, surface = (const md3Surface_t*)((const char*)surface + surface->ofsEnd)) {
      char shader[MAX_QPATH];
      if ((const char*)surface + sizeof(md3Surface_t) > data + length || surface->ofsEnd <= 0) break;
      if (surface->numVerts > 0 && surface->numTriangles > 0 && surface->numFrames == frames && md3_surface_drawn(surface, skin_text, shader)) ++drawn;
    }
  }
  if (!drawn) {
    free(data);
    free(skin_text);
    return 0;
  }
  if (dbc_model_begin(g_db.session, model_path) != DBC_OK) { free(data); free(skin_text); db_fail("model"); return 0; }
  const md3Surface_t* surface = (const md3Surface_t*)(data + header->ofsSurfaces);
  int mesh_id = 0;
  for (int s = 0; s < header->numSurfaces; ++s, surface = (const md3Surface_t*)((const char*)surface + surface->ofsEnd)) {
    if ((const char*)surface + sizeof(md3Surface_t) > data + length || surface->ofsEnd <= 0) break;
    const int nv = surface->numVerts, nt = surface->numTriangles;
    if (nv <= 0 || nt <= 0 || surface->numFrames != frames) continue;
    char shader[MAX_QPATH] = "";
    if (!md3_surface_drawn(surface, skin_text, shader)) continue;
    mesh_builder_t m;
    memset(&m, 0, sizeof(m));
    mesh_reserve(&m, (size_t)nv, (size_t)nt);
    const md3St_t* st = (const md3St_t*)((const char*)surface + surface->ofsSt);
    const md3XyzNormal_t* xyz = (const md3XyzNormal_t*)((const char*)surface + surface->ofsXyzNormals);
    const md3Triangle_t* triangles = (const md3Triangle_t*)((const char*)surface + surface->ofsTriangles);
    float* key_positions = frames > 1 ? malloc((size_t)frames * nv * 3 * sizeof(float)) : NULL;
    float* key_normals = frames > 1 ? malloc((size_t)frames * nv * 3 * sizeof(float)) : NULL;
    for (int f = 0; f < frames; ++f)
      for (int v = 0; v < nv; ++v) {
        const md3XyzNormal_t* x = &xyz[f * nv + v];
        const float p[3] = {x->xyz[0] * (float)MD3_XYZ_SCALE, x->xyz[1] * (float)MD3_XYZ_SCALE, x->xyz[2] * (float)MD3_XYZ_SCALE};
        float n[3];
        md3_normal(x->normal, n);
        if (f == 0) mesh_vertex(&m, p, n, st[v].st);
        if (key_positions) {
          to_capture(p, &key_positions[((size_t)f * nv + v) * 3]);
          to_capture(n, &key_normals[((size_t)f * nv + v) * 3]);
        }
      }
    for (int t = 0; t < nt; ++t) {
      const int* index = triangles[t].indexes;
      if (index[0] < 0 || index[1] < 0 || index[2] < 0 || index[0] >= nv || index[1] >= nv || index[2] >= nv) continue;
      mesh_triangle(&m, (uint32_t)index[0], (uint32_t)index[1], (uint32_t)index[2]);
    }
    int ok = record_mesh(mesh_id, surface->name, shader[0] ? shader_texture(shader) : NULL, &m, NULL);
    if (ok && key_positions) ok = dbc_model_mesh_frames(g_db.session, mesh_id, (size_t)frames, key_positions, key_normals) == DBC_OK;
    free(key_positions);
    free(key_normals);
    mesh_free(&m);
    if (!ok) { free(data); free(skin_text); db_fail("model mesh"); return 0; }
    ++mesh_id;
  }
  free(data);
  free(skin_text);
  if (dbc_model_end(g_db.session) != DBC_OK) { db_fail("model end"); return 0; }
  /* key frames only when some mesh has them (every recorded mesh has the model's count) */
  return mesh_id > 0 && frames > 1 ? frames : 1;
}

/* ---------------------------------------------------------------------------------------------- */
/* identities */

static uint64_t identity(int slot, int serial, int model, int skin, int occurrence, int* fresh) {
  uint32_t h = 2166136261u;
  const int key[5] = {slot, serial, model, skin, occurrence};
  for (int i = 0; i < 5; ++i) h = (h ^ (uint32_t)key[i]) * 16777619u;
  for (int probe = 0; probe < ID_TABLE_SIZE; ++probe) {
    identity_t* e = &g_db.ids[(h + (uint32_t)probe) & (ID_TABLE_SIZE - 1)];
    if (!e->used) {
      e->used = 1;
      e->slot = slot; e->serial = serial; e->model = model; e->skin = skin; e->occurrence = occurrence;
      e->id = dbc_new_id(g_db.session);
      *fresh = 1;
      return e->id;
    }
    if (e->slot == slot && e->serial == serial && e->model == model && e->skin == skin && e->occurrence == occurrence) {
      *fresh = 0;
      return e->id;
    }
  }
  *fresh = 1;
  return dbc_new_id(g_db.session); /* table full: a fresh id every frame, correct if wasteful */
}

/* ---------------------------------------------------------------------------------------------- */
/* hooks */

/* The client game's random numbers (cg_local.h sends its rand() here): the C library's would
 * interleave with the game module's and the bots' (one process), and the client draws a different
 * number of them before the match on every run (how long it took to connect). Restarted with the
 * level. A 32-bit linear congruential generator (Numerical Recipes' constants) is enough for
 * effects; rand()'s 15 bits, as the game code expects. */
static uint32_t g_cg_random = 1;

int dynbench_cg_rand(void) {
  g_cg_random = g_cg_random * 1664525u + 1013904223u;
  return (int)((g_cg_random >> 16) & 0x7fff);
}

void dynbench_map_restart(void) {
  if (!g_db.active || !g_db.restart_sent) return;
  g_db.restarted = 1;
  g_cg_random = (uint32_t)(getenv("DYNBENCH_CAPTURE_SEED") ? atoi(getenv("DYNBENCH_CAPTURE_SEED")) : 1);
}

void dynbench_register_model(const char* name, qhandle_t handle) {
  if (handle > 0 && handle < MAX_HANDLES && name) Q_strncpyz(g_db.model_names[handle], name, MAX_QPATH);
}

void dynbench_register_skin(const char* name, qhandle_t handle) {
  if (handle > 0 && handle < MAX_HANDLES && name) Q_strncpyz(g_db.skin_names[handle], name, MAX_QPATH);
}

/* Forgets what the slot drew before this pass (its draws are counted per pass: occurrence_of). */
static void reset_owner_draws(int slot) {
  memset(g_db.owner_model_count[slot], 0, sizeof(g_db.owner_model_count[slot]));
  memset(g_db.owner_models[slot], 0, sizeof(g_db.owner_models[slot]));
  g_db.owner_lights[slot] = 0;
}

void dynbench_owner_begin(int slot, int entity_type, int signature) {
  if (!g_db.active || slot < 0 || slot >= UNOWNED_SLOT) return;
  g_db.owner_slot = slot;
  g_db.owner_type = entity_type;
  /* A slot's next lifetime: another thing in it, or the same slot after a frame without it
   * (players keep theirs: their slot is their client). */
  const int gap = g_db.owner_last_frame[slot] < g_db.pass - 1;
  if (g_db.owner_signature[slot] != signature || (gap && entity_type != ET_PLAYER)) ++g_db.owner_serial[slot];
  g_db.owner_signature[slot] = signature;
  if (g_db.owner_last_frame[slot] != g_db.pass) reset_owner_draws(slot); /* its first draw this pass */
  g_db.owner_last_frame[slot] = g_db.pass;
}

void dynbench_owner_end(void) { g_db.owner_slot = UNOWNED_SLOT; g_db.owner_type = -1; }

void dynbench_clear_scene(void) {
  g_db.entity_count = 0;
  g_db.light_count = 0;
  g_db.owner_slot = UNOWNED_SLOT;
  g_db.owner_type = -1;
  reset_owner_draws(UNOWNED_SLOT); /* its draws are counted afresh each frame */
}

/* The k-th draw of this model by the current owner in this pass. */
static int occurrence_of(int slot, int model) {
  for (int i = 0; i < 8; ++i) {
    if (g_db.owner_models[slot][i] == model) return g_db.owner_model_count[slot][i]++;
    if (g_db.owner_models[slot][i] == 0) {
      g_db.owner_models[slot][i] = model;
      g_db.owner_model_count[slot][i] = 1;
      return 0;
    }
  }
  return 8 + model; /* more models than tracked: still stable */
}

void dynbench_add_ref_entity(const refEntity_t* e) {
  if (!g_db.active || !e || g_db.entity_count >= MAX_PENDING) return;
  if (e->reType != RT_MODEL || e->hModel <= 0 || e->hModel >= MAX_HANDLES) return;
  if (e->renderfx & (RF_THIRD_PERSON | RF_FIRST_PERSON | RF_DEPTHHACK)) return; /* not in the main view / the HUD gun */
  if (e->customShader) return; /* an effect shell drawn over a model (quad damage, spawn, invisibility) */
  for (int i = 0; i < 3; ++i) /* scaled to nothing (an item respawning grows from zero): nothing is drawn */
    if (!(VectorLength(e->axis[i]) >= 1e-4f) || !isfinite(e->origin[i])) return; /* (NaN too: the SDK would refuse it) */
  pending_entity_t* p = &g_db.entities[g_db.entity_count++];
  p->entity = *e;
  p->slot = g_db.owner_slot;
  p->serial = g_db.owner_serial[p->slot];
  p->occurrence = occurrence_of(p->slot, e->hModel * MAX_HANDLES + e->customSkin);
}

void dynbench_add_light(const vec3_t origin, float intensity, float r, float g, float b) {
  if (!g_db.active || g_db.light_count >= MAX_PENDING || intensity <= 0) return;
  pending_light_t* l = &g_db.lights[g_db.light_count++];
  VectorCopy(origin, l->origin);
  l->intensity = intensity;
  l->rgb[0] = r; l->rgb[1] = g; l->rgb[2] = b;
  l->slot = g_db.owner_slot;
  l->serial = g_db.owner_serial[l->slot];
  l->occurrence = g_db.owner_lights[l->slot]++;
  l->entity_type = g_db.owner_slot >= DYNBENCH_LOCAL_SLOT ? -2 : g_db.owner_type;
}

static dbc_dual_quat pose_of(const refEntity_t* e) {
  /* the model's axes as the columns of its rotation, normalised (a scaled item is drawn rigid) */
  float axis[3][3];
  for (int i = 0; i < 3; ++i) {
    float a[3] = {e->axis[i][0], e->axis[i][1], e->axis[i][2]};
    const float length = sqrtf(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (length > 1e-6f) { a[0] /= length; a[1] /= length; a[2] /= length; }
    to_capture(a, axis[i]);
  }
  /* capture-space rotation R' = C M C^T: column i of M (axis[i]) is the image of the game's basis
   * vector i, which C sends to capture basis vector c(i): +x -> -z, +y -> -x, +z -> +y */
  float R[3][3]; /* R[row][column] */
  for (int r = 0; r < 3; ++r) {
    R[r][2] = -axis[0][r]; /* capture +z is game -x */
    R[r][0] = -axis[1][r]; /* capture +x is game -y */
    R[r][1] = axis[2][r];  /* capture +y is game +z */
  }
  float q[4]; /* x y z w from the rotation matrix (Shoemake) */
  const float trace = R[0][0] + R[1][1] + R[2][2];
  if (trace > 0) {
    const float s = sqrtf(trace + 1.0f) * 2;
    q[3] = 0.25f * s; q[0] = (R[2][1] - R[1][2]) / s; q[1] = (R[0][2] - R[2][0]) / s; q[2] = (R[1][0] - R[0][1]) / s;
  } else if (R[0][0] > R[1][1] && R[0][0] > R[2][2]) {
    const float s = sqrtf(1.0f + R[0][0] - R[1][1] - R[2][2]) * 2;
    q[3] = (R[2][1] - R[1][2]) / s; q[0] = 0.25f * s; q[1] = (R[0][1] + R[1][0]) / s; q[2] = (R[0][2] + R[2][0]) / s;
  } else if (R[1][1] > R[2][2]) {
    const float s = sqrtf(1.0f + R[1][1] - R[0][0] - R[2][2]) * 2;
    q[3] = (R[0][2] - R[2][0]) / s; q[0] = (R[0][1] + R[1][0]) / s; q[1] = 0.25f * s; q[2] = (R[1][2] + R[2][1]) / s;
  } else {
    const float s = sqrtf(1.0f + R[2][2] - R[0][0] - R[1][1]) * 2;
    q[3] = (R[1][0] - R[0][1]) / s; q[0] = (R[0][2] + R[2][0]) / s; q[1] = (R[1][2] + R[2][1]) / s; q[2] = 0.25f * s;
  }
  const float n = sqrtf(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int i = 0; i < 4; ++i) q[i] /= n;
  float t[3];
  to_capture(e->origin, t);
  /* d = 1/2 (t, 0) r */
  dbc_dual_quat dq;
  dq.rx = q[0]; dq.ry = q[1]; dq.rz = q[2]; dq.rw = q[3];
  dq.dx = 0.5f * (t[0] * q[3] + t[1] * q[2] - t[2] * q[1]);
  dq.dy = 0.5f * (-t[0] * q[2] + t[1] * q[3] + t[2] * q[0]);
  dq.dz = 0.5f * (t[0] * q[1] - t[1] * q[0] + t[2] * q[3]);
  dq.dw = 0.5f * (-t[0] * q[0] - t[1] * q[1] - t[2] * q[2]);
  return dq;
}

/* Model paths: the MD3 with its skin, or a brush model of the map; the key-frame count of each
 * recorded one (0 before it is recorded, -1 when it cannot be). */
static int g_model_frames[MAX_HANDLES][8];
static int g_model_skins[MAX_HANDLES][8];

static const char* model_path_of(const refEntity_t* e, char out[3 * MAX_QPATH], int* frames) {
  const char* name = g_db.model_names[e->hModel];
  if (!name[0]) return NULL;
  const char* skin = e->customSkin > 0 && e->customSkin < MAX_HANDLES && g_db.skin_names[e->customSkin][0] ? g_db.skin_names[e->customSkin] : NULL;
  if (name[0] == '*') Com_sprintf(out, 3 * MAX_QPATH, "%s/%s", g_db.world_path, name);
  else if (skin) Com_sprintf(out, 3 * MAX_QPATH, "%s@%s", name, skin);
  else Q_strncpyz(out, name, 3 * MAX_QPATH);
  int slot = -1;
  for (int i = 0; i < 8; ++i)
    if (g_model_skins[e->hModel][i] == e->customSkin + 1 || g_model_skins[e->hModel][i] == 0) { slot = i; break; }
  if (slot < 0) return NULL;
  if (g_model_skins[e->hModel][slot] == 0) {
    g_model_skins[e->hModel][slot] = e->customSkin + 1;
    int recorded;
    if (name[0] == '*') recorded = record_bsp_model(atoi(name + 1), out);
    else recorded = record_md3(name, skin, out);
    g_model_frames[e->hModel][slot] = recorded > 0 ? recorded : -1;
  }
  *frames = g_model_frames[e->hModel][slot];
  return *frames > 0 ? out : NULL;
}

static void camera_angles(const refdef_t* view, float* pitch, float* yaw, float* roll) {
  float f[3], u[3];
  to_capture(view->viewaxis[0], f);
  to_capture(view->viewaxis[2], u);
  /* R = Ry(yaw) Rx(pitch) Rz(roll) sends -Z to the forward vector and +Y to up (docs/metrics.md) */
  *yaw = atan2f(-f[0], -f[2]);
  *pitch = asinf(fmaxf(-1.0f, fminf(1.0f, f[1])));
  /* up in the frame of Ry(yaw) Rx(pitch): (-sin roll, cos roll, 0) */
  const float cy = cosf(*yaw), sy = sinf(*yaw), cp = cosf(*pitch), sp = sinf(*pitch);
  const float x1 = cy * u[0] - sy * u[2], z1 = sy * u[0] + cy * u[2]; /* Ry(-yaw) u */
  const float y2 = cp * u[1] + sp * z1;                              /* Rx(-pitch) */
  *roll = atan2f(-x1, y2);
  *pitch *= 180.0f / (float)M_PI;
  *yaw *= 180.0f / (float)M_PI;
  *roll *= 180.0f / (float)M_PI;
}

static int first_bot(void) {
  for (int i = 0; i < MAX_CLIENTS; ++i)
    if (i != cg.clientNum && cgs.clientinfo[i].infoValid) return i;
  return -1;
}

/* Spectating: team spectator once, then `follow` until the server has us following. */
static int ensure_following(void) {
  const playerState_t* ps = &cg.snap->ps;
  if (ps->pm_flags & PMF_FOLLOW) return 1;
  if (ps->persistant[PERS_TEAM] != TEAM_SPECTATOR) {
    if (!g_db.spectate_sent_at || cg.time - g_db.spectate_sent_at > 1000) {
      trap_SendClientCommand("team spectator");
      g_db.spectate_sent_at = cg.time;
    }
    return 0;
  }
  const int target = g_db.follow_target >= 0 ? g_db.follow_target : first_bot();
  if (target >= 0 && (!g_db.follow_sent_at || cg.time - g_db.follow_sent_at > 500)) {
    trap_SendClientCommand(va("follow %d", target));
    g_db.follow_sent_at = cg.time;
  }
  return 0;
}

/* The game's own image of recorded frame `frame`: colour and depth, read right after the renderer
 * drew the frame's main view, before the swap. The renderer queues its commands and draws them at
 * the end of the engine's frame, after this module returns; registering a font makes it draw what
 * is queued first (RE_RegisterFont calls R_IssuePendingRenderCommands before anything else, and
 * OpenArena ships no font, so nothing is registered: the engine prints one warning per kept
 * frame). Reading at the start of the next frame instead, after the swap, kept the colour (Mesa's
 * llvmpipe under Xvfb swaps by copying) but the depth buffer read back as zeros on about a third
 * of the frames whenever llvmpipe rasterised in more than one thread or in the calling one. The
 * HUD is off (cg_draw2D 0) and nothing but the view is drawn before the read. 8-bit sRGB, binary
 * PPM, top row first, written to a temporary name and renamed. */
static void keep_game_frame(int frame) {
  const int w = cgs.glconfig.vidWidth, h = cgs.glconfig.vidHeight;
  static fontInfo_t no_font;
  trap_R_RegisterFont("dynbench-draw-queued-commands", 12, &no_font);
  unsigned char* rgb = malloc((size_t)w * h * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  char path[1400], temporary[1500];
  Com_sprintf(path, sizeof(path), "%s/game/frame_%05d.ppm", g_db.dir, frame);
  Com_sprintf(temporary, sizeof(temporary), "%s.part", path);
  FILE* out = make_directories(path) ? fopen(temporary, "wb") : NULL;
  int ok = out != NULL;
  if (out) {
    fprintf(out, "P6\n%d %d\n255\n", w, h);
    for (int y = h - 1; y >= 0 && ok; --y) ok = fwrite(rgb + (size_t)y * w * 3, 1, (size_t)w * 3, out) == (size_t)w * 3;
    ok = fclose(out) == 0 && ok;
  }
  free(rgb);
  if (!ok || rename(temporary, path) != 0) fprintf(stderr, "dynbench-capture: warning: cannot write %s\n", path);
  /* The depth buffer as it is (window depth, 0 at r_znear, 1 at the far plane and on the sky, which
   * the renderer draws at depth 1). The engine picks its far plane per frame from the visible
   * leaves (R_SetFarClip) and does not expose it: `dynbench fidelity` solves for it. PFM rows run
   * bottom to top, as glReadPixels returns them. */
  float* depth = malloc((size_t)w * h * sizeof(float));
  glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depth);
  /* A depth buffer that reads back uniform (as it did after the swap) is not kept: `dynbench
   * fidelity` then says the frame's depth was not read. */
  int varies = 0;
  for (int i = 1; i < w * h && !varies; ++i) varies = depth[i] != depth[0];
  Com_sprintf(path, sizeof(path), "%s/game/frame_%05d_window_depth.pfm", g_db.dir, frame);
  Com_sprintf(temporary, sizeof(temporary), "%s.part", path);
  out = varies ? fopen(temporary, "wb") : NULL;
  if (!varies) fprintf(stderr, "dynbench-capture: warning: frame %d: the depth buffer read back empty; no depth kept\n", frame);
  ok = out != NULL;
  if (out) {
    fprintf(out, "Pf\n%d %d\n-1.0\n", w, h);
    ok = fwrite(depth, sizeof(float), (size_t)w * h, out) == (size_t)w * h;
    ok = fclose(out) == 0 && ok;
  }
  free(depth);
  if (varies && (!ok || rename(temporary, path) != 0)) fprintf(stderr, "dynbench-capture: warning: cannot write %s\n", path);
  char znear[64];
  trap_Cvar_VariableStringBuffer("r_znear", znear, sizeof(znear));
  Com_sprintf(path, sizeof(path), "%s/game/window_depth.txt", g_db.dir);
  out = fopen(path, "w");
  if (out) {
    fprintf(out, "near %s\n", znear[0] ? znear : "4");
    fclose(out);
  }
}

void dynbench_scene_rendered(const refdef_t* view) {
  if (g_db.pending_game_frame < 0 || (view->rdflags & RDF_NOWORLDMODEL)) return;
  keep_game_frame(g_db.pending_game_frame);
  g_db.pending_game_frame = -1;
}

void dynbench_render_scene(const refdef_t* view) {
  if (!g_db.active || (view->rdflags & RDF_NOWORLDMODEL) || !cg.snap) return;
  ++g_db.pass;
  /* How many frames the client takes to connect and load depends on the machine's load, and the
   * client shares the C library's random numbers with the game and the bots (native modules in
   * one process), so a match that ran while the client connected would differ from run to run.
   * The client joins as a spectator (userinfo team s) of an empty level; at a fixed server time
   * the adapter restarts the level (map_restart 0: the game module re-seeds from
   * DYNBENCH_CAPTURE_SEED, the client stays connected, and the game module adds the bots of
   * DYNBENCH_CAPTURE_BOTS in the same command pass): the match starts in the same engine frame,
   * with the same random numbers, on every run. Recording starts at a fixed time after it. (Bots
   * added from here, a frame after this module saw the restart, joined a frame apart from run to
   * run; so does the moment the server starts answering `follow`.) */
  if (!g_db.restarted) {
    if (!g_db.connected_at) {
      g_db.connected_at = cg.snap->serverTime;
      printf("dynbench-capture: client in at %d ms of server time\n", g_db.connected_at);
    }
    if (cg.snap->ps.persistant[PERS_TEAM] != TEAM_SPECTATOR) {
      ensure_following();
    } else if (!g_db.restart_sent && cg.snap->serverTime >= RESTART_AT) {
      if (g_db.connected_at >= RESTART_AT)
        fprintf(stderr, "dynbench-capture: warning: the client connected after %d ms of server time; the match may differ from run to run\n", RESTART_AT);
      trap_SendConsoleCommand("map_restart 0\n");
      g_db.restart_sent = 1;
    }
    return;
  }
  const int following = ensure_following();
  if (!g_db.started) {
    if (!following || cg.time < cgs.levelStartTime + (int)(g_db.warmup * 1000)) {
      if (cg.time > cgs.levelStartTime + (int)(g_db.warmup * 1000) + 20000) {
        fprintf(stderr, "dynbench-capture: error: not following a bot 20 s after the warm-up (is one in the game?)\n");
        g_db.active = 0;
        trap_SendConsoleCommand("quit\n");
      }
      return;
    }
    g_db.started = 1;
    g_db.start_time = cg.time;
    g_db.window_start = trap_Milliseconds(); /* the machine's clock: this is the one place it is read */
    printf("dynbench-capture: level started at %d ms of server time, recording from %d\n", cgs.levelStartTime, cg.time);
  }
  const playerState_t* ps = &cg.snap->ps;
  /* --follow auto: the next bot once the followed one dies (the server switches the view) */
  const int dead = ps->stats[STAT_HEALTH] <= 0 || ps->pm_type == PM_DEAD;
  if (dead && !strcmp(g_db.follow, "auto") && g_db.next_sent_for_death != ps->clientNum + 1) {
    trap_SendClientCommand("follownext");
    g_db.next_sent_for_death = ps->clientNum + 1;
  }
  if (!dead) g_db.next_sent_for_death = 0;
  if (!g_db.record) {
    printf("dynbench-capture: %d/%d frames\n", ++g_db.frame, g_db.total_frames);
    if (g_db.frame >= g_db.total_frames) {
      printf("dynbench-capture: window of %d frames took %d ms of wall time (not recorded)\n", g_db.frame, trap_Milliseconds() - g_db.window_start);
      fflush(stdout);
      g_db.active = 0;
      trap_SendConsoleCommand("quit\n");
    }
    return;
  }
  dbc_session* s = g_db.session;
  /* The capture's lens is set once, before the first frame. The view's field of view can change
   * later (CG_CalcFov waves it while the followed player is under water, and zooms): the capture
   * keeps the first, and says so once. */
  if (!g_db.last_camera_width) {
    g_db.last_camera_width = view->width;
    g_db.last_camera_height = view->height;
    g_db.camera_fov = view->fov_y;
    if (dbc_set_camera_settings(s, (float)view->width / (float)view->height, view->fov_y, 4.0f, 16384.0f) != DBC_OK) { db_fail("camera settings"); return; }
  } else if (!g_db.fov_change_reported && (view->width != g_db.last_camera_width || view->height != g_db.last_camera_height || view->fov_y != g_db.camera_fov)) {
    g_db.fov_change_reported = 1;
    fprintf(stderr, "dynbench-capture: note: the view's field of view changed at frame %d (%.3f to %.3f degrees, under water or zoomed); the capture keeps the first\n",
            g_db.frame, g_db.camera_fov, view->fov_y);
  }
  /* models are recorded between frames: every drawn one first */
  static char paths[MAX_PENDING][3 * MAX_QPATH];
  static int key_frames[MAX_PENDING];
  for (int i = 0; i < g_db.entity_count; ++i) {
    if (!model_path_of(&g_db.entities[i].entity, paths[i], &key_frames[i])) paths[i][0] = 0;
    if (!g_db.active) return;
  }
  if (dbc_frame_begin(s, (uint64_t)g_db.frame, (cg.time - g_db.start_time) / 1000.0) != DBC_OK) { db_fail("frame"); return; }
  float position[3], pitch, yaw, roll;
  to_capture(view->vieworg, position);
  camera_angles(view, &pitch, &yaw, &roll);
  if (dbc_camera(s, g_db.camera_id, position, pitch, yaw, roll) != DBC_OK) { db_fail("camera"); return; }
  /* cuts: another player followed, a respawn or a teleporter (the game toggles EF_TELEPORT_BIT
   * when the view's origin jumps), or a jump the game did not mark */
  const int teleport = ps->eFlags & EF_TELEPORT_BIT;
  if (g_db.have_last) {
    const float dx = position[0] - g_db.last_position[0], dy = position[1] - g_db.last_position[1], dz = position[2] - g_db.last_position[2];
    const char* reason = NULL;
    if (ps->clientNum != g_db.last_client) reason = "switch";
    else if (teleport != g_db.last_teleport) reason = g_db.last_dead ? "respawn" : "teleport";
    else if (dx * dx + dy * dy + dz * dz > 64.0f * 64.0f) reason = "teleport";
    if (reason && dbc_camera_cut(s, g_db.camera_id, reason) != DBC_OK) { db_fail("camera cut"); return; }
  }
  g_db.have_last = 1;
  g_db.last_client = ps->clientNum;
  g_db.last_teleport = teleport;
  g_db.last_dead = dead;
  memcpy(g_db.last_position, position, sizeof(position));

  if (g_db.frame == 0) {
    const dbc_dual_quat identity_pose = {0, 0, 0, 1, 0, 0, 0, 0};
    if (dbc_static_model(s, dbc_new_id(s), g_db.world_path, identity_pose) != DBC_OK) { db_fail("world"); return; }
    for (int i = 0; i < g_db.static_light_count; ++i) {
      const float* light = g_db.static_lights[i];
      if (dbc_light(s, dbc_new_id(s), light, light + 3, light[6], (dbc_light_falloff)(int)light[7], DBC_LIGHT_POINT, 0,
                    g_db.have_map_lights ? "maplight" : "surfacelight") != DBC_OK) {
        db_fail("surface light");
        return;
      }
    }
  }
  for (int i = 0; i < g_db.entity_count && g_db.active; ++i) {
    const pending_entity_t* p = &g_db.entities[i];
    const char* path = paths[i];
    const int frames = key_frames[i];
    if (!path[0]) continue;
    int fresh;
    const uint64_t id = identity(p->slot, p->serial, p->entity.hModel, p->entity.customSkin, p->occurrence, &fresh);
    if (dbc_model(s, id, path, pose_of(&p->entity)) != DBC_OK) { db_fail("model transform"); return; }
    if (frames > 1) {
      const uint32_t from = (uint32_t)(p->entity.oldframe % frames), to = (uint32_t)(p->entity.frame % frames);
      const float fraction = fminf(1.0f, fmaxf(0.0f, 1.0f - p->entity.backlerp));
      if (dbc_vertex_frames(s, id, path, from, to, fraction) != DBC_OK) { db_fail("key frames"); return; }
    }
  }
  for (int i = 0; i < g_db.light_count; ++i) {
    const pending_light_t* l = &g_db.lights[i];
    int fresh;
    const uint64_t id = identity(l->slot, l->serial, -1, 0, l->occurrence, &fresh);
    float at[3];
    to_capture(l->origin, at);
    const char* type = l->entity_type == ET_MISSILE ? "missile" : l->entity_type == ET_PLAYER ? "flash" : l->entity_type == -2 ? "explosion" : "effect";
    /* the renderer's dynamic light reaches `intensity` units and fades towards it */
    if (dbc_light(s, id, at, l->rgb, l->intensity, DBC_FALLOFF_QUADRATIC, DBC_LIGHT_POINT, 1, type) != DBC_OK) { db_fail("light"); return; }
  }
  if (dbc_frame_end(s) != DBC_OK) { db_fail("frame end"); return; }
  if (strstr(g_db.game_frames, va(",%d,", g_db.frame))) g_db.pending_game_frame = g_db.frame;
  ++g_db.frame;
  printf("dynbench-capture: %d/%d frames\n", g_db.frame, g_db.total_frames);
  fflush(stdout);
  if (g_db.frame >= g_db.total_frames) {
    if (dbc_close(s) != DBC_OK) { g_db.session = NULL; db_fail("close"); return; }
    g_db.session = NULL;
    g_db.active = 0;
    printf("dynbench-capture: window of %d frames took %d ms of wall time (recorded; %d frames off the fixed clock)\n", g_db.frame,
           trap_Milliseconds() - g_db.window_start, g_db.clock_resets);
    fflush(stdout);
    trap_SendConsoleCommand("quit\n");
  }
}

int dynbench_frame_time(int server_time) {
  if (!g_db.active || g_db.frame_ms <= 0) return server_time;
  int snapshot = 0, latest = 0;
  trap_GetCurrentSnapshotNumber(&snapshot, &latest);
  if (snapshot <= 0) return server_time;
  const int t = latest - g_db.frame_ms;
  if (g_db.started && t != g_db.clock_base + g_db.frame_ms) ++g_db.clock_resets; /* a frame without its own snapshot */
  g_db.clock_base = t;
  return t;
}

/* A light colour of the game's (a lightmap's tint) as a linear colour of the same peak. The engine
 * multiplies texture and lightmap bytes and shows the product as an 8-bit sRGB image: a light of
 * colour c (peak 1) and level k displays as decode(texture) x decode(k c), whose hue is decode(c)
 * (exactly for a pure power law, closely for sRGB's curve). So a
 * (1, 0.5, 0.5) light shows dark red in the game and is (1, 0.21, 0.21) in linear light; taken as
 * linear, it lit a grey floor pale pink (oa_ctf2, docs/fidelity.md). The level stays linear (q3map2
 * adds lights' levels in lightmap bytes, and the fit did). */
static void game_colour_to_linear(float rgb[3]) {
  const float peak = fmaxf(rgb[0], fmaxf(rgb[1], rgb[2]));
  if (peak <= 0) return;
  for (int k = 0; k < 3; ++k) {
    const float c = fmaxf(rgb[k], 0.0f) / peak; /* the sRGB decoding (IEC 61966-2-1) */
    rgb[k] = peak * (c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f));
  }
}

/* dynbench's lights of the map (src/maplight/fit.h, writeAdapterLights): "point X Y Z R G B D",
 * "sun DX DY DZ R G B", "surface SHADER R G B", game axes, full-light units; their colours made
 * linear here (game_colour_to_linear). */
static int load_map_lights(const char* path) {
  if (!path || !path[0]) return 1;
  FILE* file = fopen(path, "r");
  if (!file) {
    fprintf(stderr, "dynbench-capture: error: %s: cannot open the map's lights\n", path);
    return 0;
  }
  char line[512];
  int number = 0;
  while (fgets(line, sizeof(line), file)) {
    ++number;
    char kind[16], shader[MAX_QPATH];
    float v[7];
    if (line[0] == '#' || line[0] == '\n') continue;
    if (sscanf(line, "point %f %f %f %f %f %f %f", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6]) == 7) {
      if (g_db.static_light_count >= MAX_STATIC_LIGHTS) continue;
      float* light = g_db.static_lights[g_db.static_light_count++];
      to_capture(v, light);
      game_colour_to_linear(v + 3);
      memcpy(light + 3, v + 3, 4 * sizeof(float));
      light[7] = (float)DBC_FALLOFF_INVERSE_SQUARE;
    } else if (sscanf(line, "sun %f %f %f %f %f %f", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) == 6) {
      g_db.map_sun = 1;
      memcpy(g_db.map_sun_towards, v, 3 * sizeof(float));
      game_colour_to_linear(v + 3);
      memcpy(g_db.map_sun_rgb, v + 3, 3 * sizeof(float));
    } else if (sscanf(line, "surface %63s %f %f %f", shader, &v[0], &v[1], &v[2]) == 4) {
      if (g_db.map_surface_count >= MAX_MAP_SURFACE_LIGHTS) continue;
      Q_strncpyz(g_db.map_surface_shader[g_db.map_surface_count], shader, MAX_QPATH);
      game_colour_to_linear(v);
      memcpy(g_db.map_surface_emission[g_db.map_surface_count++], v, 3 * sizeof(float));
    } else if (sscanf(line, "%15s", kind) == 1) {
      fclose(file);
      fprintf(stderr, "dynbench-capture: error: %s:%d: expected 'point X Y Z R G B D', 'sun DX DY DZ R G B' or 'surface SHADER R G B'\n", path, number);
      return 0;
    }
  }
  fclose(file);
  g_db.have_map_lights = 1;
  return 1;
}

void dynbench_cg_init(void) {
  const char* dir = getenv("DYNBENCH_CAPTURE_DIR");
  if (!dir || !dir[0] || g_db.session) return;
  Q_strncpyz(g_db.dir, dir, sizeof(g_db.dir));
  g_db.seconds = getenv("DYNBENCH_CAPTURE_SECONDS") ? atof(getenv("DYNBENCH_CAPTURE_SECONDS")) : 10.0;
  g_db.warmup = getenv("DYNBENCH_CAPTURE_WARMUP") ? atof(getenv("DYNBENCH_CAPTURE_WARMUP")) : 3.0;
  const double fps = getenv("DYNBENCH_CAPTURE_FPS") ? atof(getenv("DYNBENCH_CAPTURE_FPS")) : 50.0;
  g_db.total_frames = (int)(g_db.seconds * fps + 0.5);
  Q_strncpyz(g_db.follow, getenv("DYNBENCH_CAPTURE_FOLLOW") ? getenv("DYNBENCH_CAPTURE_FOLLOW") : "auto", sizeof(g_db.follow));
  g_db.follow_target = (g_db.follow[0] >= '0' && g_db.follow[0] <= '9') ? atoi(g_db.follow) : -1;
  g_db.owner_slot = UNOWNED_SLOT;
  /* the map: "maps/oa_dm1.bsp" */
  COM_StripExtension(COM_SkipPath(cgs.mapname), g_db.map, sizeof(g_db.map));
  Com_sprintf(g_db.world_path, sizeof(g_db.world_path), "maps/%s", g_db.map);
  /* the fixed clock: every frame advances the game by exactly 1/fps (a cheat cvar: devmap) */
  g_db.frame_ms = (int)(1000.0 / fps + 0.5);
  trap_Cvar_Set("fixedtime", va("%d", g_db.frame_ms));
  g_db.record = !getenv("DYNBENCH_CAPTURE_RECORD") || atoi(getenv("DYNBENCH_CAPTURE_RECORD")) != 0;
  g_db.pending_game_frame = -1;
  Com_sprintf(g_db.game_frames, sizeof(g_db.game_frames), ",%s,", getenv("DYNBENCH_CAPTURE_GAME_FRAMES") ? getenv("DYNBENCH_CAPTURE_GAME_FRAMES") : "");
  if (!g_db.record) {
    g_db.active = 1;
    return;
  }
  load_shader_scripts();
  if (!load_bsp()) {
    fprintf(stderr, "dynbench-capture: error: cannot read maps/%s.bsp\n", g_db.map);
    trap_SendConsoleCommand("quit\n");
    return;
  }
  /* before anything is written: a bad lights file leaves no capture behind */
  if (!load_map_lights(getenv("DYNBENCH_CAPTURE_MAP_LIGHTS"))) {
    trap_SendConsoleCommand("quit\n");
    return;
  }
  if (dbc_open(dir, "OpenArena 0.8.8 (ioquake3 1.36)", &g_db.session) != DBC_OK) {
    fprintf(stderr, "dynbench-capture: error: %s\n", dbc_last_error());
    trap_SendConsoleCommand("quit\n");
    return;
  }
  g_db.active = 1;
  const float origin[3] = {0, 0, 0};
  if (dbc_set_data_root(g_db.session, "data") != DBC_OK || dbc_set_metres_per_unit(g_db.session, 1.0f / 32.0f) != DBC_OK ||
      dbc_set_map(g_db.session, g_db.map, origin) != DBC_OK) {
    db_fail("settings");
    return;
  }
  g_db.camera_id = dbc_new_id(g_db.session);
  if (!record_bsp_model(0, g_db.world_path)) return;
  record_map_lighting();
  fprintf(stderr, "dynbench-capture: recording %d frames of %s after %.1f s\n", g_db.total_frames, g_db.map, g_db.warmup);
}

void dynbench_cg_shutdown(void) {
  if (g_db.session) {
    fprintf(stderr, "dynbench-capture: warning: the game ended after %d of %d frames\n", g_db.frame, g_db.total_frames);
    dbc_close(g_db.session);
    g_db.session = NULL;
  }
  g_db.active = 0;
  free(g_bsp.data);
  memset(&g_bsp, 0, sizeof(g_bsp));
  free(g_db.shaders);
  g_db.shaders = NULL;
}
