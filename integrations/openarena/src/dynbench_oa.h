/* dynbench's capture adapter for OpenArena's client game module (cgame), the game's own render
 * front end: every drawn entity, light and view goes through the trap_R_* calls this header's
 * hooks sit in (capture-hooks.patch puts them there; integrations/openarena/README.md). */
#ifndef DYNBENCH_OA_H
#define DYNBENCH_OA_H

#include "../renderer/tr_types.h"

/* Capturing is on when DYNBENCH_CAPTURE_DIR is set; every hook is a no-op otherwise. */
void dynbench_cg_init(void);
void dynbench_cg_shutdown(void);

/* The renderer's handles, with the names they were registered with (models, skins). */
void dynbench_register_model(const char* name, qhandle_t handle);
void dynbench_register_skin(const char* name, qhandle_t handle);

/* Who draws the next entities and lights: a packet entity (slot = entity number) or a local
 * entity (slot = DYNBENCH_LOCAL_SLOT + its index), with what tells one of its lifetimes from the
 * next (the packet entity's type and model, the local entity's start time). */
#define DYNBENCH_LOCAL_SLOT 1024
void dynbench_owner_begin(int slot, int entity_type, int signature);
void dynbench_owner_end(void);

void dynbench_clear_scene(void);
void dynbench_add_ref_entity(const refEntity_t* entity);
void dynbench_add_light(const vec3_t origin, float intensity, float r, float g, float b);
/* The client game's clock while capturing: the latest snapshot's server time less one frame, so
 * that each frame shows the server's previous frame exactly (the server runs at the capture's fps,
 * one frame and one snapshot per engine frame). The engine's own estimate (serverTime) depends on
 * when the client connected and drifts by -2/+1 ms at each snapshot. */
int dynbench_frame_time(int server_time);

/* The level restarted (map_restart; dynbench_oa.c says why the adapter restarts it). */
void dynbench_map_restart(void);

/* The main view (not the HUD's 3D icons) is recorded here, as one frame. */
void dynbench_render_scene(const refdef_t* view);
/* The engine has queued the main view: the game's own image of a frame --game-frames keeps. */
void dynbench_scene_rendered(const refdef_t* view);

#endif
