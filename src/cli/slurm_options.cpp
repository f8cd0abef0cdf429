// The --slurm options every command that can run as a Slurm job array shares (docs/cluster.md), and
// the check of what may be given beside a job file (--job), which is what those arrays run.
#include <algorithm>

#include <fmt/ranges.h>

#include "cli/commands.h"

namespace dynbench::cli {

namespace {
const std::string kSlurmGroup = "Slurm (with --slurm)";
}  // namespace

std::vector<std::string> optionsGivenBesideJob(const CLI::App* cmd, std::initializer_list<std::string_view> allowed) {
  std::vector<std::string> given;
  for (const auto* option : cmd->get_options()) {
    const std::string name = option->get_name();
    if (option->count() == 0 || name == "--job" || name == "--help" || name == "--slurm" || option->get_group() == kSlurmGroup) continue;
    if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
    given.push_back(name);
  }
  return given;
}

Expected<void> nothingBesideJob(const std::filesystem::path& jobFile, const std::vector<std::string>& given, std::string_view allowedText) {
  if (given.empty()) return {};
  return fail(ErrorCode::kUsage, "--job {}: the file holds the whole job; {} cannot be given with it (only {} and --slurm's options)", jobFile.string(),
              fmt::join(given, ", "), allowedText);
}

void addSlurmOptions(CLI::App* cmd, bool& slurm, cluster::Options& o, const std::string& what, bool perTask) {
  auto* flag = cmd->add_flag("--slurm", slurm, fmt::format("Run as a Slurm job array ({}) and wait for it", what));
  const std::string& group = kSlurmGroup;
  if (perTask)
    cmd->add_option("--frames-per-task", o.framesPerTask, "Frames per array task")->check(positive())->needs(flag)->group(group)->capture_default_str();
  cmd->add_option("--partition", o.partition, "sbatch --partition")->needs(flag)->group(group);
  cmd->add_option("--time", o.time, "sbatch --time per task, [D-]HH:MM:SS")->needs(flag)->group(group);
  cmd->add_option("--cpus-per-task", o.cpusPerTask, "sbatch --cpus-per-task (a render task renders with this many threads)")
      ->check(positive())->needs(flag)->group(group)->capture_default_str();
  cmd->add_option("--mem", o.mem, "sbatch --mem per task (e.g. 4G)")->needs(flag)->group(group);
  cmd->add_option("--sbatch-option", o.sbatchOptions, "Another sbatch option, verbatim (repeatable): --sbatch-option=--account=X")
      ->needs(flag)->group(group)->allow_extra_args(false);
  cmd->add_flag("--submit-only", o.submitOnly, "Submit and return without waiting")->needs(flag)->group(group);
}

}  // namespace dynbench::cli
