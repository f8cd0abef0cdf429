#pragma once
// `dynbench capture openarena`: runs Debian's ioquake3 with OpenArena's game modules rebuilt with
// dynbench's capture hooks (integrations/openarena) headless under Xvfb, starts a bot deathmatch,
// spectates a bot in first person and records a fixed-clock, seeded capture.
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/error.h"

namespace dynbench::capture {

// Accepted ranges (the CLI's checks and captureOpenArena's are these).
inline constexpr std::pair<int, int> kOpenArenaBotsRange{1, 16};
inline constexpr std::pair<int, int> kOpenArenaSkillRange{1, 5};  // Quake 3's bot skills
inline constexpr double kOpenArenaMinWarmup = 2.0;                // s: the camera follows a bot by then

// The CPU the game runs on. Debian's engine keeps 7 RSQRTSS and 1 RCPPS in the bots' library, whose
// bits differ between CPU vendors, and a match follows them (integrations/openarena/README.md,
// "Across CPUs"). Emulated, every instruction of the engine and the game modules is computed by
// Debian's qemu-x86_64 in software, for one fixed CPU model: the same match on every host.
enum class GameCpu { kEmulated, kHost };
inline constexpr const char* kEmulatedCpuModel = "Nehalem";  // SSE4.2, no AVX: see openarena.cpp
std::string_view gameCpuName(GameCpu cpu);                     // "emulated" or "host"
Expected<GameCpu> parseGameCpu(std::string_view name);         // a usage error names the values
std::string gameCpuChoices();                                  // "\"emulated\" or \"host\"", for errors naming a JSON value

struct OpenArenaOptions {
  std::filesystem::path output;  // the capture folder
  std::string map = "oa_dm1";
  int bots = 4;
  int skill = 3;                 // kOpenArenaSkillRange
  double seconds = 10.0;         // recorded game time
  // The fixed clock: the engine's `fixedtime` is a whole number of milliseconds a frame, so fps
  // must divide 1000 (50, 40, 25, 20, ...).
  int fps = 50;
  unsigned seed = 1;
  // auto: the first bot, then the next whenever the followed one dies; one: the first bot for the
  // whole capture (its respawns are cuts); or a client number (bots are 1, 2, ...)
  std::string follow = "auto";
  double warmup = 3.0;           // game seconds between the map loading and recording
  // Recorded frames (0-based) whose own image the game keeps in game/frame_NNNNN.ppm (8-bit sRGB,
  // the HUD hidden), to put beside the dataset's render of them.
  std::vector<long> gameFrames;
  // As Cube 2's (capture/cube2.h): the window records nothing but its aspect, and a smaller one is
  // drawn faster (a 3 s capture of oa_dm1: 4.9 s at 384x216, 6.8 s at 640x360, byte-identical).
  int width = 384, height = 216;
  bool window = false;           // on the user's display instead of Xvfb
  std::filesystem::path modules;  // folder with cgamex86_64.so and qagamex86_64.so; empty: the build's
  std::filesystem::path engine = "/usr/lib/ioquake3/ioquake3";  // Debian's ioquake3
  GameCpu gameCpu = GameCpu::kEmulated;  // kHost: about 18 times faster (178 s against 10 s, oa_dm1), the host CPU's match
  std::filesystem::path data = "/usr/lib/openarena";             // Debian's openarena (baseoa/)
  // The map's lights for the adapter (maplight::cachedAdapterLights: the emitters the BSP names and
  // the stripped lights fitted to its lightmaps). Empty: the adapter's own rough approximation
  // (a point light per light-emitting surface and the light grid's mean as ambient).
  std::filesystem::path mapLights;
  // false: play the same match without writing anything (bench/bench_capture_openarena.sh
  // compares the window's wall time with and without recording)
  bool record = true;
};

struct OpenArenaReport {
  std::size_t frames = 0;
  double wallSeconds = 0.0;        // the whole run: start, loading, warm-up, recording, exit
  double windowWallSeconds = 0.0;  // the recorded frames alone (the adapter's own clock)
  std::size_t framesOffClock = 0;  // recorded frames without their own server snapshot (the adapter's count)
};

using OpenArenaProgress = std::function<void(std::size_t, std::size_t)>;  // (recorded, total)

// The bots added, in order: `bots` names from OpenArena's bot list (scripts/bots.txt).
Expected<std::vector<std::string>> openArenaBots(int bots);

// The game modules the build made (integrations/openarena/build.sh), or an error saying how to get them.
Expected<std::filesystem::path> findOpenArenaModules(const std::filesystem::path& requested);

// The engine's command line after the executable (exposed for tests).
Expected<std::vector<std::string>> openArenaArguments(const OpenArenaOptions& options, const std::filesystem::path& basePath,
                                                      const std::filesystem::path& homePath);

// The options' checks captureOpenArena makes before starting the game (usage errors, the engine,
// data and modules present): callers that do work first (fitting the map's lights) call it first.
Expected<void> checkOpenArenaOptions(const OpenArenaOptions& options);

Expected<OpenArenaReport> captureOpenArena(const OpenArenaOptions& options, const OpenArenaProgress& progress = {});

}  // namespace dynbench::capture
