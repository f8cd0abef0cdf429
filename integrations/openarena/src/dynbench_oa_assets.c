/* dynbench's OpenArena adapter: the game's file system, the shader scripts, the mesh builder (dynbench_oa_internal.h lists the files). */
#include "dynbench_oa_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---------------------------------------------------------------------------------------------- */
/* small helpers */

static uint32_t hash_string(const char* s) {
  uint32_t h = 2166136261u;
  for (; *s; ++s) h = (h ^ (uint32_t)(unsigned char)tolower((unsigned char)*s)) * 16777619u;
  return h;
}

int make_directories(const char* path) { /* mkdir -p of path's parent directories */
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
char* read_game_file(const char* path, int* length) {
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

shader_info_t* shader_slot(const char* name, int create) {
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
void load_shader_scripts(void) {
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
const char* shader_texture(const char* shader_name) {
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


/* Gives the SDK a built mesh of the model being recorded; 0 when it refuses. */
int record_mesh(int mesh_id, const char* name, const char* texture, const mesh_builder_t* m, const float* emission) {
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

void mesh_free(mesh_builder_t* m) {
  free(m->positions); free(m->normals); free(m->uvs); free(m->indices);
  memset(m, 0, sizeof(*m));
}
