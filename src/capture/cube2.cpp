#include "capture/cube2.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "capture/check.h"
#include "capture/xvfb.h"
#include "core/files.h"
#include "core/process.h"
#include "core/runtime_files.h"

namespace dynbench::capture {
namespace fs = std::filesystem;

Expected<fs::path> findCube2Client(const fs::path& requested) {
  if (!requested.empty()) {
    if (isExecutable(requested)) return requested;
    return fail(ErrorCode::kExternalTool, "--client {}: not an executable file", requested.string());
  }
  for (const auto& c : runtimeFileCandidates({"the Cube 2 client", "DYNBENCH_CUBE2_CLIENT", "lib/dynbench/cube2/sauer_client",
                                              DYNBENCH_CUBE2_CLIENT_BUILD_PATH}))
    if (isExecutable(c)) return c;
  return fail(ErrorCode::kExternalTool,
              "the Cube 2 client with dynbench's capture hooks is not built: run scripts/setup.sh, then cmake --build "
              "(target cube2_client), or pass --client PATH");
}

const std::vector<Cube2Preset>& cube2Presets() {
  // Bot skill stays at most 100: above it Sauerbraten's bots aim instantly (fpsgame/ai.cpp), turning
  // up to 180 degrees in one frame, which no player does.
  static const std::vector<Cube2Preset> presets = {
      {"calm", "two_towers", "ffa", 2, 40, "one", "two slow bots on a large map; the camera stays with one"},
      {"fps", "colos", "ffa", 6, 80, "auto", "a deathmatch on a mid-sized arena, the camera following a bot and then the next"},
      {"hard", "colos", "instagib", 8, 90, "auto", "instagib (one shot kills) with eight skilled bots: constant fights, fast turns"},
  };
  return presets;
}

Expected<void> applyCube2Preset(const std::string& name, Cube2Options& o, const std::vector<std::string>& keep) {
  const auto& presets = cube2Presets();
  const auto preset = std::find_if(presets.begin(), presets.end(), [&](const Cube2Preset& p) { return name == p.name; });
  if (preset == presets.end()) {
    std::string names;
    for (const auto& p : presets) names += (names.empty() ? "" : ", ") + std::string(p.name);
    return fail(ErrorCode::kUsage, "--preset '{}': expected one of {}", name, names);
  }
  auto kept = [&](const char* field) { return std::find(keep.begin(), keep.end(), field) != keep.end(); };
  if (!kept("map")) o.map = preset->map;
  if (!kept("mode")) o.mode = preset->mode;
  if (!kept("bots")) o.bots = preset->bots;
  if (!kept("skill")) o.skill = preset->skill;
  if (!kept("follow")) o.follow = preset->follow;
  return {};
}

Expected<std::string> cube2Script(const Cube2Options& o) {
  static const std::map<std::string, int> modes = {{"ffa", 0}, {"teamplay", 2}, {"instagib", 3}, {"efficiency", 5}, {"tactics", 7}};
  const auto mode = modes.find(o.mode);
  if (mode == modes.end()) return fail(ErrorCode::kUsage, "--mode '{}': expected ffa, teamplay, instagib, efficiency or tactics", o.mode);
  if (o.map.empty() || o.map.find_first_of(" ;[]\"$@") != std::string::npos)
    return fail(ErrorCode::kUsage, "--map '{}': expected a map name such as colos", o.map);
  if (o.bots < kBotsRange.first || o.bots > kBotsRange.second)
    return fail(ErrorCode::kUsage, "--bots must be {} to {} (got {})", kBotsRange.first, kBotsRange.second, o.bots);
  if (o.skill < kSkillRange.first || o.skill > kSkillRange.second)
    return fail(ErrorCode::kUsage, "--skill must be {} to {} (got {})", kSkillRange.first, kSkillRange.second, o.skill);
  std::string follow;
  if (o.follow == "auto" || o.follow == "one") follow = "nextfollow 1";
  else if (!o.follow.empty() && o.follow.find_first_not_of("0123456789") == std::string::npos) follow = "follow " + o.follow;
  else return fail(ErrorCode::kUsage, "--follow '{}': expected auto, one or a client number (bots are 128, 129, ...)", o.follow);
  std::string bots;
  for (int b = 0; b < o.bots; ++b) bots += fmt::format("addbot {}; ", o.skill);
  // Map at 0.1 s, bots and spectating at 0.7 s, following at 1.2 s of game time (the server
  // answers each step a few frames later); recording starts after the warm-up.
  return fmt::format("sleep 100 [mode {}; map {}]; sleep 700 [{}spectator 1]; sleep 1200 [{}]", mode->second, o.map, bots, follow);
}

Expected<Cube2Report> captureCube2(const Cube2Options& o, const Cube2Progress& progress) {
  if (!(o.fps > 0 && o.fps <= kMaxFps)) return fail(ErrorCode::kUsage, "--fps must be in (0, {}] (got {})", kMaxFps, o.fps);
  if (!(o.seconds > 0)) return fail(ErrorCode::kUsage, "--seconds must be positive (got {})", o.seconds);
  if (!(o.warmup >= kMinWarmup))
    return fail(ErrorCode::kUsage, "--warmup must be at least {} s (the bots join and the camera starts following by then)", kMinWarmup);
  if (o.width < kMinWindow || o.height < kMinWindow) return fail(ErrorCode::kUsage, "--width and --height must be at least {}", kMinWindow);
  auto script = cube2Script(o);
  if (!script) return std::unexpected(script.error());
  auto client = findCube2Client(o.client);
  if (!client) return std::unexpected(client.error());
  std::error_code ec;
  if (!fs::exists(o.data / "packages" / "base" / (o.map + ".ogz"), ec))
    return fail(ErrorCode::kIo, "map '{}' not found in {} (Debian's cube2-data has colos, cyber1, md2, ...)", o.map,
                (o.data / "packages" / "base").string());
  if (!o.window && findOnPath("Xvfb").empty()) return fail(ErrorCode::kExternalTool, "Xvfb is missing: install Debian's xvfb (scripts/setup.sh does)");
  if (fs::exists(o.output / "Capture.txt", ec))
    return fail(ErrorCode::kUsage, "{}: already holds a capture; choose an empty folder", o.output.string());
  fs::create_directories(o.output, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create: {}", o.output.string(), ec.message());
  // A fresh home for the game's configuration: a config saved by one run cannot change the next.
  const fs::path home = o.output / fmt::format(".cube2-home-{}", ::getpid());
  fs::remove_all(home, ec);
  fs::create_directories(home, ec);

  const std::size_t total = static_cast<std::size_t>(o.seconds * o.fps + 0.5);
  // A stalled game is stopped: at least 2 frames/s of wall time plus a minute for loading.
  const int timeout = 60 + static_cast<int>((o.seconds + o.warmup) * o.fps / 2.0);
  ProcessOptions game;
  game.workingDirectory = client->parent_path();  // the client finds its own files relative to it
  game.environment = {{"DYNBENCH_CAPTURE_DIR", fs::absolute(o.output).string()},
                      {"DYNBENCH_CAPTURE_DATA_ROOT", fs::absolute(o.data).string()},
                      {"DYNBENCH_CAPTURE_FPS", fmt::format("{}", o.fps)},
                      {"DYNBENCH_CAPTURE_SEED", fmt::format("{}", o.seed)},
                      {"DYNBENCH_CAPTURE_WARMUP", fmt::format("{}", o.warmup)},
                      {"DYNBENCH_CAPTURE_SECONDS", fmt::format("{}", o.seconds)},
                      {"DYNBENCH_CAPTURE_FOLLOW_AUTO", o.follow == "auto" ? "1" : "0"}};
  if (!o.gameFrames.empty()) {
    std::string list;
    for (const long k : o.gameFrames) {
      if (k < 0 || static_cast<std::size_t>(k) >= total)
        return fail(ErrorCode::kUsage, "--game-frames: frame {} is outside the capture's frames 0 to {}", k, total - 1);
      if (!list.empty()) list += ',';
      list += std::to_string(k);
    }
    game.environment.emplace_back("DYNBENCH_CAPTURE_GAME_FRAMES", list);
  }
  // The game's own display (capture/xvfb.h: why not xvfb-run), stopped when the capture ends.
  std::optional<XvfbDisplay> display;
  if (!o.window) {
    auto started = XvfbDisplay::start(o.width, o.height);
    if (!started) {
      fs::remove_all(home, ec);
      return std::unexpected(started.error());
    }
    display.emplace(std::move(*started));
    game.environment.emplace_back("DISPLAY", display->name());
  }
  // -k 10: SIGKILL if the client outlives the SIGTERM by 10 s (as capture/openarena.cpp, whose engine once hung in its handler)
  game.argv = {"timeout", "-k", "10", fmt::format("{}", timeout), "./" + client->filename().string(), "-q" + fs::absolute(home).string(),
               "-k" + fs::absolute(o.data).string(), "-r", "-t0", fmt::format("-w{}", o.width), fmt::format("-h{}", o.height),
               "-x" + *script};
  std::size_t frames = 0;
  std::optional<std::chrono::steady_clock::time_point> captureClosed;  // when the client said the capture is complete
  game.onLine = [&](std::string_view line) {
    unsigned long long done = 0, all = 0;
    if (std::sscanf(std::string(line).c_str(), "dynbench-capture: %llu/%llu frames", &done, &all) == 2) {
      frames = static_cast<std::size_t>(done);
      if (progress) progress(frames, total);
    }
    if (line.starts_with("dynbench-capture: window of ")) captureClosed = std::chrono::steady_clock::now();
    return true;
  };
  game.stopIf = [&] {
    return captureClosed && std::chrono::steady_clock::now() - *captureClosed > std::chrono::duration<double>(kClientExitGrace);
  };
  game.tailBytes = 3000;
  const auto started = std::chrono::steady_clock::now();
  auto run = runProcess(game);
  fs::remove_all(home, ec);
  if (!run) return std::unexpected(run.error());
  // A client stopped after closing a complete capture is not a failed capture: checkCapture below
  // reads the whole of it.
  const bool stoppedAfterCapture = run->stoppedByCaller && captureClosed && frames >= total;
  if ((!run->succeeded() && !stoppedAfterCapture) || frames < total)
    return fail(ErrorCode::kExternalTool, "the Cube 2 client stopped after {} of {} frames (status {}); its last output:\n{}", frames, total,
                run->exitStatus, run->tail);
  auto summary = checkCapture(o.output);
  if (!summary) return std::unexpected(summary.error());
  // The licences of what the capture holds, which `convert` copies into the dataset's README:
  // the game data's Debian copyright file (maps, textures, models) and the engine's licence.
  std::string licences =
      "This dataset was captured from Cube 2: Sauerbraten (engine: zlib licence, Debian source package cube2 "
      "0.0.20201227+dfsg) playing with the game data of Debian's cube2-data package. The maps, textures and models in it "
      "come from that package, whose copyright file follows.\n\n";
  const fs::path copyright = "/usr/share/doc/cube2-data/copyright";
  if (auto text = readWholeFile(copyright)) licences += "```\n" + *text + "```\n";
  else licences += fmt::format("({} was not found: check the game data's licences before publishing.)\n", copyright.string());
  if (auto ok = writeFileAtomic(o.output / "LICENSES.txt", licences); !ok) return std::unexpected(ok.error());
  Cube2Report report;
  report.frames = frames;
  report.clientStoppedAfterCapture = stoppedAfterCapture;
  report.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

}  // namespace dynbench::capture
