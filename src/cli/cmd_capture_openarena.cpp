// `dynbench capture openarena -o DIR`: record a headless, seeded OpenArena bot match
// (integrations/openarena).
#include <memory>
#include <optional>

#include "capture/openarena.h"
#include "cli/commands.h"
#include "core/progress.h"
#include "maplight/cache.h"

namespace dynbench::cli {

void addCaptureOpenArenaCommand(CLI::App* capture, CommandRun& run) {
  auto o = std::make_shared<capture::OpenArenaOptions>();
  auto* cmd = capture->add_subcommand("openarena", "Record an OpenArena (id Tech 3) bot match, headless, at a fixed clock and seed");
  cmd->footer("Runs Debian's ioquake3 with OpenArena's game modules rebuilt with dynbench's capture hooks under Xvfb, starts a\n"
              "free-for-all with --bots bots, spectates one in first person and records --seconds of game time after --warmup.\n"
              "The same --seed and options give a byte-identical capture, on every x86-64 host with --game-cpu emulated (the\n"
              "default). Then: dynbench convert DIR -o dataset.gltf\n"
              "Example: dynbench capture openarena -o captures/dm1 --map oa_dm1 --bots 4 --seconds 10 --seed 3");
  cmd->add_option("-o,--output", o->output, "Capture folder (new or empty)")->required();
  cmd->add_option("--map", o->map, "Map (OpenArena's: oa_dm1 ... oa_dm7, aggressor, ...)");
  cmd->add_option("--bots", o->bots, "Number of bots")->check(between(capture::kOpenArenaBotsRange.first, capture::kOpenArenaBotsRange.second));
  cmd->add_option("--skill", o->skill, "Bot skill (Quake 3's 1 to 5)")
      ->check(between(capture::kOpenArenaSkillRange.first, capture::kOpenArenaSkillRange.second));
  cmd->add_option("--seconds", o->seconds, "Game seconds recorded")->check(positive());
  cmd->add_option("--fps", o->fps, "Fixed clock, frames per game second (a divisor of 1000: the engine counts whole milliseconds)")
      ->check(between(1, 1000));
  cmd->add_option("--seed", o->seed, "Seed of every random choice");
  cmd->add_option("--game-frames", o->gameFrames,
                  "Recorded frames (0-based, comma-separated) whose own image the game keeps in DIR/game/frame_NNNNN.ppm (the HUD hidden)")
      ->delimiter(',');
  cmd->add_option("--follow", o->follow, "auto (a bot, then the next whenever the followed one dies), one (the first bot throughout; its respawns are camera cuts) or a bot's client number (1, 2, ...)");
  cmd->add_option("--warmup", o->warmup, "Game seconds after the map loads before recording")->check(between(capture::kOpenArenaMinWarmup, 3600.0));
  cmd->add_option("--width", o->width, "Window width")->check(between(64, 16384));
  cmd->add_option("--height", o->height, "Window height")->check(between(64, 16384));
  cmd->add_flag("--window", o->window, "Use the current display instead of Xvfb");
  cmd->add_option("--modules", o->modules, "Folder with the capture's cgamex86_64.so and qagamex86_64.so (empty: the build's)");
  cmd->add_option("--engine", o->engine, "The ioquake3 executable (Debian's)");
  auto gameCpu = std::make_shared<std::string>("emulated");
  cmd->add_option("--game-cpu", *gameCpu,
                  "emulated (the game run under Debian's qemu-x86_64 as a Nehalem: the same match on every host, a frame about 0.4 s) "
                  "or host (about 18 times faster; the match follows the CPU's vendor: integrations/openarena/README.md)")
      ->capture_default_str();
  cmd->add_option("--data", o->data, "OpenArena's base path, holding baseoa/ (Debian's openarena)");
  auto mapLights = std::make_shared<std::string>("fit");
  cmd->add_option("--map-lights", *mapLights,
                  "The map's lights: fit (the emitters its BSP names and the stripped lights fitted to its lightmaps, cached in "
                  "~/.cache/dynbench/map-lights; `dynbench map-lights MAP` shows how well), none (the adapter's rough "
                  "approximation), or a file `dynbench map-lights --adapter-lights` wrote")
      ->capture_default_str();
  cmd->add_flag("--no-record", [o](std::int64_t) { o->record = false; },
                "Play the same match without writing anything; prints the recording window's wall time (bench/bench_capture_openarena.sh)");
  cmd->callback([o, mapLights, gameCpu, &run] {
    run = [o, mapLights, gameCpu]() -> Expected<void> {
      auto cpu = capture::parseGameCpu(*gameCpu);
      if (!cpu) return std::unexpected(cpu.error());
      o->gameCpu = *cpu;
      if (auto ok = capture::checkOpenArenaOptions(*o); !ok) return std::unexpected(ok.error());
      if (*mapLights == "fit" && o->record) {
        std::unique_ptr<Progress> bar;
        auto file = maplight::cachedAdapterLights(o->data / "baseoa", o->map, maplight::defaultCacheFolder(), stepProgress("map lights", bar));
        bar.reset();
        if (!file) return std::unexpected(file.error());
        o->mapLights = *file;
      } else if (*mapLights != "none" && *mapLights != "fit") {
        o->mapLights = *mapLights;
      }
      std::optional<Progress> progress;
      capture::OpenArenaProgress report;
      if (Progress("capture", 0, "frames").enabled())
        report = [&](std::size_t done, std::size_t total) {
          if (!progress) progress.emplace("capture", total, "frames");
          progress->update(done, "game time at the fixed clock");
        };
      auto result = capture::captureOpenArena(*o, report);
      progress.reset();
      if (!result) return std::unexpected(result.error());
      const double perFrame = 1000.0 * result->windowWallSeconds / static_cast<double>(std::max<std::size_t>(result->frames, 1));
      if (!o->record) {
        fmt::print("not recorded: window of {} frames took {:.3f} s of wall time ({:.2f} ms/frame)\n", result->frames,
                   result->windowWallSeconds, perFrame);
        return {};
      }
      fmt::print("{}: {} frames ({:.1f} s of game time at {} frames/s) in {:.1f} s (the recorded window {:.3f} s, {:.2f} ms/frame); next: "
                 "dynbench convert {} -o DATASET.gltf\n",
                 o->output.string(), result->frames, static_cast<double>(result->frames) / o->fps, o->fps, result->wallSeconds,
                 result->windowWallSeconds, perFrame, o->output.string());
      if (result->framesOffClock > 0) fmt::print(stderr, "warning: {} frames off the fixed clock\n", result->framesOffClock);
      return {};
    };
  });
}

}  // namespace dynbench::cli
