// dynbench capture adapter for Cube 2: Sauerbraten, compiled into the game's client with the
// engine sources (engine/dynbench_capture.cpp). It turns the engine's state into dynbench capture SDK calls
// (include/dynbench/capture.h, docs/capture-format.md).
//
// Environment (set by `dynbench capture cube2`):
//   DYNBENCH_CAPTURE_DIR      capture folder; capturing is off when unset
//   DYNBENCH_CAPTURE_FPS      fixed clock rate (default 60)
//   DYNBENCH_CAPTURE_SEED     seed of the game's random numbers (default 1)
//   DYNBENCH_CAPTURE_WARMUP   seconds of game time after the map loads before recording (default 2)
//   DYNBENCH_CAPTURE_SECONDS  seconds of game time recorded (default 30)
//   DYNBENCH_CAPTURE_VERIFY_FRAME  N: also write DIR/skinning_frame_N.txt, the engine's own skinned
//                             vertices of frame N (tests/cube2_test.cpp checks the dataset with it)
//   DYNBENCH_CAPTURE_FOLLOW_AUTO  1: when the followed bot dies, follow the next one (nextfollow)
//   DYNBENCH_CAPTURE_RECORD   0: run the same fixed-clock, seeded match without writing anything
//                             (bench/bench_capture.sh measures the capture's cost against it)
//
// Only the engine's containers here (vector, hashtable, string): its tools.h defines placement new,
// which clashes with the standard library's <new>.
//
// Coordinates: Cube 2 is Z-up, and its view matrix (engine/rendergl.cpp, `viewmatrix`) sends a
// world point (x, y, z) to eye space (-x, z, -y): +x is on the left when looking along +y. The
// capture format is Y-up and right-handed, so the adapter uses that same map,
// (x, y, z)_cube -> (-x, z, -y), which keeps what the player saw. Cube's yaw then becomes -yaw
// (it grows to the left along -x) and roll -roll; pitch (up positive) stays.
// Length unit: 8 Cube units to the metre, the Sauerbraten mappers' rule (the player's eyes are 14
// units, 1.75 m, above the ground).
#include "engine.h"

#include <cstdlib>
#include <unistd.h>

#include "dynbench/capture.h"
#include "dynbench_capture.h"

// The engine's clip planes (engine/rendergl.cpp), not in its headers.
extern float nearplane;
extern int farplane;

