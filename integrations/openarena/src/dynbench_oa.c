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
#include "dynbench_oa_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <GL/gl.h>

dynbench_oa_state_t g_db;

/* ---------------------------------------------------------------------------------------------- */
/* the state */

void db_fail(const char* what) {
  fprintf(stderr, "dynbench-capture: error: %s: %s\n", what, dbc_last_error());
  fflush(stderr);
  g_db.active = 0;
  trap_SendConsoleCommand("quit\n");
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

/* Before the match: whether recording has started. How many frames the client takes to connect
 * and load depends on the machine's load, and the client shares the C library's random numbers
 * with the game and the bots (native modules in one process), so a match that ran while the client
 * connected would differ from run to run. The client joins as a spectator (userinfo team s) of an
 * empty level; at a fixed server time the adapter restarts the level (map_restart 0: the game
 * module re-seeds from DYNBENCH_CAPTURE_SEED, the client stays connected, and the game module adds
 * the bots of DYNBENCH_CAPTURE_BOTS in the same command pass): the match starts in the same engine
 * frame, with the same random numbers, on every run. Recording starts at a fixed time after it.
 * (Bots added from here, a frame after this module saw the restart, joined a frame apart from run
 * to run; so does the moment the server starts answering `follow`.) */
static int match_started(void) {
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
    return 0;
  }
  const int following = ensure_following();
  if (!g_db.started) {
    if (!following || cg.time < cgs.levelStartTime + (int)(g_db.warmup * 1000)) {
      if (cg.time > cgs.levelStartTime + (int)(g_db.warmup * 1000) + 20000) {
        fprintf(stderr, "dynbench-capture: error: not following a bot 20 s after the warm-up (is one in the game?)\n");
        g_db.active = 0;
        trap_SendConsoleCommand("quit\n");
      }
      return 0;
    }
    g_db.started = 1;
    g_db.start_time = cg.time;
    g_db.window_start = trap_Milliseconds(); /* the machine's clock: this is the one place it is read */
    printf("dynbench-capture: level started at %d ms of server time, recording from %d\n", cgs.levelStartTime, cg.time);
  }
  return 1;
}

/* A window played without recording (DYNBENCH_CAPTURE_RECORD=0, the overhead benchmark): counts
 * the frame and quits after the last. */
static void count_unrecorded_frame(void) {
  printf("dynbench-capture: %d/%d frames\n", ++g_db.frame, g_db.total_frames);
  if (g_db.frame >= g_db.total_frames) {
    printf("dynbench-capture: window of %d frames took %d ms of wall time (not recorded)\n", g_db.frame, trap_Milliseconds() - g_db.window_start);
    fflush(stdout);
    g_db.active = 0;
    trap_SendConsoleCommand("quit\n");
  }
}

/* The capture's lens is set once, before the first frame. The view's field of view can change
 * later (CG_CalcFov waves it while the followed player is under water, and zooms): the capture
 * keeps the first, and says so once. 0 on failure. */
static int record_lens(dbc_session* s, const refdef_t* view) {
  if (!g_db.last_camera_width) {
    g_db.last_camera_width = view->width;
    g_db.last_camera_height = view->height;
    g_db.camera_fov = view->fov_y;
    if (dbc_set_camera_settings(s, (float)view->width / (float)view->height, view->fov_y, 4.0f, 16384.0f) != DBC_OK) { db_fail("camera settings"); return 0; }
  } else if (!g_db.fov_change_reported && (view->width != g_db.last_camera_width || view->height != g_db.last_camera_height || view->fov_y != g_db.camera_fov)) {
    g_db.fov_change_reported = 1;
    fprintf(stderr, "dynbench-capture: note: the view's field of view changed at frame %d (%.3f to %.3f degrees, under water or zoomed); the capture keeps the first\n",
            g_db.frame, g_db.camera_fov, view->fov_y);
  }
  return 1;
}

/* The frame's camera, and a cut where the view jumped: another player followed, a respawn or a
 * teleporter (the game toggles EF_TELEPORT_BIT when the view's origin jumps), or a jump the game
 * did not mark. 0 on failure. */
static int record_camera(dbc_session* s, const refdef_t* view, const playerState_t* ps, int dead) {
  float position[3], pitch, yaw, roll;
  to_capture(view->vieworg, position);
  camera_angles(view, &pitch, &yaw, &roll);
  if (dbc_camera(s, g_db.camera_id, position, pitch, yaw, roll) != DBC_OK) { db_fail("camera"); return 0; }
  const int teleport = ps->eFlags & EF_TELEPORT_BIT;
  if (g_db.have_last) {
    const float dx = position[0] - g_db.last_position[0], dy = position[1] - g_db.last_position[1], dz = position[2] - g_db.last_position[2];
    const char* reason = NULL;
    if (ps->clientNum != g_db.last_client) reason = "switch";
    else if (teleport != g_db.last_teleport) reason = g_db.last_dead ? "respawn" : "teleport";
    else if (dx * dx + dy * dy + dz * dz > 64.0f * 64.0f) reason = "teleport";
    if (reason && dbc_camera_cut(s, g_db.camera_id, reason) != DBC_OK) { db_fail("camera cut"); return 0; }
  }
  g_db.have_last = 1;
  g_db.last_client = ps->clientNum;
  g_db.last_teleport = teleport;
  g_db.last_dead = dead;
  memcpy(g_db.last_position, position, sizeof(position));
  return 1;
}

