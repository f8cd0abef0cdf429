// The --slurm options every command that can run as a Slurm job array shares (docs/cluster.md).
#include "cli/commands.h"

namespace dynbench::cli {

void addSlurmOptions(CLI::App* cmd, bool& slurm, pipeline::slurm::Options& o, const std::string& what, bool perTask) {
  auto* flag = cmd->add_flag("--slurm", slurm, fmt::format("Run as a Slurm job array ({}) and wait for it", what));
  const std::string group = "Slurm (with --slurm)";
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