namespace {

struct CaptureState {
  bool enabled = false;
  double fps = 60.0;
  unsigned seed = 1;
  double warmupSeconds = 2.0, seconds = 30.0;
  long long clockFrames = 0;  // frames since the clock was fixed
  int clockBase = 1;
  dbc_session *session = nullptr;
  long long firstMapMillis = -1;  // lastmillis when the map was first seen loaded
  long long recorded = 0;         // frames recorded
  uint64_t cameraId = 0;
  bool done = false;
  bool record = true;
  long long verifyFrame = -1;
  vector<long long> gameFrames;  // recorded frames whose image the game keeps (DYNBENCH_CAPTURE_GAME_FRAMES)
  bool followAuto = false;
  string directory = "";
  Uint32 windowStart = 0;  // wall clock when the capture window opened (SDL milliseconds)
  int lastFollowLife = -1;  // dynbench_followlife of the last recorded frame
  vec lastCameraPosition = vec(0, 0, 0);
};

CaptureState state;

double envNumber(const char *name, double fallback) {
  const char *v = std::getenv(name);
  if (!v || !*v) return fallback;
  char *end = nullptr;
  const double d = std::strtod(v, &end);
  return end && *end == '\0' ? d : fallback;
}

void failCapture(const char *what) {
  conoutf("\f3dynbench capture: %s: %s", what, dbc_last_error());
  fprintf(stderr, "dynbench capture: %s: %s\n", what, dbc_last_error());
  if (state.session) dbc_close(state.session);
  state.session = nullptr;
  state.done = true;
  exit(EXIT_FAILURE);
}

// The window is over and the capture closed: leave at once. The engine's own shutdown (quit:
// disconnecting the bots, saving a config to the throwaway home, tearing down SDL and software
// OpenGL under Xvfb) adds nothing to the capture and has hung for minutes under load after it.
void finishCapture() {
  fflush(stdout);
  fflush(stderr);
  _exit(EXIT_SUCCESS);
}

void toCapture(const vec &cube, float out[3]) {
  out[0] = -cube.x;
  out[1] = cube.z;
  out[2] = -cube.y;
}

// A mesh of the map model being gathered: capture-space positions and normals, texture coordinates.
struct SurfaceMesh {
  vector<float> positions, normals, uvs;
  vector<uint> indices;
};

// The map's geometry, as the engine's own writeobj (engine/worldio.cpp) walks it: every vertex
// array, its index ranges per texture slot. One capture mesh per texture slot, with positions and
// normals in capture space, texture coordinates as the engine has them (v down, as glTF) and the
// slot's first texture relative to the data root.
struct MapMesh : SurfaceMesh {
  int slot = -1;
};

// The SDK's record of a map surface mesh (texture "" for none); the arrays stay the mesh's.
dbc_mesh surfaceRecord(int meshId, const char *name, const char *texture, const SurfaceMesh &mesh) {
  dbc_mesh m = {};
  m.mesh_id = meshId;
  m.name = name;
  m.texture = texture[0] ? texture : nullptr;
  m.vertex_count = size_t(mesh.positions.length() / 3);
  m.positions = mesh.positions.getbuf();
  m.normals = mesh.normals.getbuf();
  m.uvs = mesh.uvs.getbuf();
  m.triangle_count = size_t(mesh.indices.length() / 3);
  m.indices = mesh.indices.getbuf();
  return m;
}

// A texture slot's file relative to the data root. Texture commands prefix load options such as
// <dds> or <mad:...>: the file name follows them.
void texturePath(const char *name, string &out) {
  const char *file = name;
  while (*file == '<') {
    const char *end = strchr(file, '>');
    if (!end) break;
    file = end + 1;
  }
  formatstring(out, "packages/%s", file);
}

// Water and lava are material volumes, not world geometry: the engine draws their visible faces
// (engine/material.cpp, water.cpp) and the capture records them as surfaces of the map, one mesh
// per material and side (top or falls), with the material the engine gives them:
// - top faces lie WATER_OFFSET below the volume's top, as renderflatwater draws them (the engine's
//   waves, WATER_AMPLITUDE about that, are not recorded); the falls' top and bottom edges move as
//   renderwaterfall moves them at the waves' mean;
// - lava is drawn unlit, texture x 2t with t pulsing between 0.5 and 1 (its shader, material.cpp):
//   emission 1.5, the pulse's mean, times its texture, in full-light units; texture coordinates are
//   the shader's world-space projection (TEX_SCALE / (texture size x slot scale)) without its scroll;
// - water is the engine's reflecting, refracting surface tinted by its colour (watercolour): a
//   smooth opaque dielectric of that colour (the floor seen through it, fogged, is not recorded).
// Bottom faces, which the engine does not draw, and faces only the editor shows are left out.
struct MaterialMesh : SurfaceMesh {
  int material = 0;  // MAT_WATER or MAT_LAVA with its index (water2...)
  bool top = true;
};

void addMaterialFace(vector<MaterialMesh *> &meshes, const materialsurface &m) {
  const bool top = m.orient == O_TOP;
  MaterialMesh *mesh = nullptr;
  loopv(meshes) if (meshes[i]->material == m.material && meshes[i]->top == top) mesh = meshes[i];
  if (!mesh) {
    mesh = new MaterialMesh;
    mesh->material = m.material;
    mesh->top = top;
    meshes.add(mesh);
  }
  vec corners[4];
  if (top) {
    const float z = m.o.z - WATER_OFFSET;
    corners[0] = vec(m.o.x, m.o.y, z);
    corners[1] = vec(m.o.x + m.rsize, m.o.y, z);
    corners[2] = vec(m.o.x + m.rsize, m.o.y + m.csize, z);
    corners[3] = vec(m.o.x, m.o.y + m.csize, z);
  } else {
    // renderwaterfall's corners (GENFACEVERTSXY), its waves at their mean.
    const float x = m.o.x, y = m.o.y, offset = 0.1f;
    float zmin = m.o.z, zmax = zmin;
    if (m.ends & 1) zmin += -WATER_OFFSET - WATER_AMPLITUDE;
    if (m.ends & 2) zmax += -WATER_OFFSET;
    const int csize = m.csize, rsize = m.rsize;
    int n = 0;
    switch (m.orient) {
#define GENFACEORIENT(orient, v0, v1, v2, v3) \
  case orient: v0 v1 v2 v3 break;
#define GENFACEVERT(orient, vert, mx, my, mz, sx, sy, sz) corners[n++] = vec(mx sx, my sy, mz sz);
      GENFACEVERTSXY(x, x, y, y, zmin, zmax, /**/, +csize, /**/, +rsize, +offset, -offset)
#undef GENFACEORIENT
#undef GENFACEVERT
      default: return;
    }
  }
  // Texture coordinates: the lava shader's projection, tc = mix(xz, yy, |n.xz|) (top: xy).
  MSlot &slot = lookupmaterialslot(m.material, true);
  const int sub = top ? 0 : 1;
  Texture *t = slot.sts.inrange(sub) ? slot.sts[sub].t : nullptr;
  const float scale = slot.scale > 0 ? slot.scale : 1.0f;
  const float su = t && t->xs > 0 ? TEX_SCALE / (t->xs * scale) : 1.0f / 64, sv = t && t->ys > 0 ? TEX_SCALE / (t->ys * scale) : 1.0f / 64;
  const int dim = dimension(m.orient);
  const uint base = uint(mesh->positions.length() / 3);
  vec outward(0, 0, 0);
  outward[dim] = dimcoord(m.orient) ? 1 : -1;
  float normal[3];
  toCapture(outward, normal);
  loopi(4) {
    float p[3];
    toCapture(corners[i], p);
    loopk(3) mesh->positions.add(p[k]);
    loopk(3) mesh->normals.add(normal[k]);
    const vec &c = corners[i];
    const float u = top ? c.x : dim == 0 ? c.y : c.x, v = top ? c.y : c.z;
    mesh->uvs.add(u * su);
    mesh->uvs.add(top ? v * sv : -v * sv);
  }
  // Two triangles, wound counter-clockwise seen from the outward side (glTF's front).
  float a[3], b[3], c[3];
  toCapture(corners[0], a);
  toCapture(corners[1], b);
  toCapture(corners[2], c);
  const vec e1(b[0] - a[0], b[1] - a[1], b[2] - a[2]), e2(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
  vec cross;
  cross.cross(e1, e2);
  const bool ccw = cross.dot(vec(normal[0], normal[1], normal[2])) > 0;
  const uint order[6] = {0, 1, 2, 0, 2, 3};
  loopi(6) mesh->indices.add(base + (ccw ? order[i] : order[5 - i]));
}

void collectMaterialFaces(vector<MaterialMesh *> &meshes) {
  loopv(valist) {
    const vtxarray &va = *valist[i];
    loopj(va.matsurfs) {
      const materialsurface &m = va.matbuf[j];
      const int volume = m.material & MATF_VOLUME;
      if ((volume != MAT_WATER && volume != MAT_LAVA) || m.visible != MATSURF_VISIBLE || m.orient == O_BOTTOM) continue;
      addMaterialFace(meshes, m);
    }
  }
}

// A material surface's mesh: its texture (lava) or colour (water) and emission.
bool writeMaterialMesh(int meshId, const MaterialMesh &mesh) {
  const bool lava = (mesh.material & MATF_VOLUME) == MAT_LAVA;
  MSlot &slot = lookupmaterialslot(mesh.material, true);
  const int sub = mesh.top ? 0 : 1;
  string texture = "";
  if (lava && slot.sts.inrange(sub)) texturePath(slot.sts[sub].name, texture);
  defformatstring(name, "%s%s", lava ? "lava" : "water", mesh.top ? "" : "fall");
  dbc_mesh m = surfaceRecord(meshId, name, texture, mesh);
  const float lavaEmission[3] = {1.5f, 1.5f, 1.5f};
  const float smooth[2] = {0.0f, 0.05f};
  float colour[4] = {1, 1, 1, 1};
  if (lava) {
    m.emission = lavaEmission;
    m.emission_texture = m.texture;
  } else {
    // The engine's colours are 8-bit sRGB values: linear for the capture.
    const bvec &c = getwatercolor(mesh.material);
    loopk(3) {
      const float v = c[k] / 255.0f;
      colour[k] = v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
    }
    m.base_color = colour;
    m.metallic_roughness = smooth;
  }
  return dbc_model_mesh(state.session, &m) == DBC_OK;
}

void exportMap(const char *map) {
  vector<MapMesh *> meshes;
  auto meshFor = [&](int slot) -> MapMesh & {
    loopv(meshes) if (meshes[i]->slot == slot) return *meshes[i];
    MapMesh *m = new MapMesh;
    m->slot = slot;
    meshes.add(m);
    return *m;
  };
  loopv(valist) {
    vtxarray &va = *valist[i];
    ushort *edata = nullptr;
    vertex *vdata = nullptr;
    if (!readva(&va, edata, vdata)) continue;
    // The vertex buffer holds each normal as signed bytes: genverts (engine/octarender.cpp) flips
    // the sign bit of the engine's bvec (x * 255/2 + 127.5). Surfaces the engine lights only from
    // lightmaps get the placeholder (0, 0, 1) there, whatever their orientation (gencubeverts);
    // those take their triangle's face normal, which for the map's flat cube faces is the normal.
    const bvec placeholder(128, 128, 255);
    // Per vertex array and slot, each engine vertex becomes one mesh vertex per distinct normal.
    vector<int> *remap = new vector<int>[va.verts];
    ushort *idx = edata;
    loopj(va.texs) {
      elementset &es = va.eslist[j];
      MapMesh &mesh = meshFor(es.texture);
      loopk(va.verts) remap[k].setsize(0);
      for (int k = 0; k + 2 < es.length[1]; k += 3) {
        float corner[3][3];
        loopl(3) toCapture(vdata[idx[k + l] - va.voffset].pos, corner[l]);
        // Engine order winds clockwise seen from the front in capture space: the front normal is
        // (c - a) x (b - a).
        vec e1(corner[2][0] - corner[0][0], corner[2][1] - corner[0][1], corner[2][2] - corner[0][2]);
        vec e2(corner[1][0] - corner[0][0], corner[1][1] - corner[0][1], corner[1][2] - corner[0][2]);
        vec face;
        face.cross(e1, e2);
        const float area = face.magnitude();
        face = area > 0 ? face.div(area) : vec(0, 1, 0);
        loopl(3) {
          const int n = idx[k + l] - va.voffset;
          const vertex &v = vdata[n];
          bvec stored(v.norm.x, v.norm.y, v.norm.z);
          stored.flip();
          float engineNormal[3];
          toCapture(stored.tonormal(), engineNormal);
          vec normal(engineNormal[0], engineNormal[1], engineNormal[2]);
          const float length = normal.magnitude();
          const bool usable = stored != placeholder && length > 0 && normal.dot(face) > 0;
          normal = usable ? normal.div(length) : face;
          int index = -1;
          for (int m = 0; m < remap[n].length(); m++) {
            const int candidate = remap[n][m];
            const vec existing(mesh.normals[3 * candidate], mesh.normals[3 * candidate + 1], mesh.normals[3 * candidate + 2]);
            if (existing.dot(normal) > 0.9999f) {
              index = candidate;
              break;
            }
          }
          if (index < 0) {
            index = mesh.positions.length() / 3;
            remap[n].add(index);
            for (int c = 0; c < 3; c++) {
              mesh.positions.add(corner[l][c]);
              mesh.normals.add(normal[c]);
            }
            mesh.uvs.add(v.tc.x);
            mesh.uvs.add(v.tc.y);
          }
          mesh.indices.add(uint(index));
        }
      }
      idx += es.length[1];
    }
    delete[] remap;
    delete[] edata;
    delete[] vdata;
  }
  if (dbc_model_begin(state.session, map) != DBC_OK) failCapture("map model");
  int meshId = 0;
  loopv(meshes) {
    MapMesh &mesh = *meshes[i];
    if (mesh.indices.length() < 3) continue;
    // The engine draws with glFrontFace(GL_CW): in eye space, which the capture space is, front faces
    // wind clockwise; glTF's wind counter-clockwise, so two corners of every triangle swap.
    for (int t = 0; t + 2 < mesh.indices.length(); t += 3) swap(mesh.indices[t + 1], mesh.indices[t + 2]);
    VSlot &vslot = lookupvslot(mesh.slot, false);
    string texture = "";
    if (vslot.slot && !vslot.slot->sts.empty()) texturePath(vslot.slot->sts[0].name, texture);
    defformatstring(name, "slot%d", mesh.slot);
    const dbc_mesh m = surfaceRecord(meshId++, name, texture, mesh);
    if (dbc_model_mesh(state.session, &m) != DBC_OK) failCapture("map mesh");
  }
  meshes.deletecontents();
  vector<MaterialMesh *> materials;
  collectMaterialFaces(materials);
  loopv(materials) if (!writeMaterialMesh(meshId++, *materials[i])) failCapture("water or lava mesh");
  materials.deletecontents();
  if (dbc_model_end(state.session) != DBC_OK) failCapture("map model end");
}

// The map's lighting variables (engine/lightmap.cpp), in the lights' units (255 = 1): the lightmap
// of a surface is max(ambient, sky light x the share of 17 sky rays that escape, sum over lights
// of colour x (1 - d / radius) x cos + sun x cos), clamped to 255 (generatelumel, calcskylight).
void recordMapLighting() {
  float direction[3];
  toCapture(sunlightdir, direction);
  const float sun[3] = {sunlightcolor.x * sunlightscale / 255.0f, sunlightcolor.y * sunlightscale / 255.0f, sunlightcolor.z * sunlightscale / 255.0f};
  const float ambient[3] = {ambientcolor.x / 255.0f, ambientcolor.y / 255.0f, ambientcolor.z / 255.0f};
  const float sky[3] = {skylightcolor.x / 255.0f, skylightcolor.y / 255.0f, skylightcolor.z / 255.0f};
  if (dbc_set_lighting(state.session, direction, sun, ambient, sky) != DBC_OK) failCapture("map lighting");
}

// Map lights (ET_LIGHT entities: attr1 radius, 0 for none, attr2-4 colour 0-255): static, written once.
void recordStaticLights() {
  const vector<extentity *> &ents = entities::getents();
  loopv(ents) {
    const extentity &e = *ents[i];
    if (e.type != ET_LIGHT) continue;
    float position[3];
    toCapture(e.o, position);
    const float rgb[3] = {e.attr2 / 255.0f, e.attr3 / 255.0f, e.attr4 / 255.0f};
    if (dbc_light(state.session, dbc_new_id(state.session), position, rgb, float(max(0, int(e.attr1))), DBC_FALLOFF_LINEAR, DBC_LIGHT_POINT, 0, "none") != DBC_OK)
      failCapture("static light");
  }
}

// Dynamic lights (engine/dynlight.cpp) this frame, classified by how the game makes them
// (fpsgame/weapon.cpp): DL_FLASH is a muzzle flash; a fading light is an explosion; a light that
// lives one frame follows a projectile: rockets make radius-20 lights, grenades smaller ones.
//
// Identity. The engine keeps no id for a dynamic light, so one is inferred from the previous
// recorded frame, as dynbench_models.h does for parts:
// - a light with a life span (flash, explosion: fade + peak > 0) stays one queue entry until it
//   expires; the same owner, expiry, flags, fade, peak and base colour is the same light (a muzzle
//   flash follows its owner's gun, so its position may change);
// - a light re-added every frame (a projectile's) is the nearest unclaimed light of the previous
//   frame with the same flags and base colour, within kDynbenchMaxStepUnits.
// So a rocket's light is one light that moves and then disappears, and a muzzle flash one per shot.
struct RecordedLight {
  dynbench_dynlight light;
  uint64_t id;
};
vector<RecordedLight> previousLights, currentLights;
vector<bool> claimedLights;

bool sameLife(const dynbench_dynlight &a, const dynbench_dynlight &b) {
  return a.owner == b.owner && a.expire == b.expire && a.flags == b.flags && a.fade == b.fade && a.peak == b.peak && a.basecolor == b.basecolor;
}

uint64_t dynamicLightId(const dynbench_dynlight &d) {
  const bool lifeSpan = d.fade + d.peak > 0;
  int best = -1;
  float bestDistance = kDynbenchMaxStepUnits;
  loopv(previousLights) {
    if (claimedLights[i]) continue;
    const dynbench_dynlight &p = previousLights[i].light;
    if (lifeSpan) {
      if (sameLife(p, d)) { best = i; break; }
      continue;
    }
    if (p.fade + p.peak > 0 || p.flags != d.flags || !(p.basecolor == d.basecolor)) continue;
    const float distance = p.o.dist(d.o);
    if (distance < bestDistance) { bestDistance = distance; best = i; }
  }
  if (best < 0) return dbc_new_id(state.session);
  claimedLights[best] = true;
  return previousLights[best].id;
}

void recordDynamicLight(const dynbench_dynlight &d) {
  float position[3];
  toCapture(d.o, position);
  const float rgb[3] = {d.color.x, d.color.y, d.color.z};
  const bool fading = d.fade + d.peak > 0;
  const char *type = (d.flags & DL_FLASH) ? "flash" : fading ? "explosion" : d.radius >= 16 ? "rocket" : "bouncer";
  RecordedLight recorded;
  recorded.light = d;
  recorded.id = dynamicLightId(d);
  currentLights.add(recorded);
  if (dbc_light(state.session, recorded.id, position, rgb, max(0.0f, d.radius), DBC_FALLOFF_QUADRATIC, DBC_LIGHT_POINT, 1, type) != DBC_OK) failCapture("dynamic light");
}

void recordDynamicLights() {
  claimedLights.setsize(0);
  loopv(previousLights) claimedLights.add(false);
  currentLights.setsize(0);
  dynbench_visit_dynlights(recordDynamicLight);
  previousLights = currentLights;
}

// Camera cuts: the camera's transform this frame does not continue the previous frame's when the
// followed player changed ("switch"), died (the view becomes the game's death camera: "death"),
// got a new life ("respawn", the game's lifesequence), or the camera moved further than
// kDynbenchMaxStepUnits in one frame ("teleport": teleporters, jump pads at low frame rates).
// dynbench_followlife (the patch, fpsgame/fps.cpp) is clientnum*256 + lifesequence*2 + dead.
const char *cameraCut(const vec &position) {
  const int followLife = execute("dynbench_followlife");
  const int last = state.lastFollowLife;
  const char *reason = nullptr;
  if (state.recorded > 0) {
    if (followLife < 0 || last < 0 || followLife / 256 != last / 256) {
      if (followLife != last) reason = "switch";
    } else if (followLife / 2 != last / 2) {
      reason = "respawn";
    } else if (followLife != last) {
      reason = "death";
    }
    if (!reason && position.dist(state.lastCameraPosition) > kDynbenchMaxStepUnits) reason = "teleport";
  }
  state.lastFollowLife = followLife;
  state.lastCameraPosition = position;
  return reason;
}

// The game's own image of a recorded frame, for `dynbench fidelity` (docs/fidelity.md): the colour
// the game drew (8-bit sRGB, as PPM) and its depth buffer turned into view depth in capture units
// (PFM, 0 where the sky is), read back before the frame is shown. The depth buffer holds
// z_ndc = 2 d - 1 of OpenGL's perspective (engine/rendergl.cpp: projmatrix.perspective with
// nearplane and farplane), so view depth = 2 f n / (f + n - z_ndc (f - n)).
void writeGameFrame(long long frame) {
  const int w = screenw, h = screenh;
  vector<uchar> rgb;
  rgb.setsize(0);
  loopi(w * h * 3) rgb.add(0);
  vector<float> depth;
  loopi(w * h) depth.add(0.0f);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb.getbuf());
  glReadPixels(0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, depth.getbuf());
  const float n = nearplane, f = float(farplane);
  loopi(w * h) {
    const float d = depth[i];
    depth[i] = d >= 1.0f ? 0.0f : 2.0f * f * n / (f + n - (2.0f * d - 1.0f) * (f - n));
  }
  defformatstring(folder, "%s/game", state.directory);
  createdir(folder);
  // PPM rows run top to bottom, OpenGL's bottom to top; PFM's bottom to top, as OpenGL's.
  defformatstring(colourPath, "%s/frame_%05lld.ppm", folder, frame);
  defformatstring(depthPath, "%s/frame_%05lld_depth.pfm", folder, frame);
  FILE *c = fopen(colourPath, "wb"), *z = fopen(depthPath, "wb");
  if (!c || !z) failCapture("game frame");
  fprintf(c, "P6\n%d %d\n255\n", w, h);
  for (int y = h - 1; y >= 0; --y) fwrite(&rgb[y * w * 3], 1, w * 3, c);
  fprintf(z, "Pf\n%d %d\n-1.0\n", w, h);
  fwrite(depth.getbuf(), sizeof(float), w * h, z);
  if (fclose(c) != 0 || fclose(z) != 0) failCapture("game frame");
}

// One rendered frame with the map loaded: exports the map first, records inside the window.
void recordFrame(const char *map) {
  if (state.firstMapMillis < 0) {
    state.firstMapMillis = lastmillis;
    if (!state.record) return;
    // The camera's lens: the engine's horizontal field of view and the window's aspect ratio.
    const float aspectRatio = float(screenw) / float(max(screenh, 1));
    const float yfov = 2.0f * atan(tan(curfov * 0.5f * RAD) / aspectRatio) / RAD;
    if (dbc_set_camera_settings(state.session, aspectRatio, yfov, nearplane, float(farplane)) != DBC_OK) failCapture("camera settings");
    const float offset[3] = {0, 0, 0};
    if (dbc_set_map(state.session, map, offset) != DBC_OK) failCapture("map");
    recordMapLighting();
    exportMap(map);
  }
  if (lastmillis - state.firstMapMillis < static_cast<long long>(state.warmupSeconds * 1000.0)) {
    dynbench_models_next_frame(false);
    return;
  }
  if (state.recorded == 0) state.windowStart = SDL_GetTicks();
  if (!state.record) {
    ++state.recorded;
    if (static_cast<double>(state.recorded) >= state.seconds * state.fps) {
      printf("dynbench-capture: window of %lld frames took %u ms of wall time (not recorded)\n", state.recorded, SDL_GetTicks() - state.windowStart);
      finishCapture();
    }
    return;
  }
  const double time = static_cast<double>(state.recorded) / state.fps;
  const bool firstFrame = state.recorded == 0;
  if (firstFrame && !dynbench_models_capture_static(state.session)) failCapture("map models");
  if (!dynbench_models_export(state.session)) failCapture("models");
  if (dbc_frame_begin(state.session, static_cast<uint64_t>(state.recorded), time) != DBC_OK) failCapture("frame");
  float position[3];
  toCapture(camera1->o, position);
  if (dbc_camera(state.session, state.cameraId, position, camera1->pitch, -camera1->yaw, -camera1->roll) != DBC_OK) failCapture("camera");
  if (const char *cut = cameraCut(camera1->o))
    if (dbc_camera_cut(state.session, state.cameraId, cut) != DBC_OK) failCapture("camera cut");
  if (firstFrame) recordStaticLights();
  if (!dynbench_models_write(state.session, firstFrame)) failCapture("model instances");
  if (state.gameFrames.find(state.recorded) >= 0) writeGameFrame(state.recorded);
  if (state.recorded == state.verifyFrame) {
    defformatstring(path, "%s/skinning_frame_%lld.txt", state.directory, state.recorded);
    if (!dynbench_models_write_verification(path)) failCapture("skinning verification file");
  }
  recordDynamicLights();
  if (dbc_frame_end(state.session) != DBC_OK) failCapture("frame end");
  dynbench_models_next_frame(true);
  ++state.recorded;
  const long long total = static_cast<long long>(state.seconds * state.fps + 0.5);
  // One line per second of game time for `dynbench capture cube2`'s progress.
  if (state.recorded % max(1, int(state.fps)) == 0 || state.recorded >= total) {
    printf("dynbench-capture: %lld/%lld frames, %d models drawn\n", state.recorded, total, dynbench_models_count());
    fflush(stdout);
  }
  if (state.recorded >= total) {
    if (dbc_close(state.session) != DBC_OK) failCapture("close");
    printf("dynbench-capture: window of %lld frames took %u ms of wall time (recorded)\n", state.recorded, SDL_GetTicks() - state.windowStart);
    state.session = nullptr;
    finishCapture();
  }
}

}  // namespace

