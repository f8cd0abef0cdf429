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
//
// Coordinates: Cube 2 is Z-up (x east, y north); the capture format is Y-up, right-handed:
// (x, y, z)_cube -> (x, z, -y). Cube's yaw (0 = looking along +y, growing to the left) and pitch
// (up positive) are the capture convention's yaw and pitch (docs/metrics.md) after that mapping.
// Length unit: 8 Cube units to the metre, the Sauerbraten mappers' rule (the player's eyes are 14
// units, 1.75 m, above the ground).
#include "engine.h"

#include <cstdlib>

#include "dynbench/capture.h"
#include "dynbench_capture.h"

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

void toCapture(const vec &cube, float out[3]) {
  out[0] = cube.x;
  out[1] = cube.z;
  out[2] = -cube.y;
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
  seedMT(state.seed);
  if (dbc_open(dir, "Cube 2: Sauerbraten 2020-12-27 (Debian cube2 0.0.20201227+dfsg)", &state.session) != DBC_OK)
    failCapture("cannot open the capture folder");
  if (dbc_set_metres_per_unit(state.session, 0.125f) != DBC_OK) failCapture("settings");
  state.cameraId = dbc_new_id(state.session);
}

bool dynbench_capture_fixed_clock() { return state.enabled; }

int dynbench_capture_clock_millis() {
  // Frame k is at exactly k / fps seconds; the engine's integer milliseconds round to it.
  return state.clockBase + static_cast<int>(static_cast<double>(state.clockFrames) * 1000.0 / state.fps + 0.5);
}

void dynbench_capture_frame() {
  if (!state.enabled || state.done) return;
  ++state.clockFrames;
  const char *map = game::getclientmap();
  if (!map || !*map || !camera1) return;
  if (state.firstMapMillis < 0) {
    state.firstMapMillis = lastmillis;
    // The camera's lens: the engine's horizontal field of view and the window's aspect ratio.
    extern float nearplane;
    extern int farplane;
    const float aspectRatio = float(screenw) / float(max(screenh, 1));
    const float yfov = 2.0f * atan(tan(curfov * 0.5f * RAD) / aspectRatio) / RAD;
    if (dbc_set_camera_settings(state.session, aspectRatio, yfov, nearplane, float(farplane)) != DBC_OK) failCapture("camera settings");
    const float offset[3] = {0, 0, 0};
    if (dbc_set_map(state.session, map, offset) != DBC_OK) failCapture("map");
  }
  if (lastmillis - state.firstMapMillis < static_cast<long long>(state.warmupSeconds * 1000.0)) return;
  const double time = static_cast<double>(state.recorded) / state.fps;
  if (dbc_frame_begin(state.session, static_cast<uint64_t>(state.recorded), time) != DBC_OK) failCapture("frame");
  float position[3];
  toCapture(camera1->o, position);
  if (dbc_camera(state.session, state.cameraId, position, camera1->pitch, camera1->yaw, camera1->roll) != DBC_OK) failCapture("camera");
  if (dbc_frame_end(state.session) != DBC_OK) failCapture("frame end");
  ++state.recorded;
  if (static_cast<double>(state.recorded) >= state.seconds * state.fps) {
    if (dbc_close(state.session) != DBC_OK) failCapture("close");
    state.session = nullptr;
    state.done = true;
    execute("quit");
  }
}
