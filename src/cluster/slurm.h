#pragma once
// Slurm job arrays (docs/cluster.md): the one place that talks to Slurm, through its own commands
// (sbatch, squeue, scontrol), so dynbench uses a site's scheduler as it is. A job script is written
// into the output folder (kept, readable, re-submittable by hand), submitted as one `sbatch
// --array`, and, unless asked not to, waited for: its progress from the files it writes and from
// squeue, and at the end the work still missing, by task, with the sbatch command that reruns only
// those tasks. The job runs dynbench itself (this executable, by absolute path), whose stages are
// resumable, so a task that is requeued or rerun continues from its last complete frame.
#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench::cluster {

// What sbatch is asked for (each maps to one sbatch option; docs/cluster.md has the table).
struct Options {
  int framesPerTask = 8;                   // frames (or items) per array task
  std::string partition;                   // --partition; empty: the cluster's default
  std::string time;                        // --time, [D-]HH:MM:SS, MM:SS or MM; empty: the partition's default
  int cpusPerTask = 1;                     // --cpus-per-task; each task renders with this many threads
  std::string mem;                         // --mem (e.g. 4G); empty: the cluster's default
  std::vector<std::string> sbatchOptions;  // more, verbatim (--account=X, --qos=Y, --constraint=Z, ...)
  bool submitOnly = false;                 // submit and return; do not wait
  int signalSeconds = 120;                 // the job's signal (B:USR1) this long before its time limit
  std::filesystem::path executable;        // the dynbench the job runs; empty: this process's
  std::chrono::milliseconds poll{2000};    // how often the wait looks at squeue and the files
};

// A job's array tasks as squeue lists them now (pending, running, completing, requeued, ...).
struct QueuedTask {
  int task = 0;
  std::string state;  // squeue's %T: PENDING, RUNNING, COMPLETING, ...
};

// sbatch on PATH, a controller that answers, and the partition (when one is named) known to it;
// a clear error otherwise, before anything is submitted.
Expected<void> checkCluster(const Options& options);

// Submits a job script; `extra` goes to sbatch before it (e.g. --array=3,5, --dependency=afterok:12).
// First `sbatch --test-only`, so a request the cluster can never satisfy fails here. Returns the job id.
Expected<std::string> submit(const std::filesystem::path& script, const std::vector<std::string>& extra = {});
// The job's tasks still in the queue (empty once all have left it).
Expected<std::vector<QueuedTask>> queuedTasks(const std::string& jobId);
// The final state of each array task scontrol still remembers (COMPLETED, FAILED, CANCELLED, ...).
std::map<int, std::string> taskStates(const std::string& jobId);

// Array tasks by state while a job runs; failed: left the queue without its work complete.
struct ArrayStatus {
  int pending = 0, running = 0, failed = 0, done = 0;
};
// Waits until no task of `jobId` is queued, polling squeue every options.poll; a task that has left
// the queue is done when taskComplete(task) and failed otherwise. Returns the failed tasks.
Expected<std::vector<int>> waitForArray(const std::string& jobId, int tasks, const std::function<bool(int)>& taskComplete,
                                        const std::function<void(const ArrayStatus&)>& progress, const Options& options);
// "sbatch --array=3,5 SCRIPT": reruns only those tasks.
std::string resubmitCommand(const std::vector<int>& tasks, const std::filesystem::path& script);
// The path of the dynbench executable a job runs.
std::filesystem::path jobExecutable(const Options& options);
// Writes an executable job script through a temporary name.
Expected<void> writeScript(const std::filesystem::path& path, const std::string& text);

// The #SBATCH lines and the signal trap shared by every dynbench job script: `name`, the array
// (`tasks` tasks), the log files, --requeue, the signal before the time limit, and the options.
std::string scriptHeader(const std::string& name, int tasks, const std::filesystem::path& logDir, const Options& options);

// The USR1 trap of a job script: `work` names what is stopped in its message, `cleanup` is the shell
// command that removes what the work left unfinished; the work runs in the background as $child.
std::string signalTrap(const std::string& work, const std::string& cleanup);

// A job's command line: the dynbench the job runs (jobExecutable), the verb, each argument quoted.
std::string jobCommand(const Options& options, const std::string& verb, const std::vector<std::string>& arguments);

// A word for a POSIX shell script, single-quoted when it needs to be.
std::string shellQuote(const std::string& word);

// Seconds of a Slurm time ("[D-]HH:MM:SS", "HH:MM:SS", "MM:SS", "MM"); nullopt when malformed.
std::optional<long> parseSlurmTime(const std::string& text);

// ---- a command as a chain of jobs ---------------------------------------------------------------
// A chain of three jobs (demo --slurm, suite --slurm): the datasets, an array of render tasks, and
// the whole command again, which reuses both and writes the final file.
struct ChainStatus {
  std::string datasets, report;  // the one-task jobs' states: PENDING, RUNNING, done, failed
  ArrayStatus render;
};
struct ChainOutcome {
  std::string datasetsJob, renderJob, reportJob;
  std::filesystem::path datasetsScript, renderScript, reportScript;
  int renderTasks = 0;
  std::filesystem::path report;  // the final file (OUT/report.html, OUT/suite.json) when the chain completed
  std::string failure;           // which job failed and where its log is; empty when complete
  bool waited = false;
};
struct ChainSpec {
  std::string name;                     // the command: "demo" or "suite"
  std::filesystem::path output;         // OUT, absolute: OUT/slurm holds the scripts and logs
  std::vector<std::string> arguments;   // the command's arguments but its part
  int frameRenders = 0;                 // divided among the render tasks
  std::string datasetsWhat, finalWhat;  // what the first and last jobs do (script comments)
  std::filesystem::path datasetsDone;   // a file the datasets job has written when it completed
  std::filesystem::path finalFile;      // the file the last job writes
};
// Writes OUT/slurm/{datasets,render,report}.sbatch, each the command with `--part datasets`,
// `--part render --render-task K --frames-per-task F`, and nothing, chained with
// --dependency=afterok and --kill-on-invalid-dep=yes; waits for the last unless submitOnly.
Expected<ChainOutcome> chainOfJobs(const ChainSpec& spec, const Options& options, const std::function<void(const ChainStatus&)>& progress = {});

}  // namespace dynbench::cluster
