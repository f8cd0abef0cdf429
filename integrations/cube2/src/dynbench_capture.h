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

// Implemented in engine/dynlight.cpp by the patch (struct dynlight is private to that file):
// calls `visit` for every queued dynamic light.
void dynbench_visit_dynlights(void (*visit)(const vec &o, const vec &color, float radius, int flags, bool fading));

// A stand-in for an entity's address where the engine seeds animation variety and phase from it
// (animmodel.h calcanim): entities numbered in order of first appearance, scrambled.
unsigned dynbench_capture_entity_seed(const void *entity);

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

#endif
