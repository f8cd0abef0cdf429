#include "cluster/slurm.h"

#include <sys/stat.h>

#include <algorithm>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/files.h"
#include "core/process.h"

namespace dynbench::cluster {
namespace {

namespace fs = std::filesystem;

struct Output {
  int status = -1;
  std::vector<std::string> lines;  // stdout and stderr, merged
  std::string text() const { return fmt::format("{}", fmt::join(lines, "\n")); }
};

// Runs a Slurm command and keeps what it printed. Fails only when it cannot be started.
Expected<Output> slurmCommand(std::vector<std::string> argv) {
  Output out;
  ProcessOptions p;
  p.argv = std::move(argv);
  p.onLine = [&](std::string_view line) {
    out.lines.emplace_back(line);
    return true;
  };
  auto run = runProcess(p);
  if (!run)
    return fail(ErrorCode::kExternalTool, "{}: {}; --slurm needs Slurm's commands (Debian: slurm-client, or slurm-wlm as scripts/setup.sh --all installs)",
                p.argv.front(), run.error().message);
  out.status = run->exitStatus;
  return out;
}

fs::path thisExecutable() {
  std::error_code ec;
  auto self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path("dynbench") : self;
}

bool allDigits(const std::string& text) {
  return !text.empty() && std::all_of(text.begin(), text.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
}

// squeue's states of a task that waits to run (requeued ones too); any other is running or ending.
bool waiting(const std::string& state) { return state == "PENDING" || state == "REQUEUED" || state == "REQUEUE_HOLD"; }

}  // namespace

std::string jobCommand(const Options& options, const std::string& verb, const std::vector<std::string>& arguments) {
  std::string command = shellQuote(jobExecutable(options).string()) + " " + verb;
  for (const auto& a : arguments) {
    command += ' ';
    command += shellQuote(a);
  }
  return command;
}

std::string shellQuote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("-_./:=,+@%").find(c) != std::string_view::npos;
  });
  if (plain) return word;
  std::string quoted = "'";
  for (char c : word) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::optional<long> parseSlurmTime(const std::string& text) {
  // Slurm's forms (sbatch(1), --time): MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS. Each number
  // has at most 9 digits, so that the seconds fit a long (and std::stol cannot throw out_of_range).
  constexpr std::size_t kMaxDigits = 9;
  long days = 0;
  std::string rest = text;
  if (const auto dash = text.find('-'); dash != std::string::npos) {
    if (dash > kMaxDigits) return std::nullopt;
    try {
      std::size_t used = 0;
      days = std::stol(text.substr(0, dash), &used);
      if (used != dash) return std::nullopt;
    } catch (...) {
      return std::nullopt;
    }
    rest = text.substr(dash + 1);
  }
  std::vector<long> parts;
  std::istringstream in(rest);
  for (std::string part; std::getline(in, part, ':');) {
    if (!allDigits(part) || part.size() > kMaxDigits) return std::nullopt;
    parts.push_back(std::stol(part));
  }
  if (parts.empty() || parts.size() > 3) return std::nullopt;
  if (text.find('-') != std::string::npos) {  // D-HH[:MM[:SS]]
    parts.resize(3, 0);
    return ((days * 24 + parts[0]) * 60 + parts[1]) * 60 + parts[2];
  }
  if (parts.size() == 1) return parts[0] * 60;                      // MM
  if (parts.size() == 2) return parts[0] * 60 + parts[1];           // MM:SS
  return (parts[0] * 60 + parts[1]) * 60 + parts[2];                // HH:MM:SS
}

