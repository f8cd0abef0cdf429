/* dynbench's OpenArena adapter: the map (world surfaces, brush models, the map's lighting) (dynbench_oa_internal.h lists the files). */
#include "dynbench_oa_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

int load_bsp(void) {
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

void free_bsp(void) {
  free(g_bsp.data);
  memset(&g_bsp, 0, sizeof(g_bsp));
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
int record_bsp_model(int index, const char* model_path) {
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
void record_map_lighting(void) {
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
