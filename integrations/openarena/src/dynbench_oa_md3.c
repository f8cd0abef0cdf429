/* dynbench's OpenArena adapter: MD3 models (dynbench_oa_internal.h lists the files). */
#include "dynbench_oa_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
int record_md3(const char* file, const char* skin, const char* model_path) {
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