Expected<void> checkCluster(const Options& options) {
  if (findOnPath("sbatch").empty())
    return fail(ErrorCode::kExternalTool,
                "--slurm: sbatch is not on PATH; run where Slurm's commands are (a cluster's login node), install them (Debian: "
                "slurm-client), or render without --slurm");
  auto ping = slurmCommand({"scontrol", "ping"});
  if (!ping) return std::unexpected(ping.error());
  if (ping->status != 0 || ping->text().find("is UP") == std::string::npos)
    return fail(ErrorCode::kExternalTool, "--slurm: the Slurm controller does not answer (scontrol ping: {}){}",
                ping->lines.empty() ? "no output" : ping->lines.front(),
                std::getenv("SLURM_CONF") ? fmt::format("; SLURM_CONF is {}", std::getenv("SLURM_CONF")) : std::string());
  if (!options.partition.empty()) {
    auto shown = slurmCommand({"scontrol", "-o", "show", "partition", options.partition});
    if (!shown) return std::unexpected(shown.error());
    if (shown->status != 0 || shown->text().find("PartitionName=" + options.partition) == std::string::npos) {
      auto all = slurmCommand({"sinfo", "-h", "-o", "%R"});
      std::string names = all && all->status == 0 ? fmt::format("{}", fmt::join(all->lines, ", ")) : "unknown";
      return fail(ErrorCode::kUsage, "--partition {}: no such partition on this cluster (its partitions: {})", options.partition, names);
    }
  }
  if (!options.time.empty() && !parseSlurmTime(options.time))
    return fail(ErrorCode::kUsage, "--time '{}': expected [D-]HH:MM:SS, HH:MM:SS, MM:SS or MM", options.time);
  if (options.framesPerTask < 1) return fail(ErrorCode::kUsage, "--frames-per-task {}: expected at least 1", options.framesPerTask);
  if (options.cpusPerTask < 1) return fail(ErrorCode::kUsage, "--cpus-per-task {}: expected at least 1", options.cpusPerTask);
  return {};
}

Expected<std::string> submit(const fs::path& script, const std::vector<std::string>& extra) {
  auto sbatch = [&](const char* mode) {
    std::vector<std::string> argv = {"sbatch", mode};
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.push_back(script.string());
    return slurmCommand(argv);
  };
  auto tested = sbatch("--test-only");
  if (!tested) return std::unexpected(tested.error());
  if (tested->status != 0)
    return fail(ErrorCode::kExternalTool, "{}: Slurm would not accept the job (sbatch --test-only: {}); nothing was submitted", script.string(),
                tested->text());
  auto submitted = sbatch("--parsable");
  if (!submitted) return std::unexpected(submitted.error());
  // --parsable prints "JOBID" or "JOBID;CLUSTER" (after any warnings).
  std::string id = submitted->lines.empty() ? "" : submitted->lines.back();
  id = id.substr(0, id.find(';'));
  if (submitted->status != 0 || !allDigits(id))
    return fail(ErrorCode::kExternalTool, "{}: sbatch failed: {}", script.string(), submitted->text());
  return id;
}

Expected<std::vector<QueuedTask>> queuedTasks(const std::string& jobId) {
  auto listed = slurmCommand({"squeue", "-h", "-r", "-j", jobId, "-o", "%K %T"});
  if (!listed) return std::unexpected(listed.error());
  std::vector<QueuedTask> tasks;
  if (listed->status != 0) {
    // A job the controller has forgotten (older than MinJobAge) is no longer queued.
    if (listed->text().find("Invalid job id") != std::string::npos) return tasks;
    return fail(ErrorCode::kExternalTool, "squeue -j {}: {}", jobId, listed->text());
  }
  for (const auto& line : listed->lines) {
    QueuedTask t;
    std::istringstream in(line);
    if (in >> t.task >> t.state) tasks.push_back(t);
  }
  return tasks;
}

std::map<int, std::string> taskStates(const std::string& jobId) {
  std::map<int, std::string> states;
  auto shown = slurmCommand({"scontrol", "-o", "show", "job", jobId});
  if (!shown || shown->status != 0) return states;
  for (const auto& line : shown->lines) {
    auto field = [&](const std::string& key) -> std::string {
      const auto at = line.find(" " + key + "=");
      if (at == std::string::npos) return {};
      const auto start = at + key.size() + 2;
      return line.substr(start, line.find(' ', start) - start);
    };
    const std::string task = field("ArrayTaskId"), state = field("JobState");
    if (allDigits(task))
      states[std::stoi(task)] = state;
  }
  return states;
}

Expected<std::vector<int>> waitForArray(const std::string& jobId, int tasks, const std::function<bool(int)>& taskComplete,
                                        const std::function<void(const ArrayStatus&)>& progress, const Options& options) {
  for (;;) {
    auto queued = queuedTasks(jobId);
    if (!queued) return std::unexpected(queued.error());
    ArrayStatus status;
    std::vector<bool> inQueue(static_cast<std::size_t>(tasks), false);
    for (const auto& t : *queued) {
      if (t.task >= 0 && t.task < tasks) inQueue[static_cast<std::size_t>(t.task)] = true;
      (waiting(t.state) ? status.pending : status.running)++;
    }
    std::vector<int> failed;
    for (int k = 0; k < tasks; ++k) {
      if (inQueue[static_cast<std::size_t>(k)]) continue;
      if (taskComplete(k)) {
        ++status.done;
      } else {
        failed.push_back(k);
        ++status.failed;
      }
    }
    if (progress) progress(status);
    if (queued->empty()) return failed;
    std::this_thread::sleep_for(options.poll);
  }
}