void dynbench_capture_init() {
  const char *dir = std::getenv("DYNBENCH_CAPTURE_DIR");
  if (!dir || !*dir) return;
  state.enabled = true;
  state.fps = envNumber("DYNBENCH_CAPTURE_FPS", 60.0);
  if (!(state.fps > 0 && state.fps <= 1000)) state.fps = 60.0;
  state.seed = static_cast<unsigned>(envNumber("DYNBENCH_CAPTURE_SEED", 1.0));
  state.warmupSeconds = envNumber("DYNBENCH_CAPTURE_WARMUP", 2.0);
  state.seconds = envNumber("DYNBENCH_CAPTURE_SECONDS", 30.0);
  state.record = envNumber("DYNBENCH_CAPTURE_RECORD", 1.0) != 0.0;
  state.verifyFrame = static_cast<long long>(envNumber("DYNBENCH_CAPTURE_VERIFY_FRAME", -1.0));
  state.followAuto = envNumber("DYNBENCH_CAPTURE_FOLLOW_AUTO", 0.0) != 0.0;
  if (const char *list = std::getenv("DYNBENCH_CAPTURE_GAME_FRAMES"))
    for (const char *p = list; *p;) {
      char *end = nullptr;
      const long long k = std::strtoll(p, &end, 10);
      if (end == p) break;
      state.gameFrames.add(k);
      p = *end == ',' ? end + 1 : end;
    }
  // The game's own frames are compared with renders of the world: no HUD over them, and none of
  // the text the game floats in the world (players' names, damage numbers: particletext; status
  // icons and bars above players).
  if (state.gameFrames.length()) {
    execute("hidehud 1");
    execute("particletext 0");
    execute("statusicons 0");
    execute("statusbars 0");
  }
  copystring(state.directory, dir);
  seedMT(state.seed);
  // Occlusion queries answer when the GPU gets to them, not at a fixed frame: what is drawn, and
  // so where a muzzle flash starts (a model tag), would vary from run to run. Off while capturing.
  execute("oqfrags 0");
  // The first-person gun is a screen overlay, not part of the world, and the muzzle position the
  // game takes from it depends on that frame's overlay rendering; without it the game places
  // muzzle flashes and grenades from the player's body, as it does for every other player.
  execute("hudgun 0");
  // No sound. A sound the game plays draws from the game's random numbers (an alternative sample,
  // engine/sound.cpp's chooseslot), and only when the machine has a working audio device (with
  // none, playsound returns first); channels are freed when the device has played them, in real
  // time. So the bots' dice, and with them the match, depended on the machine's audio: the same
  // seed gave 9 cuts without a device and 8 with SDL's dummy driver (issue 45). With the volume 0
  // playsound returns before choosing, whatever the machine has.
  execute("soundvol 0");
  // Debian's cube2-data ships one player model, snoutx10k (1); bots otherwise pick models at random
  // from five and are not drawn when theirs is missing.
  execute("playermodel 1");
  execute("forceplayermodels 1");
  if (!state.record) return;
  if (dbc_open(dir, "Cube 2: Sauerbraten 2020-12-27 (Debian cube2 0.0.20201227+dfsg)", &state.session) != DBC_OK)
    failCapture("cannot open the capture folder");
  const char *dataRoot = std::getenv("DYNBENCH_CAPTURE_DATA_ROOT");
  if (dbc_set_metres_per_unit(state.session, 0.125f) != DBC_OK ||
      (dataRoot && *dataRoot && dbc_set_data_root(state.session, dataRoot) != DBC_OK))
    failCapture("settings");
  state.cameraId = dbc_new_id(state.session);
}

