// `dynbench capture cube2 -o DIR`: record a headless, seeded Cube 2 bot match (integrations/cube2).
#include <optional>

#include "capture/cube2.h"
#include "capture/cube2_job.h"
#include "cli/commands.h"
#include "core/progress.h"

namespace dynbench::cli {
namespace {

Expected<void> runCube2(const capture::Cube2Options& options) {
  std::optional<Progress> progress;
  capture::Cube2Progress report;
  if (Progress("capture", 0, "frames").enabled())
    report = [&](std::size_t done, std::size_t total) {
      if (!progress) progress.emplace("capture", total, "frames");
      progress->update(done, "game time at the fixed clock");
    };
  auto result = capture::captureCube2(options, report);
  progress.reset();
  if (!result) return std::unexpected(result.error());
  if (result->clientStoppedAfterCapture)
    fmt::print(stderr, "dynbench: note: the Cube 2 client closed the capture but did not exit within {:.0f} s; it was stopped\n",
               capture::kClientExitGrace);
  fmt::print("{}: {} frames ({:.1f} s of game time at {} frames/s) in {:.1f} s; next: dynbench convert {} -o DATASET.gltf\n",
             options.output.string(), result->frames, result->frames / options.fps, options.fps, result->wallSeconds,
             options.output.string());
  return {};
}

// capture cube2 --slurm --seeds A:B: one capture per seed as a Slurm job array (pipeline/cluster_jobs.h).
Expected<void> captureOnSlurm(const capture::Cube2Options& options, const std::string& seeds, const cluster::Options& slurm) {
  unsigned first = 0, last = 0;
  char colon = 0, extra = 0;
  const int n = std::sscanf(seeds.c_str(), "%u%c%u%c", &first, &colon, &last, &extra);
  if (n == 1) last = first;
  else if (n != 3 || colon != ':') return fail(ErrorCode::kUsage, "--seeds '{}': expected A:B (seeds A to B) or A", seeds);
  std::optional<Progress> progress;
  auto outcome = pipeline::captureArray(options, first, last, slurm, [&](const cluster::ArrayStatus& s) {
    if (!progress) progress.emplace("slurm capture", static_cast<std::size_t>(last - first + 1), "captures");
    progress->update(static_cast<std::size_t>(s.done), fmt::format("tasks {} pending, {} running, {} failed", s.pending, s.running, s.failed));
  });
  progress.reset();
  if (!outcome) return std::unexpected(outcome.error());
  fmt::print("{}: Slurm job {}, {} capture(s), script {}\n", options.output.string(), outcome->jobId, outcome->seeds.size(),
             outcome->script.string());
  if (!outcome->waited) return {};
  if (!outcome->failed.empty()) {
    std::string list;
    for (int task : outcome->failed)
      list += fmt::format("  task {}: seed {} ({} missing)\n", task, outcome->seeds[static_cast<std::size_t>(task)],
                          (outcome->captures[static_cast<std::size_t>(task)] / "Capture.txt").string());
    return fail(ErrorCode::kIncomplete, "Slurm job {} ended with {} capture(s) missing:\n{}Rerun only those tasks: {}", outcome->jobId,
                outcome->failed.size(), list, outcome->resubmit);
  }
  for (const auto& c : outcome->captures) fmt::print("{}\n", c.string());
  return {};
}

// The preset names, from their one definition (capture/cube2.h).
std::vector<std::string> presetNames() {
  std::vector<std::string> names;
  for (const auto& p : capture::cube2Presets()) names.emplace_back(p.name);
  return names;
}

}  // namespace

void addCaptureCommand(CLI::App& app, CommandRun& run) {
  auto* capture = app.add_subcommand("capture", "Capture animations from a running program");
  capture->require_subcommand(1);
  auto o = std::make_shared<capture::Cube2Options>();
  auto* cmd = capture->add_subcommand("cube2", "Record a Cube 2: Sauerbraten bot match, headless, at a fixed clock and seed");
  cmd->footer("Runs the game built with dynbench's capture hooks under Xvfb, sets up the match, spectates a bot in first\n"
              "person and records --seconds of game time after --warmup. The same --seed and options give a byte-identical\n"
              "Capture.txt. Then: dynbench convert DIR -o dataset.gltf\n"
              "Example: dynbench capture cube2 -o captures/colos --map colos --bots 6 --seconds 10");
  cmd->add_option("-o,--output", o->output, "Capture folder (new or empty)");
  auto jobFile = std::make_shared<std::filesystem::path>();
  cmd->add_option("--job", *jobFile,
                  "The capture's options from a JSON file (docs/cli.md, \"Job files\"; what a Slurm task runs) instead of the options "
                  "below; -o and --seed may still be given")
      ->check(CLI::ExistingFile);
  auto preset = std::make_shared<std::string>();
  cmd->add_option("--preset", *preset, "calm, fps or hard: map, mode, bots, skill and follow together (docs/presets.md); options given explicitly win")
      ->check(CLI::IsMember(presetNames()));
  cmd->add_option("--map", o->map, "Map (others with bot waypoints: cyber1, md2, ...)");
  cmd->add_option("--mode", o->mode, "Game mode")
      ->check(CLI::IsMember({"ffa", "teamplay", "instagib", "efficiency", "tactics"}));
  cmd->add_option("--bots", o->bots, "Number of bots")->check(between(capture::kBotsRange.first, capture::kBotsRange.second));
  cmd->add_option("--skill", o->skill, "Bot skill (Sauerbraten's)")->check(between(capture::kSkillRange.first, capture::kSkillRange.second));
  cmd->add_option("--seconds", o->seconds, "Game seconds recorded")->check(positive());
  cmd->add_option("--fps", o->fps, "Fixed clock, frames per game second")->check(between(1e-3, capture::kMaxFps));
  cmd->add_option("--seed", o->seed, "Seed of every random choice");
  cmd->add_option("--game-frames", o->gameFrames,
                  "Recorded frames (0-based, comma-separated) whose own image the game keeps in DIR/game/ (colour and view depth; "
                  "the HUD is hidden) for dynbench fidelity")
      ->delimiter(',');
  cmd->add_option("--follow", o->follow, "auto (a bot, then the next whenever the followed one dies, as a spectator would), one (the first bot throughout; its respawns are camera cuts) or a bot's client number (128, 129, ...)");
  cmd->add_option("--warmup", o->warmup, "Game seconds after the map loads before recording (the bots join and the camera follows by 1.5)")
      ->check(between(capture::kMinWarmup, 3600.0));
  cmd->add_option("--width", o->width, "Window width")->check(between(capture::kMinWindow, 16384));
  cmd->add_option("--height", o->height, "Window height")->check(between(capture::kMinWindow, 16384));
  cmd->add_flag("--window", o->window, "Use the current display instead of Xvfb");
  cmd->add_option("--client", o->client, "The Cube 2 client with the capture hooks (empty: the one the build made)");
  cmd->add_option("--data", o->data, "Game data (Debian's cube2-data)");
  auto slurm = std::make_shared<std::pair<bool, cluster::Options>>();
  auto seeds = std::make_shared<std::string>();
  addSlurmOptions(cmd, slurm->first, slurm->second, "DIR/slurm/capture.sbatch, one task per seed of --seeds, each into DIR/seed_N", false);
  cmd->add_option("--seeds", *seeds, "With --slurm: capture seeds A to B (A:B), one array task each")->group("Slurm (with --slurm)");
  cmd->callback([o, preset, cmd, slurm, seeds, jobFile, &run] {
    std::vector<std::string> given;
    for (const char* field : {"map", "mode", "bots", "skill", "follow"})
      if (cmd->count(std::string("--") + field) > 0) given.push_back(field);
    const bool outputGiven = cmd->count("--output") > 0, seedGiven = cmd->count("--seed") > 0;
    const auto besideJob = jobFile->empty() ? std::vector<std::string>{} : optionsGivenBesideJob(cmd, {"--output", "--seed", "--seeds"});
    run = [o, preset, given, slurm, seeds, jobFile, outputGiven, seedGiven, besideJob]() -> Expected<void> {
      if (!jobFile->empty()) {
        if (auto ok = nothingBesideJob(*jobFile, besideJob, "-o, --seed, --seeds"); !ok) return ok;
        auto job = capture::readCube2Job(*jobFile);
        if (!job) return std::unexpected(job.error());
        if (outputGiven) job->output = o->output;
        if (seedGiven) job->seed = o->seed;
        *o = *job;
      }
      if (o->output.empty()) return fail(ErrorCode::kUsage, "capture cube2: -o DIR is required (in the command or the --job file)");
      if (!preset->empty())
        if (auto ok = capture::applyCube2Preset(*preset, *o, given); !ok) return ok;
      if (slurm->first) return captureOnSlurm(*o, seeds->empty() ? std::to_string(o->seed) : *seeds, slurm->second);
      if (!seeds->empty()) return fail(ErrorCode::kUsage, "--seeds: only with --slurm (one capture per seed); for one capture use --seed");
      return runCube2(*o);
    };
  });
  addCaptureOpenArenaCommand(capture, run);
}

}  // namespace dynbench::cli