/* The first frame's world model and the map's static lights. 0 on failure. */
static int record_world(dbc_session* s) {
  const dbc_dual_quat identity_pose = {0, 0, 0, 1, 0, 0, 0, 0};
  if (dbc_static_model(s, dbc_new_id(s), g_db.world_path, identity_pose) != DBC_OK) { db_fail("world"); return 0; }
  for (int i = 0; i < g_db.static_light_count; ++i) {
    const float* light = g_db.static_lights[i];
    if (dbc_light(s, dbc_new_id(s), light, light + 3, light[6], (dbc_light_falloff)(int)light[7], DBC_LIGHT_POINT, 0,
                  g_db.have_map_lights ? "maplight" : "surfacelight") != DBC_OK) {
      db_fail("surface light");
      return 0;
    }
  }
  return 1;
}

/* The frame's drawn models (paths and key-frame counts found before the frame began) with their
 * poses and key frames, and its dynamic lights. 0 on failure. */
static int record_entities(dbc_session* s, char paths[][3 * MAX_QPATH], const int* key_frames) {
  for (int i = 0; i < g_db.entity_count && g_db.active; ++i) {
    const pending_entity_t* p = &g_db.entities[i];
    const char* path = paths[i];
    const int frames = key_frames[i];
    if (!path[0]) continue;
    int fresh;
    const uint64_t id = identity(p->slot, p->serial, p->entity.hModel, p->entity.customSkin, p->occurrence, &fresh);
    if (dbc_model(s, id, path, pose_of(&p->entity)) != DBC_OK) { db_fail("model transform"); return 0; }
    if (frames > 1) {
      const uint32_t from = (uint32_t)(p->entity.oldframe % frames), to = (uint32_t)(p->entity.frame % frames);
      const float fraction = fminf(1.0f, fmaxf(0.0f, 1.0f - p->entity.backlerp));
      if (dbc_vertex_frames(s, id, path, from, to, fraction) != DBC_OK) { db_fail("key frames"); return 0; }
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
    if (dbc_light(s, id, at, l->rgb, l->intensity, DBC_FALLOFF_QUADRATIC, DBC_LIGHT_POINT, 1, type) != DBC_OK) { db_fail("light"); return 0; }
  }
  return 1;
}

/* After a recorded frame: the game frame to keep, progress, and after the last frame the capture
 * closed and the game quit. */
static void finish_frame(dbc_session* s) {
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

void dynbench_render_scene(const refdef_t* view) {
  if (!g_db.active || (view->rdflags & RDF_NOWORLDMODEL) || !cg.snap) return;
  ++g_db.pass;
  if (!match_started()) return;
  const playerState_t* ps = &cg.snap->ps;
  /* --follow auto: the next bot once the followed one dies (the server switches the view) */
  const int dead = ps->stats[STAT_HEALTH] <= 0 || ps->pm_type == PM_DEAD;
  if (dead && !strcmp(g_db.follow, "auto") && g_db.next_sent_for_death != ps->clientNum + 1) {
    trap_SendClientCommand("follownext");
    g_db.next_sent_for_death = ps->clientNum + 1;
  }
  if (!dead) g_db.next_sent_for_death = 0;
  if (!g_db.record) {
    count_unrecorded_frame();
    return;
  }
  dbc_session* s = g_db.session;
  if (!record_lens(s, view)) return;
  /* models are recorded between frames: every drawn one first */
  static char paths[MAX_PENDING][3 * MAX_QPATH];
  static int key_frames[MAX_PENDING];
  for (int i = 0; i < g_db.entity_count; ++i) {
    if (!model_path_of(&g_db.entities[i].entity, paths[i], &key_frames[i])) paths[i][0] = 0;
    if (!g_db.active) return;
  }
  if (dbc_frame_begin(s, (uint64_t)g_db.frame, (cg.time - g_db.start_time) / 1000.0) != DBC_OK) { db_fail("frame"); return; }
  if (!record_camera(s, view, ps, dead)) return;
  if (g_db.frame == 0 && !record_world(s)) return;
  if (!record_entities(s, paths, key_frames)) return;
  if (dbc_frame_end(s) != DBC_OK) { db_fail("frame end"); return; }
  finish_frame(s);
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

/* dynbench's lights of the map (src/maplight/fit.h, writeAdapterLights): "point X Y Z R G B D E"
 * (R G B at D units, ended by KHR's window at E; "point X Y Z R G B D", an older file's, has no
 * end), "sun DX DY DZ R G B", "surface SHADER R G B", game axes, full-light units; their colours
 * made linear here (game_colour_to_linear). */
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
    float v[8];
    int read;
    if (line[0] == '#' || line[0] == '\n') continue;
    if ((read = sscanf(line, "point %f %f %f %f %f %f %f %f", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7])) >= 7) {
      if (g_db.static_light_count >= MAX_STATIC_LIGHTS) continue;
      float* light = g_db.static_lights[g_db.static_light_count++];
      to_capture(v, light);
      game_colour_to_linear(v + 3);
      memcpy(light + 3, v + 3, 4 * sizeof(float));
      light[7] = (float)DBC_FALLOFF_INVERSE_SQUARE;
      if (read == 8 && v[7] > 0.0f) { /* the same light given at its end: colour x (D/E)^2 at E */
        const float atEnd = (v[6] / v[7]) * (v[6] / v[7]);
        for (int k = 3; k < 6; ++k) light[k] *= atEnd;
        light[6] = v[7];
        light[7] = (float)DBC_FALLOFF_WINDOWED_INVERSE_SQUARE;
      }
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
      fprintf(stderr, "dynbench-capture: error: %s:%d: expected 'point X Y Z R G B D E', 'sun DX DY DZ R G B' or 'surface SHADER R G B'\n", path, number);
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
  free_bsp();
  free(g_db.shaders);
  g_db.shaders = NULL;
}
