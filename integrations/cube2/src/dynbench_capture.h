// dynbench capture hooks for Cube 2: Sauerbraten (integrations/cube2/README.md). The engine patch
// calls these four functions (and provides dynbench_visit_dynlights); everything else lives in dynbench_capture.cpp. Capturing is on
// only when DYNBENCH_CAPTURE_DIR is set, so the patched game plays as before otherwise.
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

#endif