std::string resubmitCommand(const std::vector<int>& tasks, const fs::path& script) {
  return fmt::format("sbatch --array={} {}", fmt::join(tasks, ","), shellQuote(script.string()));
}

fs::path jobExecutable(const Options& options) { return options.executable.empty() ? thisExecutable() : options.executable; }

Expected<void> writeScript(const fs::path& path, const std::string& text) {
  if (auto ok = writeFileAtomic(path, text); !ok) return std::unexpected(ok.error());
  if (::chmod(path.c_str(), 0755) != 0) return fail(ErrorCode::kIo, "{}: cannot make it executable", path.string());
  return {};
}

std::string signalTrap(const std::string& work, const std::string& cleanup) {
  return fmt::format(
      "# The signal before the time limit (or a preemption): stop the work, remove what it left\n"
      "# unfinished, and put this task, only this one, back in the queue.\n"
      "on_signal() {{\n"
      "  echo \"dynbench: stopping {0}; task ${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}} goes back to the queue\"\n"
      "  kill -TERM \"$child\" 2>/dev/null\n"
      "  wait \"$child\" 2>/dev/null\n"
      "  {1}\n"
      "  scontrol requeue \"${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}\"\n"
      "  exit 0\n"
      "}}\n"
      "trap on_signal USR1\n"
      "echo \"dynbench: task ${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}} started $(date -u +%Y-%m-%dT%H:%M:%S.%N) on $(hostname)\"\n",
      work, cleanup);
}

std::string scriptHeader(const std::string& name, int tasks, const fs::path& logDir, const Options& options) {
  // The signal comes signalSeconds before the time limit, but at most a quarter of a short limit in.
  long signal = options.signalSeconds;
  if (auto limit = parseSlurmTime(options.time)) signal = std::clamp<long>(*limit / 4, 1, signal);
  std::string h = "#!/bin/bash\n";
  h += fmt::format("#SBATCH --job-name={}\n", name);
  h += fmt::format("#SBATCH --array=0-{}\n", tasks - 1);
  h += fmt::format("#SBATCH --output={}\n", (logDir / "task-%A_%a.log").string());
  h += "#SBATCH --open-mode=append\n";  // a requeued task adds to its log instead of replacing it
  h += "#SBATCH --requeue\n";
  h += fmt::format("#SBATCH --signal=B:USR1@{}\n", signal);
  h += fmt::format("#SBATCH --cpus-per-task={}\n", options.cpusPerTask);
  if (!options.partition.empty()) h += fmt::format("#SBATCH --partition={}\n", options.partition);
  if (!options.time.empty()) h += fmt::format("#SBATCH --time={}\n", options.time);
  if (!options.mem.empty()) h += fmt::format("#SBATCH --mem={}\n", options.mem);
  for (const auto& o : options.sbatchOptions) h += fmt::format("#SBATCH {}\n", o);
  return h;
}