bool dynbench_capture_fixed_clock() { return state.enabled; }

int dynbench_capture_clock_millis() {
  // Frame k is at exactly k / fps seconds; the engine's integer milliseconds round to it.
  return state.clockBase + static_cast<int>(static_cast<double>(state.clockFrames) * 1000.0 / state.fps + 0.5);
}

// Entities numbered in order of first appearance. A deleted entity's slot is cleared
// (dynbench_capture_forget_entity): the allocator may give its address to a later entity (a ragdoll
// is a copy of the dead player, made at respawn), and whether it does depends on the heap, which
// other threads share, so a reused address must not inherit the old number.
static vector<const void *> seenEntities;  // a few dozen players and ragdolls: a linear search is enough

unsigned dynbench_capture_entity_seed(const void *entity) {
  if (!entity) return 0;
  int index = seenEntities.find(entity);
  if (index < 0) {
    index = seenEntities.length();
    seenEntities.add(entity);
  }
  return (uint(index) + 1u) * 2654435761u;  // Knuth's multiplicative hash spreads the low bits
}

void dynbench_capture_forget_entity(const void *entity) {
  if (!state.enabled || !entity) return;
  const int index = seenEntities.find(entity);
  if (index >= 0) seenEntities[index] = nullptr;
  dynbench_models_forget_owner(entity);
}

bool dynbench_capture_recording() { return state.enabled && state.record && state.session && !state.done && state.firstMapMillis >= 0; }

void dynbench_capture_frame() {
  if (!state.enabled || state.done) return;
  ++state.clockFrames;
  const char *map = game::getclientmap();
  if (!map || !*map || !camera1) return;
  recordFrame(map);
  // As a spectator would: when the followed bot dies, follow the next one from the next frame on.
  if (state.followAuto && !state.done && execute("dynbench_followdead")) execute("nextfollow 1");
}