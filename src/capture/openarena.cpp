#include "capture/openarena.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include <fmt/format.h>

#include "capture/check.h"
#include "capture/xvfb.h"
#include "core/files.h"
#include "core/process.h"
#include "core/runtime_files.h"

namespace dynbench::capture {
namespace fs = std::filesystem;

namespace {

// Debian's user-mode emulator (qemu-user). Under it the guest's floating point is qemu's software
// IEEE arithmetic (RSQRTSS and RCPPS come out exact, not a vendor's estimate), and the CPU the
// guest's C library sees is the model named, whatever the host is.
constexpr const char* kQemu = "qemu-x86_64";

// The game modules the capture replaces; every other file of baseoa/ (the paks, the menu module)
// is Debian's own, linked into the run's private base folder.
constexpr const char* kModules[] = {"cgamex86_64.so", "qagamex86_64.so"};

bool isModuleFolder(const fs::path& folder) {
  std::error_code ec;
  for (const char* m : kModules)
    if (!fs::is_regular_file(folder / m, ec)) return false;
  return true;
}

// RUN/base/baseoa: Debian's baseoa/ as links, with the capture's game modules instead of its own.
Expected<void> makeBaseFolder(const fs::path& data, const fs::path& modules, const fs::path& base) {
  std::error_code ec;
  const fs::path game = base / "baseoa";
  fs::create_directories(game, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create: {}", game.string(), ec.message());
  for (const auto& entry : fs::directory_iterator(data / "baseoa", ec)) {
    const std::string name = entry.path().filename().string();
    if (name == kModules[0] || name == kModules[1]) continue;
    fs::create_symlink(fs::absolute(entry.path()), game / name, ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot link {}: {}", game.string(), name, ec.message());
  }
  if (ec) return fail(ErrorCode::kIo, "{}: cannot list: {}", (data / "baseoa").string(), ec.message());
  for (const char* m : kModules) {
    fs::create_symlink(fs::absolute(modules / m), game / m, ec);
    if (ec) return fail(ErrorCode::kIo, "{}: cannot link {}: {}", game.string(), m, ec.message());
  }
  return {};
}

}  // namespace

std::string_view gameCpuName(GameCpu cpu) { return cpu == GameCpu::kEmulated ? "emulated" : "host"; }

Expected<GameCpu> parseGameCpu(std::string_view name) {
  for (const GameCpu cpu : {GameCpu::kEmulated, GameCpu::kHost})
    if (name == gameCpuName(cpu)) return cpu;
  return fail(ErrorCode::kUsage, "--game-cpu '{}': expected {} or {}", name, gameCpuName(GameCpu::kEmulated), gameCpuName(GameCpu::kHost));
}

std::string gameCpuChoices() { return fmt::format("\"{}\" or \"{}\"", gameCpuName(GameCpu::kEmulated), gameCpuName(GameCpu::kHost)); }

Expected<std::vector<std::string>> openArenaBots(int bots) {
  // OpenArena 0.8.8's bots (scripts/bots.txt in pak6-patch088.pk3), a varied order.
  static const std::vector<std::string> names = {"Sarge", "Grism", "Kyonshi", "Angelyss", "Major", "Merman", "Penguin", "Liz",
                                                 "Sorceress", "Tony", "Gargoyle", "Beret", "Assassin", "Ayumi", "Jenna", "Grunt"};
  if (bots < kOpenArenaBotsRange.first || bots > kOpenArenaBotsRange.second)
    return fail(ErrorCode::kUsage, "--bots must be {} to {} (got {})", kOpenArenaBotsRange.first, kOpenArenaBotsRange.second, bots);
  return std::vector<std::string>(names.begin(), names.begin() + bots);
}

Expected<fs::path> findOpenArenaModules(const fs::path& requested) {
  if (!requested.empty()) {
    if (isModuleFolder(requested)) return requested;
    return fail(ErrorCode::kExternalTool, "--modules {}: expected a folder with cgamex86_64.so and qagamex86_64.so", requested.string());
  }
  for (const auto& c : runtimeFileCandidates({"OpenArena's game modules with the capture hooks", "DYNBENCH_OPENARENA_MODULES",
                                              "lib/dynbench/openarena", DYNBENCH_OPENARENA_MODULES_BUILD_PATH}))
    if (isModuleFolder(c)) return c;
  return fail(ErrorCode::kExternalTool,
              "OpenArena's game modules with dynbench's capture hooks are not built: run scripts/setup.sh --all (it installs "
              "OpenArena and fetches its game code), then cmake --build build/release --target openarena_modules, or pass "
              "--modules DIR");
}

namespace {

// The match's own settings (map name, skill, fps, bots), checked before anything is made.
Expected<void> checkMatch(const OpenArenaOptions& o) {
  if (o.map.empty() || o.map.find_first_of(" ;\"\\/\n") != std::string::npos)
    return fail(ErrorCode::kUsage, "--map '{}': expected a map name such as oa_dm1", o.map);
  if (o.skill < kOpenArenaSkillRange.first || o.skill > kOpenArenaSkillRange.second)
    return fail(ErrorCode::kUsage, "--skill must be {} to {} (got {})", kOpenArenaSkillRange.first, kOpenArenaSkillRange.second, o.skill);
  if (!(o.fps > 0 && o.fps <= 1000 && 1000 % o.fps == 0))
    return fail(ErrorCode::kUsage, "--fps {}: the engine's fixed clock is whole milliseconds a frame; expected a divisor of 1000 (50, 40, 25, ...)", o.fps);
  if (auto bots = openArenaBots(o.bots); !bots) return std::unexpected(bots.error());
  return {};
}

}  // namespace

Expected<std::vector<std::string>> openArenaArguments(const OpenArenaOptions& o, const fs::path& basePath, const fs::path& homePath) {
  if (auto ok = checkMatch(o); !ok) return std::unexpected(ok.error());
  std::vector<std::string> a = {
      // Debian's openarena wrapper's settings (/usr/games/openarena), with private base and home folders
      "+set", "com_basegame", "baseoa", "+set", "fs_basepath", basePath.string(), "+set", "fs_homepath", homePath.string(),
      "+set", "com_protocol", "71", "+set", "com_legacyprotocol", "71", "+set", "cl_motd", "0", "+set", "sv_master1", "",
      // the native game modules (the capture's), no sound, the window
      "+set", "vm_cgame", "0", "+set", "vm_game", "0", "+set", "vm_ui", "0", "+set", "sv_pure", "0", "+set", "s_initsound", "0",
      "+set", "ttycon", "0", "+set", "r_mode", "-1", "+set", "r_fullscreen", "0", "+set", "r_customwidth", std::to_string(o.width),
      "+set", "r_customheight", std::to_string(o.height),
      // the game's own frames (--game-frames) from ioquake3's classic renderer, drawn straight into
      // the window: lightmap bytes times 4, clipped, as q3map2's model and docs/fidelity.md take
      // them, with no hardware gamma ramp (which a read-back would not see). Debian's default,
      // opengl2, draws the view into an off-screen HDR framebuffer and tone-maps it with an
      // exposure that adapts over frames; the depth buffer of the window then holds nothing.
      "+set", "cl_renderer", "opengl1", "+set", "r_ignorehwgamma", "1",
      // the fixed clock from the first frame (the server's first frames too: set later, the bots'
      // first moves would follow the machine's speed), frames as fast as the machine goes
      "+set", "fixedtime", std::to_string(1000 / o.fps), "+set", "com_maxfps", "0",
      // the server runs a frame, and sends the client a snapshot, every engine frame: each
      // recorded frame is a server frame (dynbench_frame_time in the adapter)
      "+set", "sv_fps", std::to_string(o.fps), "+set", "snaps", std::to_string(o.fps),
      // what the camera shows: no HUD gun, no 2D overlay
      "+set", "cg_drawGun", "0", "+set", "cg_draw2D", "0",
      // the local client joins as a spectator (the adapter then restarts the level: dynbench_oa.c)
      "+setu", "team", "s",
      // a free-for-all without limits, bots with their chat off
      "+set", "g_gametype", "0", "+set", "fraglimit", "0", "+set", "timelimit", "0", "+set", "bot_nochat", "1",
      "+devmap", o.map};
  return a;
}

Expected<void> checkOpenArenaOptions(const OpenArenaOptions& o) {
  if (!(o.seconds > 0)) return fail(ErrorCode::kUsage, "--seconds must be positive (got {})", o.seconds);
  if (!(o.warmup >= kOpenArenaMinWarmup))
    return fail(ErrorCode::kUsage, "--warmup must be at least {} s (the camera follows a bot by then)", kOpenArenaMinWarmup);
  if (o.width < 64 || o.height < 64) return fail(ErrorCode::kUsage, "--width and --height must be at least 64");
  if (o.follow != "auto" && o.follow != "one" && (o.follow.empty() || o.follow.find_first_not_of("0123456789") != std::string::npos))
    return fail(ErrorCode::kUsage, "--follow '{}': expected auto, one or a bot's client number (1, 2, ...)", o.follow);
  const std::size_t total = static_cast<std::size_t>(o.seconds * o.fps + 0.5);
  for (const long k : o.gameFrames) {
    // the last frame's image would be read at the frame after it, which is not played
    if (k < 0 || static_cast<std::size_t>(k) + 1 >= total)
      return fail(ErrorCode::kUsage, "--game-frames: frame {} is outside the capture's frames 0 to {} (the last one cannot be kept)", k,
                  static_cast<long>(total) - 2);
  }
  if (auto ok = checkMatch(o); !ok) return std::unexpected(ok.error());
  auto modules = findOpenArenaModules(o.modules);
  if (!modules) return std::unexpected(modules.error());
  if (!isExecutable(o.engine))
    return fail(ErrorCode::kExternalTool, "{}: not an executable: install Debian's openarena (scripts/setup.sh --all does)", o.engine.string());
  std::error_code ec;
  if (!fs::is_directory(o.data / "baseoa", ec))
    return fail(ErrorCode::kExternalTool, "{}: missing: install Debian's openarena (scripts/setup.sh --all does)", (o.data / "baseoa").string());
  if (!o.window && findOnPath("Xvfb").empty()) return fail(ErrorCode::kExternalTool, "Xvfb is missing: install Debian's xvfb (scripts/setup.sh does)");
  if (o.gameCpu == GameCpu::kEmulated && findOnPath(kQemu).empty())
    return fail(ErrorCode::kExternalTool, "{} is missing: install Debian's qemu-user (scripts/setup.sh --all does), or pass --game-cpu host", kQemu);
  if (fs::exists(o.output / "Capture.txt", ec))
    return fail(ErrorCode::kUsage, "{}: already holds a capture; choose an empty folder", o.output.string());
  return {};
}

Expected<OpenArenaReport> captureOpenArena(const OpenArenaOptions& o, const OpenArenaProgress& progress) {
  if (auto ok = checkOpenArenaOptions(o); !ok) return std::unexpected(ok.error());
  const std::size_t total = static_cast<std::size_t>(o.seconds * o.fps + 0.5);
  std::string gameFrames;
  for (const long k : o.gameFrames) gameFrames += fmt::format("{}{}", gameFrames.empty() ? "" : ",", k);
  auto modules = findOpenArenaModules(o.modules);
  if (!modules) return std::unexpected(modules.error());
  std::error_code ec;
  fs::create_directories(o.output, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create: {}", o.output.string(), ec.message());
  // A private base (Debian's paks and the capture's modules) and a fresh home (a config saved by
  // one run cannot change the next), removed afterwards.
  const fs::path run = fs::absolute(o.output / fmt::format(".openarena-{}", ::getpid()));
  fs::remove_all(run, ec);
  struct Cleanup {
    fs::path path;
    ~Cleanup() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } cleanup{run};
  if (auto ok = makeBaseFolder(o.data, *modules, run / "base"); !ok) return std::unexpected(ok.error());
  fs::create_directories(run / "home", ec);
  auto arguments = openArenaArguments(o, run / "base", run / "home");
  if (!arguments) return std::unexpected(arguments.error());

  // A stalled game is stopped: at least 2 frames/s of wall time plus a minute for loading; emulated
  // (0.33-0.4 s a frame measured, 30-60 s to load), at least one frame every 2 s plus 3 minutes.
  const double frameCount = (o.seconds + o.warmup) * o.fps;
  const int timeout = o.gameCpu == GameCpu::kEmulated ? 180 + static_cast<int>(frameCount * 2.0) : 60 + static_cast<int>(frameCount / 2.0);
  ProcessOptions game;
  game.workingDirectory = run;
  game.environment = {{"DYNBENCH_CAPTURE_DIR", fs::absolute(o.output).string()},
                      {"DYNBENCH_CAPTURE_FPS", std::to_string(o.fps)},
                      {"DYNBENCH_CAPTURE_SEED", std::to_string(o.seed)},
                      {"DYNBENCH_CAPTURE_WARMUP", fmt::format("{}", o.warmup)},
                      {"DYNBENCH_CAPTURE_SECONDS", fmt::format("{}", o.seconds)},
                      {"DYNBENCH_CAPTURE_FOLLOW", o.follow},
                      {"DYNBENCH_CAPTURE_RECORD", o.record ? "1" : "0"}};
  if (!gameFrames.empty()) game.environment.emplace_back("DYNBENCH_CAPTURE_GAME_FRAMES", gameFrames);
  if (!o.mapLights.empty()) game.environment.emplace_back("DYNBENCH_CAPTURE_MAP_LIGHTS", fs::absolute(o.mapLights).string());
  // The engine loads the modules through the run's base folder (links), so their run path's
  // $ORIGIN/../.. names that folder, not the prefix they are installed in: installed modules
  // (PREFIX/lib/dynbench/openarena) get their prefix's SDK (PREFIX/lib) this way instead. Modules
  // in the build folder have none there and keep their run path's (the SDK installed into the build).
  const fs::path prefixLib = fs::weakly_canonical(fs::absolute(*modules)) / ".." / "..";
  if (fs::exists(prefixLib / "libdynbench_capture.so", ec)) {
    const char* existing = std::getenv("LD_LIBRARY_PATH");
    game.environment.emplace_back("LD_LIBRARY_PATH", existing && *existing ? fmt::format("{}:{}", prefixLib.lexically_normal().string(), existing)
                                                                           : prefixLib.lexically_normal().string());
  }
  // The bots join after the level restart the adapter makes (dynbench_oa.c says why).
  std::string bots;
  const auto names = openArenaBots(o.bots);  // checked by openArenaArguments
  for (const auto& bot : *names) bots += fmt::format("{}{}:{}", bots.empty() ? "" : " ", bot, o.skill);
  game.environment.emplace_back("DYNBENCH_CAPTURE_BOTS", bots);
  std::optional<XvfbDisplay> display;  // capture/xvfb.h: why not xvfb-run
  if (!o.window) {
    auto started = XvfbDisplay::start(o.width, o.height);
    if (!started) return std::unexpected(started.error());
    display.emplace(std::move(*started));
    game.environment.emplace_back("DISPLAY", display->name());
  }
  // -k: SIGKILL 10 s after the SIGTERM (the timeout's, or ours when the engine cannot load the map)
  // if the engine is still there. ioquake3's SIGTERM handler shuts the engine down from inside the
  // handler and can deadlock there: once, under load, a `--map no_such_map` capture hung with the
  // signal blocked in its handler and the main thread waiting on a lock, past both signals.
  game.argv = {"timeout", "-k", "10", std::to_string(timeout)};
  // Nehalem (SSE4.2, no AVX): a model qemu 7.2 emulates in full, so that what the guest's C library
  // and Mesa choose by CPUID is fixed; with `max` (which follows qemu's version) Mesa's rasteriser
  // emits FMA, which qemu computes in software: 2 s a frame against 0.4 s (oa_dm1, 384x216).
  if (o.gameCpu == GameCpu::kEmulated) game.argv.insert(game.argv.end(), {kQemu, "-cpu", kEmulatedCpuModel});
  game.argv.push_back(o.engine.string());
  game.argv.insert(game.argv.end(), arguments->begin(), arguments->end());
  std::size_t frames = 0;
  unsigned long windowMs = 0, offClock = 0;
  bool complete = false;
  std::string adapterErrors;
  game.onLine = [&](std::string_view line) {
    unsigned long long done = 0, all = 0;
    if (std::sscanf(std::string(line).c_str(), "dynbench-capture: %llu/%llu frames", &done, &all) == 2) {
      frames = static_cast<std::size_t>(done);
      if (progress) progress(frames, total);
    }
    unsigned long n = 0;
    if (std::sscanf(std::string(line).c_str(), "dynbench-capture: window of %lu frames took %lu ms of wall time (recorded; %lu frames off", &n,
                    &windowMs, &offClock) >= 2)
      complete = true;
    if (line.starts_with("dynbench-capture: error")) adapterErrors += std::string(line) + "\n";
    // The engine stays at its console after a map it cannot load; stop it then.
    if (line.starts_with("Can't find map")) {
      adapterErrors += std::string(line) + " (OpenArena's maps: oa_dm1 ... oa_dm7, aggressor, ...)\n";
      return false;
    }
    return true;
  };
  game.tailBytes = 3000;
  const auto started = std::chrono::steady_clock::now();
  auto result = runProcess(game);
  if (!result) return std::unexpected(result.error());
  if (!complete || frames < total)
    return fail(ErrorCode::kExternalTool, "OpenArena stopped after {} of {} frames (status {}){}; its last output:\n{}", frames, total,
                result->exitStatus, adapterErrors.empty() ? "" : ":\n" + adapterErrors, result->tail);
  OpenArenaReport report;
  report.frames = frames;
  report.windowWallSeconds = static_cast<double>(windowMs) / 1000.0;
  report.framesOffClock = offClock;
  report.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!o.record) return report;
  auto summary = checkCapture(o.output);
  if (!summary) return std::unexpected(summary.error());
  // The licences of what the capture holds, which `convert` copies into the dataset's README.
  std::string licences =
      "This dataset was captured from OpenArena 0.8.8 (game code: GPL-2, Debian source package openarena 0.8.8+dfsg; engine: "
      "Debian's ioquake3, GPL-2) with the game data of Debian's openarena-data, openarena-085-data and openarena-088-data "
      "packages. The maps, textures and models in it come from those packages, whose copyright files follow.\n\n";
  for (const char* package : {"openarena-data", "openarena-085-data", "openarena-088-data"}) {
    const fs::path copyright = fs::path("/usr/share/doc") / package / "copyright";
    if (auto text = readWholeFile(copyright)) licences += fmt::format("## {}\n\n```\n{}```\n\n", package, *text);
    else licences += fmt::format("({} was not found: check the game data's licences before publishing.)\n", copyright.string());
  }
  if (auto ok = writeFileAtomic(o.output / "LICENSES.txt", licences); !ok) return std::unexpected(ok.error());
  return report;
}

}  // namespace dynbench::capture