Expected<ChainOutcome> chainOfJobs(const ChainSpec& spec, const Options& options, const std::function<void(const ChainStatus&)>& progress) {
  if (auto ok = checkCluster(options); !ok) return std::unexpected(ok.error());
  const fs::path jobDir = spec.output / "slurm";
  std::error_code ec;
  fs::create_directories(jobDir, ec);
  if (ec) return fail(ErrorCode::kIo, "{}: cannot create the jobs' folder: {}", jobDir.string(), ec.message());
  ChainOutcome out;
  out.renderTasks = (spec.frameRenders + options.framesPerTask - 1) / options.framesPerTask;
  const std::string command = jobCommand(options, spec.name, spec.arguments);
  // Every part is the command itself, run in the background so the signal trap can stop it; its
  // outputs are written through temporary names, so a stopped part leaves nothing to clean.
  auto script = [&](const std::string& name, int tasks, const std::string& part, const std::string& what) {
    std::string text = scriptHeader(fmt::format("dynbench-{}-{}", spec.name, name), tasks, jobDir, options);
    text += fmt::format("#\n# Part of `dynbench {} --slurm` (docs/cluster.md): {}.\nset -u\n", spec.name, what);
    text += signalTrap(fmt::format("the {}'s {}", spec.name, name), ":");
    text += command + part + " &\nchild=$!\nwait \"$child\"\n";
    return text;
  };
  out.datasetsScript = jobDir / "datasets.sbatch";
  out.renderScript = jobDir / "render.sbatch";
  out.reportScript = jobDir / "report.sbatch";
  for (const auto& [path, text] :
       {std::pair{out.datasetsScript, script("datasets", 1, " --part datasets", spec.datasetsWhat)},
        std::pair{out.renderScript,
                  script("render", out.renderTasks,
                         fmt::format(" --part render --render-task \"$SLURM_ARRAY_TASK_ID\" --frames-per-task {} --threads \"${{SLURM_CPUS_PER_TASK:-1}}\"",
                                     options.framesPerTask),
                         fmt::format("task k renders frame renders {0}k to {0}k+{1} of the {2}'s {3}", options.framesPerTask,
                                     options.framesPerTask - 1, spec.name, spec.frameRenders))},
        std::pair{out.reportScript, script("report", 1, "", spec.finalWhat)}})
    if (auto ok = writeScript(path, text); !ok) return std::unexpected(ok.error());
  auto datasets = submit(out.datasetsScript);
  if (!datasets) return std::unexpected(datasets.error());
  out.datasetsJob = *datasets;
  auto render = submit(out.renderScript, {"--dependency=afterok:" + out.datasetsJob, "--kill-on-invalid-dep=yes"});
  if (!render) return std::unexpected(render.error());
  out.renderJob = *render;
  auto report = submit(out.reportScript, {"--dependency=afterok:" + out.renderJob, "--kill-on-invalid-dep=yes"});
  if (!report) return std::unexpected(report.error());
  out.reportJob = *report;
  if (options.submitOnly) return out;

  const auto submitted = fs::file_time_type::clock::now();
  auto reportWritten = [&] {
    std::error_code e;
    return fs::is_regular_file(spec.finalFile, e) && fs::last_write_time(spec.finalFile, e) >= submitted;
  };
  // One-task jobs by their squeue state; the render array by its tasks.
  auto state = [&](const std::string& job, const std::function<bool()>& complete) -> Expected<std::string> {
    auto q = queuedTasks(job);
    if (!q) return std::unexpected(q.error());
    if (!q->empty()) return q->front().state;
    return complete() ? std::string("done") : std::string("failed");
  };
  for (;;) {
    ChainStatus status;
    auto a = state(out.datasetsJob, [&] { return fs::is_regular_file(spec.datasetsDone); });
    if (!a) return std::unexpected(a.error());
    status.datasets = *a;
    auto r = queuedTasks(out.renderJob);
    if (!r) return std::unexpected(r.error());
    for (const auto& t : *r) (waiting(t.state) ? status.render.pending : status.render.running)++;
    status.render.done = out.renderTasks - status.render.pending - status.render.running;
    auto c = state(out.reportJob, reportWritten);
    if (!c) return std::unexpected(c.error());
    status.report = *c;
    if (progress) progress(status);
    if (status.report == "done" || status.report == "failed") break;
    std::this_thread::sleep_for(options.poll);
  }
  out.waited = true;
  if (reportWritten()) {
    out.report = spec.finalFile;
    return out;
  }
  // Which part failed: the first whose job did not complete.
  for (const auto& [name, job] : {std::pair{"datasets", out.datasetsJob}, std::pair{"render", out.renderJob}, std::pair{"report", out.reportJob}}) {
    const auto states = taskStates(job);
    std::vector<int> bad;
    for (const auto& [task, st] : states)
      if (st != "COMPLETED") bad.push_back(task);
    if (!bad.empty() || states.empty()) {
      out.failure = fmt::format("the {} job ({}) did not complete{}; its logs: {}", name, job,
                                states.empty() ? "" : fmt::format(" (task(s) {}: {})", fmt::join(bad, ","), states.at(bad.front())),
                                (jobDir / fmt::format("task-{}_*.log", job)).string());
      break;
    }
  }
  if (out.failure.empty()) out.failure = fmt::format("the last job ({}) ended without writing {}", out.reportJob, spec.finalFile.string());
  return out;
}

}  // namespace dynbench::cluster
