// dynbench capture hooks for Cube 2: Sauerbraten (integrations/cube2/README.md). The engine patch
// calls the first four functions (and provides dynbench_visit_dynlights and the model part hook);
// the work lives in dynbench_capture.cpp and dynbench_models.h. Capturing is on only when
// DYNBENCH_CAPTURE_DIR is set, so the patched game plays as before otherwise.
#ifndef DYNBENCH_CUBE2_CAPTURE_H
#define DYNBENCH_CUBE2_CAPTURE_H

// Reads the DYNBENCH_CAPTURE_* environment, seeds the game's random numbers. Call before the
// init script runs.
void dynbench_capture_init();
// True when the game clock is fixed: it then advances by exactly 1/fps per frame.
bool dynbench_capture_fixed_clock();
// The fixed clock, in the engine's milliseconds.
int dynbench_capture_clock_millis();
// After each rendered frame: records it when the capture window is open, quits when it closes.
void dynbench_capture_frame();

// How far (Cube units) a thing the engine keeps no identity for (a part drawn without a game
// entity, a light re-added every frame) may move between two frames and keep its id: a rocket flies
// 320 units/s, 5.3 units per frame at 60 fps and 13 at 24 fps; 48 allows down to about 7 fps. A
// camera moving further than this in one frame has jumped (teleporter): a cut.
static const float kDynbenchMaxStepUnits = 48.0f;

// One queued dynamic light as the engine holds it (engine/dynlight.cpp; its struct is private).
struct dynbench_dynlight {
  vec o;               // position this frame
  vec color;           // colour this frame, after the engine's peak and fade
  vec basecolor;       // the colour it was added with (constant over its life)
  float radius;        // radius this frame
  int flags;           // DL_FLASH, DL_SHRINK, DL_EXPAND
  int fade, peak;      // milliseconds; both 0 for a light re-added every frame (projectiles)
  int expire;          // lastmillis at which it ends
  const void *owner;   // the player a tracked light follows (muzzle flash), or NULL
};

// Implemented in engine/dynlight.cpp by the patch: calls `visit` for every queued dynamic light.
void dynbench_visit_dynlights(void (*visit)(const dynbench_dynlight &light));

// A stand-in for an entity's address where the engine seeds animation variety and phase from it
// (animmodel.h calcanim): entities numbered in order of first appearance, scrambled.
unsigned dynbench_capture_entity_seed(const void *entity);
// Called by the patch from dynent's destructor: the entity is gone, and a later one at its address
// is another (its seed and its parts' ids are not inherited).
void dynbench_capture_forget_entity(const void *entity);

// True while a capture session is open and the map is loaded: the model part hook collects then.
bool dynbench_capture_recording();

// engine/dynbench_models.h (compiled into engine/rendermodel.cpp, where the model classes are
// complete). All return false when the capture SDK refuses a call (dbc_last_error says why).
struct dbc_session;
// Records every map model entity once as a static model (its mesh, then its pose at the first
// frame).
bool dynbench_models_capture_static(dbc_session *session);
// Outside a frame: records the meshes of models first drawn this frame and gives every part drawn
// this frame its capturable id.
bool dynbench_models_export(dbc_session *session);
// Inside a frame: the static models (first frame only), then this frame's model transforms and
// joints.
bool dynbench_models_write(dbc_session *session, bool firstFrame);
// Writes the engine's own skinning of this frame's skeletal parts to `path` (a test's reference).
bool dynbench_models_write_verification(const char *path);
// Starts collecting the next frame; keepIds: this frame was recorded, so its parts lend their ids.
void dynbench_models_next_frame(bool keepIds);
// Parts recorded in the last recorded frame.
int dynbench_models_count();
// The entity was deleted: parts of the last frame drawn for it no longer match a new entity at
// the same address.
void dynbench_models_forget_owner(const void *entity);

#endif
