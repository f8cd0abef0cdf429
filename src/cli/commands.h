#pragma once
// Each subcommand registers itself on the CLI11 app and leaves a function to run after parsing.
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/error.h"
#include "core/progress.h"
#include "pipeline/cluster_jobs.h"

namespace dynbench::cli {

using CommandRun = std::function<Expected<void>()>;

// Registers `stats`; sets `run` when the user picked it.
void addStatsCommand(CLI::App& app, CommandRun& run);

// Registers `capture-check`.
void addCaptureCheckCommand(CLI::App& app, CommandRun& run);

// Registers `convert`.
void addConvertCommand(CLI::App& app, CommandRun& run);

// Registers `merge-camera`.
void addMergeCameraCommand(CLI::App& app, CommandRun& run);

// Registers `flythrough`.
void addFlythroughCommand(CLI::App& app, CommandRun& run);
void addVrCameraCommand(CLI::App& app, CommandRun& run);

// Registers `render`.
void addRenderCommand(CLI::App& app, CommandRun& run);

// Registers `discard`.
void addDiscardCommand(CLI::App& app, CommandRun& run);

// Registers `report`.
void addReportCommand(CLI::App& app, CommandRun& run);

// Registers `capture cube2` and `capture openarena`.
void addCaptureCommand(CLI::App& app, CommandRun& run);
void addCaptureOpenArenaCommand(CLI::App* capture, CommandRun& run);

// Registers `fidelity`.
void addFidelityCommand(CLI::App& app, CommandRun& run);

// Registers `compare`.
void addCompareCommand(CLI::App& app, CommandRun& run);

// Registers `evaluate`.
void addEvaluateCommand(CLI::App& app, CommandRun& run);

// The --slurm flag and its sbatch options (docs/cluster.md); `what` says what the array runs,
// perTask adds --frames-per-task.
void addSlurmOptions(CLI::App* cmd, bool& slurm, cluster::Options& options, const std::string& what, bool perTask);

// Job files (--job FILE, docs/cli.md "Job files"): the options given on `cmd`'s command line other
// than --job, --help, `allowed` and --slurm's, by name; each is an error beside --job, as the file
// holds the whole job. Call it in the subcommand's callback (after parsing).
std::vector<std::string> optionsGivenBesideJob(const CLI::App* cmd, std::initializer_list<std::string_view> allowed);
// A usage error naming them, or nothing when `given` is empty.
Expected<void> nothingBesideJob(const std::filesystem::path& jobFile, const std::vector<std::string>& given, std::string_view allowedText);

// Registers `suite` and `suite verify`.
void addSuiteCommand(CLI::App& app, CommandRun& run);

// Progress for work reported in named steps (maplight's fit): a bar per step, kept in `bar`, which
// the caller resets when the work ends. Silent off a terminal, as Progress is.
using StepProgress = std::function<void(const std::string& step, std::size_t done, std::size_t total)>;
StepProgress stepProgress(const std::string& label, std::unique_ptr<Progress>& bar);

// Registers `map-lights`.
void addMapLightsCommand(CLI::App& app, CommandRun& run);

// Registers `demo`.
void addDemoCommand(CLI::App& app, CommandRun& run);

// Number checks for options (CLI11's own print the limits of double in full). A failed check is a
// usage error, status 2, like every other malformed argument.
CLI::Validator positive();     // > 0
CLI::Validator nonNegative();  // >= 0
CLI::Validator between(double low, double high);  // [low, high]

// "WIDTHxHEIGHT" of a --res option (render, demo).
Expected<std::pair<int, int>> parseResolution(const std::string& text);

// Exit status for an error (docs/cli.md lists them).
int exitCode(const Error& error);

}  // namespace dynbench::cli
