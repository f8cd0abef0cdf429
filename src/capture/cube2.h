#pragma once
// `dynbench capture cube2`: runs Cube 2: Sauerbraten with dynbench's capture hooks
// (integrations/cube2) headless under Xvfb, sets up a bot match, spectates a bot in first person
// and records a fixed-clock, seeded capture.
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace dynbench::capture {

// Accepted ranges (the CLI's checks and captureCube2's are these).
inline constexpr std::pair<int, int> kBotsRange{1, 32};
inline constexpr std::pair<int, int> kSkillRange{1, 101};  // the game's own addbot clamp
inline constexpr double kMaxFps = 1000.0;                  // fps in (0, kMaxFps]
inline constexpr double kMinWarmup = 1.5;                  // s: bots join at 0.7 s, following starts at 1.2 s
inline constexpr int kMinWindow = 64;                      // pixels, each side

struct Cube2Options {
  std::filesystem::path output;  // the capture folder
  std::string map = "colos";
  std::string mode = "ffa";      // ffa, teamplay, instagib, efficiency, tactics
  int bots = 6;
  int skill = 80;                // Sauerbraten's bot skill, kSkillRange
  double seconds = 30.0;         // recorded game time
  double fps = 60.0;             // fixed clock
  unsigned seed = 1;
  // Recorded frames (0-based) whose image the game keeps beside the capture, in game/: its colour
  // (PPM) and view depth (PFM), for `dynbench fidelity` (docs/fidelity.md). The HUD is hidden then.
  std::vector<long> gameFrames;
  // auto: the first bot, then the next whenever the followed one dies; one: the first bot for the
  // whole capture (its respawns are cuts); or a client number (bots are 128, 129, ...)
  std::string follow = "auto";
  double warmup = 2.0;           // game seconds between the map loading and recording
  // The window records nothing but its aspect (the capture's C line: aspect and field of view), and
  // the game draws every frame in software under Xvfb: a 3 s capture took 20 s at 384x216 and 31 s
  // at 640x360, byte-identical. 384x216 is the smallest 16:9 window the game keeps (engine/main.cpp
  // raises a window to SCR_MINW x SCR_MINH, 320x200, which changes the aspect). Larger for
  // --game-frames that are to be looked at.
  int width = 384, height = 216;
  bool window = false;           // on the user's display instead of Xvfb
  std::filesystem::path client;  // empty: the one the build made
  std::filesystem::path data = "/usr/share/games/cube2";  // Debian's cube2-data
};

// How long the client may take to exit after it has closed a complete capture (s). Its own
// shutdown (software OpenGL and SDL under Xvfb) has hung for minutes under load, after the
// capture was complete; it is stopped then, and the capture is checked as usual.
inline constexpr double kClientExitGrace = 20.0;

struct Cube2Report {
  std::size_t frames = 0;
  double wallSeconds = 0.0;
  bool clientStoppedAfterCapture = false;  // the client did not exit within kClientExitGrace and was stopped
};

// (frames recorded, frames total)
using Cube2Progress = std::function<void(std::size_t, std::size_t)>;

// Named capture presets: game settings and the camera-follow policy only (never synthetic camera
// motion), from calm to harder than the thesis's human-played Eternal Valley FPS. Their measured
// Tables 6.4-6.7 are in docs/presets.md.
struct Cube2Preset {
  const char* name;
  const char* map;
  const char* mode;
  int bots;
  int skill;
  const char* follow;
  const char* description;
};
const std::vector<Cube2Preset>& cube2Presets();
// Sets the preset's map, mode, bots, skill and follow in `options`, except the fields named in
// `keep` ("map", "mode", "bots", "skill", "follow": given explicitly). Unknown name: kUsage.
Expected<void> applyCube2Preset(const std::string& name, Cube2Options& options, const std::vector<std::string>& keep = {});

// The client the build made (integrations/cube2/build.sh), or an error saying how to get one.
Expected<std::filesystem::path> findCube2Client(const std::filesystem::path& requested);

Expected<Cube2Report> captureCube2(const Cube2Options& options, const Cube2Progress& progress = {});

// The cubescript that sets the match up (exposed for tests).
Expected<std::string> cube2Script(const Cube2Options& options);

}  // namespace dynbench::capture
