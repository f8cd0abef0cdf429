// `dynbench render --slurm` against a real Slurm: each test process brings up its own single-node
// cluster with scripts/slurm-local.sh (Debian's slurm-wlm and munge; its own folder and ports),
// submits real job arrays, watches them with Slurm's own squeue and scontrol, and stops it.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <algorithm>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "core/files.h"
#include "core/image_io.h"
#include "external_tools.h"
#include "frames/frame_io.h"
#include "gltf_builder.h"
#include "pipeline/cluster_jobs.h"
#include "run_cli.h"
#include "shared_run.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kSlurmLocal = fs::path(DYNBENCH_SOURCE_DIR) / "scripts" / "slurm-local.sh";

std::string shell(const std::string& command) {
  std::string out;
  runShell(command + " 2>&1", out);
  return out;
}

class Slurm : public ::testing::Test {
 protected:
  // One cluster per test process (ctest runs each test in its own), on ports of its own, so tests
  // may run side by side.
  static void SetUpTestSuite() {
    if (!test::missingSlurm().empty()) return;
    dir_ = test::freshDir("slurm_cluster");
    int port = 21000 + static_cast<int>(::getpid() % 4900) * 2;
    if (port >= 26816 && port <= 26818) port += 4;  // not slurm-local.sh's default ports, which a user's cluster may hold
    env_ = fmt::format("DYNBENCH_SLURM_DIR={} DYNBENCH_SLURM_CTLD_PORT={} DYNBENCH_SLURM_SLURMD_PORT={}", dir_.string(), port, port + 1);
    started_ = shell(fmt::format("{} {} start", env_, kSlurmLocal.string()));
    ::setenv("SLURM_CONF", (dir_ / "slurm.conf").c_str(), 1);
  }
  static void TearDownTestSuite() {
    if (!env_.empty()) shell(fmt::format("{} {} stop", env_, kSlurmLocal.string()));
  }
  void SetUp() override {
    DYNBENCH_NEEDS(test::missingSlurm());
    ASSERT_NE(started_.find("slurm-local: up"), std::string::npos) << started_;
  }
  static inline fs::path dir_;
  static inline std::string env_, started_;
};

// squeue's tasks of a job ("0 RUNNING", ...), one per line.
std::vector<std::pair<int, std::string>> queued(const std::string& job) {
  std::vector<std::pair<int, std::string>> tasks;
  std::istringstream in(shell(fmt::format("squeue -h -r -j {} -o '%K %T'", job)));
  int task = 0;
  std::string state;
  while (in >> task >> state) tasks.emplace_back(task, state);
  return tasks;
}

void waitUntilGone(const std::string& job) {
  ASSERT_TRUE(!job.empty() && job.find_first_not_of("0123456789") == std::string::npos) << "'" << job << "' is not a job id";
  for (int i = 0; i < 600 && !queued(job).empty(); ++i) std::this_thread::sleep_for(200ms);
  ASSERT_TRUE(queued(job).empty()) << "job " << job << " still queued after 2 minutes";
}

// A task's log (which may not exist yet) says its script has started.
bool hasStarted(const fs::path& log) {
  std::ifstream in(log);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str().find(" started ") != std::string::npos;
}

// Every file of `local` is in `slurm` with the same bytes (the job's slurm/ folder aside).
void expectSameFrames(const fs::path& local, const fs::path& slurm, std::size_t frames) {
  std::size_t compared = 0;
  for (const auto& e : fs::directory_iterator(local)) {
    if (!e.is_regular_file()) continue;
    EXPECT_TRUE(test::slurp(e.path()) == test::slurp(slurm / e.path().filename())) << e.path().filename() << " differs";
    ++compared;
  }
  EXPECT_EQ(compared, 2 * frames);  // an EXR and a sidecar each
}

TEST_F(Slurm, RenderArrayOfSixTasksMatchesALocalRender) {
  const auto dir = test::freshDir("slurm_render");
  const fs::path out = dir / "frames";
  const std::string options = "--frames 0:23 --res 32x18 --spp 2 --bounces 2 --seed 7";
  auto r = dynbench(fmt::format("render {} -o {} {} --slurm --frames-per-task 4 --submit-only", kOrbit.string(), out.string(), options), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("Slurm job (\\d+), 6 task\\(s\\) of at most 4 frame\\(s\\)"))) << r.out;
  const std::string job = m[1];
  // Slurm's own record: one array job of tasks 0-5, and the script it runs, kept in the folder.
  const std::string record = shell(fmt::format("scontrol -o show job {}", job));
  EXPECT_NE(record.find("ArrayJobId=" + job), std::string::npos) << record;
  EXPECT_NE(record.find(fmt::format("Command={}", (out / "slurm" / "render.sbatch").string())), std::string::npos) << record;
  const std::string script = test::slurp(out / "slurm" / "render.sbatch");
  EXPECT_NE(script.find("#SBATCH --array=0-5\n"), std::string::npos) << script;
  EXPECT_NE(script.find("chunks=(0:3 4:7 8:11 12:15 16:19 20:23)"), std::string::npos) << script;
  EXPECT_NE(script.find("#SBATCH --requeue\n"), std::string::npos);
  EXPECT_NE(script.find("#SBATCH --signal=B:USR1@"), std::string::npos);
  // Every task runs the one job file (docs/cli.md, "Job files"), which holds the job as given.
  EXPECT_NE(script.find(fmt::format(" render --job {} --frames \"$frames\"", (out / "slurm" / "render-job.json").string())), std::string::npos)
      << script;
  const auto jobFile = nlohmann::json::parse(test::slurp(out / "slurm" / "render-job.json"));
  EXPECT_EQ(jobFile["dataset"], kOrbit.string());
  EXPECT_EQ(jobFile["output"], out.string());
  EXPECT_EQ(jobFile["samples_per_pixel"], 2);
  EXPECT_EQ(jobFile["seed"], 7);
  ASSERT_NO_FATAL_FAILURE(waitUntilGone(job));
  std::set<int> tasks;  // every task ran and logged its render
  for (const auto& e : fs::directory_iterator(out / "slurm")) {
    std::smatch t;
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, t, std::regex("task-" + job + "_(\\d+)\\.log"))) {
      tasks.insert(std::stoi(t[1]));
      EXPECT_NE(test::slurp(e.path()).find("4 frame(s) rendered"), std::string::npos) << name << ": " << test::slurp(e.path());
    }
  }
  EXPECT_EQ(tasks, (std::set<int>{0, 1, 2, 3, 4, 5}));
  // The same frames rendered here, with the same (absolute) dataset path the job recorded.
  r = dynbench(fmt::format("render {} -o {} {} --threads 2", kOrbit.string(), (dir / "local").string(), options), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  expectSameFrames(dir / "local", out, 24);
}

TEST_F(Slurm, ASignalledTaskRequeuesAndACancelledOneIsReportedAndRerun) {
  const auto dir = test::freshDir("slurm_failures");
  const fs::path out = dir / "frames";
  // About a second a frame on one core, so that tasks are caught running.
  const std::string options = "--frames 0:11 --res 160x90 --spp 512 --bounces 2";
  const std::string command = fmt::format("{} render {} -o {} {} --slurm --frames-per-task 4", DYNBENCH_EXE, kOrbit.string(), out.string(), options);
  // The waiting dynbench runs in the background; its job id comes from the script's log names.
  std::string waitOutput;
  int waitStatus = -1;
  std::thread waiting([&] { waitStatus = runShell(command + " 2>&1", waitOutput); });
  std::string job;
  auto runningTask = [&](int not_) {
    for (int i = 0; i < 600; ++i) {
      if (job.empty()) {
        const std::string ids = shell("squeue -h -o %F -n dynbench-render | head -n 1");
        if (!ids.empty() && std::isdigit(static_cast<unsigned char>(ids[0]))) job = ids.substr(0, ids.find('\n'));
      }
      // Running, and its script past `trap` (it logs "started" after it): a signal before that
      // would end the task instead of requeueing it.
      if (!job.empty())
        for (const auto& [task, state] : queued(job))
          if (state == "RUNNING" && task != not_ &&
              hasStarted(out / "slurm" / fmt::format("task-{}_{}.log", job, task)))
            return task;
      std::this_thread::sleep_for(100ms);
    }
    return -1;
  };
  // A signal as before the time limit (B:USR1 to the batch shell): the task stops its render and
  // puts itself back in the queue; it later resumes and completes.
  const int signalled = runningTask(-1);
  ASSERT_GE(signalled, 0) << "no task ran";
  EXPECT_EQ(shell(fmt::format("scancel --batch --signal=USR1 {}_{}", job, signalled)), "");
  // Another running task is cancelled outright.
  const int cancelled = runningTask(signalled);
  ASSERT_GE(cancelled, 0);
  EXPECT_EQ(shell(fmt::format("scancel {}_{}", job, cancelled)), "");
  // Slurm holds a requeued batch job back for two minutes (its BeginTime); the test lets it start
  // after three seconds rather than wait. Not at once: slurmd revokes the first run's credential
  // when the requeue kills it, and refuses a new one issued within the same second ("Killing
  // non-startable batch job: Job credential revoked"), which ends the task FAILED.
  for (int i = 0; i < 100; ++i) {
    const std::string reason = shell(fmt::format("squeue -h -j {}_{} -o %r", job, signalled));
    if (reason.find("BeginTime") != std::string::npos) {
      EXPECT_EQ(shell(fmt::format("scontrol update jobid={}_{} StartTime=now+3", job, signalled)), "");
      break;
    }
    std::this_thread::sleep_for(100ms);
  }
  waiting.join();
  // The signalled task went back to the queue (Slurm counts a restart) and said why in its log.
  EXPECT_NE(shell(fmt::format("scontrol -o show job {}_{}", job, signalled)).find("Restarts=1"), std::string::npos);
  std::string log;
  for (const auto& e : fs::directory_iterator(out / "slurm"))
    if (e.path().filename().string() == fmt::format("task-{}_{}.log", job, signalled)) log = test::slurp(e.path());
  EXPECT_NE(log.find("goes back to the queue"), std::string::npos) << log;
  // The wait reports the cancelled task's frames and exits 8, with the command that reruns it.
  EXPECT_EQ(waitStatus, 8) << waitOutput;
  std::smatch missing;  // the frames it had not finished: the end of its chunk
  ASSERT_TRUE(std::regex_search(waitOutput, missing, std::regex(fmt::format("task {} \\(CANCELLED\\): frames (\\d+)(-(\\d+))?", cancelled))))
      << waitOutput;
  EXPECT_GE(std::stoi(missing[1]), 4 * cancelled);
  EXPECT_EQ(missing[3].matched ? std::stoi(missing[3]) : std::stoi(missing[1]), 4 * cancelled + 3);
  const std::string rerun = fmt::format("sbatch --array={} {}", cancelled, (out / "slurm" / "render.sbatch").string());
  EXPECT_NE(waitOutput.find("Rerun only those tasks: " + rerun), std::string::npos) << waitOutput;
  // No frame file is half-written under its final name: every EXR there reads.
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().extension() == ".exr") EXPECT_TRUE(readImageHeader(e.path())) << e.path();
  // The printed command completes the missing frames.
  // sbatch reads its options before the script (anything after it goes to the script), so
  // --parsable goes first; the wait then has the job id to wait for.
  const std::string resubmitted =
      shell(fmt::format("sbatch --parsable --array={} {}", cancelled, (out / "slurm" / "render.sbatch").string()));
  const std::string rerunJob = resubmitted.substr(0, resubmitted.find_first_of(";\n"));
  ASSERT_NO_FATAL_FAILURE(waitUntilGone(rerunJob));
  auto r = dynbench(fmt::format("render {} -o {} {} --threads 2", kOrbit.string(), (dir / "local").string(), options), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  expectSameFrames(dir / "local", out, 12);
}

TEST_F(Slurm, BadRequestsFailBeforeAnythingIsSubmitted) {
  const auto dir = test::freshDir("slurm_bad");
  const std::string before = shell("squeue -h -o %i");
  const std::string render = fmt::format("render {} --frames 0:3 --res 16x9 --spp 1", kOrbit.string());
  // A partition the cluster does not have.
  auto r = dynbench(fmt::format("{} -o {} --slurm --partition gpu-nope", render, (dir / "a").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--partition gpu-nope: no such partition on this cluster (its partitions: local)"), std::string::npos) << r.err;
  // An output folder the job cannot write (under a file).
  ASSERT_TRUE(writeFileAtomic(dir / "file", "x"));
  r = dynbench(fmt::format("{} -o {} --slurm", render, (dir / "file" / "frames").string()), dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("cannot create the job's folder"), std::string::npos) << r.err;
  // A controller that does not answer: the same cluster's configuration, another port.
  std::string conf = test::slurp(dir_ / "slurm.conf");
  conf = std::regex_replace(conf, std::regex("SlurmctldPort=\\d+"), "SlurmctldPort=1");
  ASSERT_TRUE(writeFileAtomic(dir / "down.conf", conf));
  std::string out;
  int status = runShell(fmt::format("SLURM_CONF={} {} {} -o {} --slurm 2>&1", (dir / "down.conf").string(), DYNBENCH_EXE, render,
                                    (dir / "b").string()),
                        out);
  EXPECT_EQ(status, 7) << out;
  EXPECT_NE(out.find("the Slurm controller does not answer (scontrol ping: Slurmctld(primary) at"), std::string::npos) << out;
  // No sbatch on PATH.
  out.clear();
  status = runShell(fmt::format("PATH={} {} {} -o {} --slurm 2>&1", (dir / "nothing").string(), DYNBENCH_EXE, render, (dir / "c").string()), out);
  EXPECT_EQ(status, 7) << out;
  EXPECT_NE(out.find("sbatch is not on PATH"), std::string::npos) << out;
  // A request the cluster can never meet (more CPUs than the node has): sbatch --test-only says so.
  r = dynbench(fmt::format("{} -o {} --slurm --cpus-per-task 4096", render, (dir / "d").string()), dir);
  EXPECT_EQ(r.status, 7) << r.err;
  EXPECT_NE(r.err.find("Slurm would not accept the job (sbatch --test-only:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing was submitted"), std::string::npos) << r.err;
  // Slurm options without --slurm are a usage error.
  r = dynbench(fmt::format("{} -o {} --frames-per-task 4", render, (dir / "e").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(shell("squeue -h -o %i"), before);  // nothing was submitted
  for (const char* folder : {"a", "b", "c", "d", "e"}) EXPECT_FALSE(fs::exists(dir / folder / "frame_00000.exr")) << folder;
}

TEST_F(Slurm, CaptureArrayOfSeedsMatchesLocalCaptures) {
  DYNBENCH_NEEDS(test::missingCube2());
  const auto dir = test::freshDir("slurm_capture");
  const std::string match = "--seconds 1 --bots 2 --warmup 2";
  auto r = dynbench(fmt::format("capture cube2 -o {} {} --slurm --seeds 4:5", (dir / "cluster").string(), match), dir);
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("2 capture(s)"), std::string::npos) << r.out;
  const std::string script = test::slurp(dir / "cluster" / "slurm" / "capture.sbatch");
  EXPECT_NE(script.find("seeds=(4 5)"), std::string::npos);
  // Every task runs the one job file, with its own output and seed.
  EXPECT_NE(script.find(fmt::format(" capture cube2 --job {} -o \"$partial\" --seed \"$seed\"", (dir / "cluster" / "slurm" / "capture-job.json").string())),
            std::string::npos)
      << script;
  for (int seed : {4, 5}) EXPECT_FALSE(fs::exists(dir / "cluster" / fmt::format("seed_{}.partial", seed)));
  // Each task's capture is the one a local capture with its seed makes, byte for byte.
  r = dynbench(fmt::format("capture cube2 -o {} {} --seed 5", (dir / "local5").string(), match), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string local = test::slurp(dir / "local5" / "Capture.txt");
  EXPECT_FALSE(local.empty());
  EXPECT_TRUE(local == test::slurp(dir / "cluster" / "seed_5" / "Capture.txt"));
  EXPECT_FALSE(local == test::slurp(dir / "cluster" / "seed_4" / "Capture.txt"));  // another seed, another match
  // --seeds without --slurm is a usage error.
  r = dynbench(fmt::format("capture cube2 -o {} --seeds 1:2", (dir / "x").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
}

TEST_F(Slurm, DemoAsAChainOfJobsGivesTheLocalDemosTables) {
  DYNBENCH_NEEDS(test::missingCube2());
  DYNBENCH_NEEDS(test::missingFfmpeg());
  const auto dir = test::freshDir("slurm_demo");
  const std::string options = "--seconds 3 --bots 4 --res 32x18 --spp 1 --max-spp 32 --render-frames 12 --bounces 1";
  auto r = dynbench(fmt::format("demo -o {} {} --slurm --frames-per-task 20", (dir / "cluster").string(), options), dir);
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  // Three jobs chained: the datasets, an array of 4 render tasks (80 frame renders, 20 a task: per
  // dataset 12 reference frames, 12 of each input, jittered and still, and 4 of the noise floor),
  // the report; Slurm's record of the render job names its dependency on the datasets job.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("Slurm jobs: datasets (\\d+) .*render (\\d+) \\(4 tasks.*report (\\d+) "))) << r.out;
  for (const char* script : {"datasets.sbatch", "render.sbatch", "report.sbatch"})
    EXPECT_TRUE(fs::exists(dir / "cluster" / "slurm" / script)) << script;
  EXPECT_NE(test::slurp(dir / "cluster" / "slurm" / "render.sbatch").find("#SBATCH --array=0-3\n"), std::string::npos);
  // Each job runs the demo's one job file, which holds the options as given.
  const fs::path jobFile = dir / "cluster" / "slurm" / "demo-job.json";
  for (const char* script : {"datasets.sbatch", "render.sbatch", "report.sbatch"})
    EXPECT_NE(test::slurp(dir / "cluster" / "slurm" / script).find(" demo --job " + jobFile.string()), std::string::npos) << script;
  const auto job = nlohmann::json::parse(test::slurp(jobFile));
  EXPECT_FALSE(job.contains("render"));  // flat, as docs/cli.md spells it
  EXPECT_EQ(job["width"], 32);
  EXPECT_EQ(job["frames"], 12);
  EXPECT_EQ(job["max_spp"], 32);
  // The local demo is Demo.WholeChainOnAShortMatch's (shared_run.h: made once for both).
  const auto localRun = test::sharedRun("demo", "demo -o {out} " + options);
  ASSERT_EQ(localRun.run.status, 0) << localRun.run.err;
  // The same tables, every cell (the figures' file names aside).
  auto tables = [](const std::string& md) {
    std::string rows;
    std::istringstream in(md);
    for (std::string line; std::getline(in, line);)
      if (line.starts_with("|") || line.starts_with("Table")) rows += line + "\n";
    return rows;
  };
  const std::string local = tables(test::slurp(localRun.output / "report.md"));
  EXPECT_GT(std::count(local.begin(), local.end(), '\n'), 30);
  EXPECT_EQ(local, tables(test::slurp(dir / "cluster" / "report.md")));
}

TEST_F(Slurm, SuiteAsAChainOfJobsGivesTheLocalSuitesNumbers) {
  DYNBENCH_NEEDS(test::missingCube2());
  const auto dir = test::freshDir("slurm_suite");
  const fs::path smoke = fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "smoke.json";
  auto r = dynbench(fmt::format("suite {} -o {} --slurm --frames-per-task 33", smoke.string(), (dir / "cluster").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  // Three jobs chained: the datasets, an array of 4 render tasks (6 datasets x (3 renders x 6
  // frames: reference, jittered and still input; + 4 noise-floor frames) = 132 frame renders, 33 a
  // task), the whole suite.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("Slurm jobs: datasets (\\d+) .*render (\\d+) \\(4 tasks.*suite (\\d+) "))) << r.out;
  EXPECT_NE(test::slurp(dir / "cluster" / "slurm" / "render.sbatch").find("#SBATCH --array=0-3\n"), std::string::npos);
  // The local run is Suite.SmokeSuite...'s (shared_run.h: made once for both).
  const auto localRun = test::sharedRun("smoke-suite", fmt::format("suite {} -o {{out}}", smoke.string()));
  ASSERT_EQ(localRun.run.status, 0) << localRun.run.err;
  // The same numbers and the same frames, byte for byte: the renders are seeded, whoever runs them.
  // (Sidecars name the dataset's absolute path, so only the images are compared.)
  const auto local = nlohmann::json::parse(test::slurp(localRun.output / "suite.json"));
  const auto cluster = nlohmann::json::parse(test::slurp(dir / "cluster" / "suite.json"));
  EXPECT_EQ(local["datasets"], cluster["datasets"]);
  EXPECT_EQ(local["validity"], cluster["validity"]);
  std::size_t frames = 0;
  for (const auto& [file, sum] : local["files"].items()) {
    if (!file.ends_with(".exr")) continue;
    ++frames;
    EXPECT_EQ(sum, cluster["files"][file]) << file;
  }
  EXPECT_EQ(frames, 6u * (3 * 6 + 4));  // reference, both inputs and noise-floor frames
  // The cluster's suite verifies.
  EXPECT_EQ(dynbench(fmt::format("suite verify {}", (dir / "cluster").string()), dir).status, 0);
}

TEST(SlurmScript, TimesAndQuotingAsSlurmAndTheShellRead) {
  using cluster::parseSlurmTime;
  EXPECT_EQ(parseSlurmTime("30"), 30 * 60);  // minutes
  EXPECT_EQ(parseSlurmTime("5:30"), 5 * 60 + 30);
  EXPECT_EQ(parseSlurmTime("02:00:00"), 7200);
  EXPECT_EQ(parseSlurmTime("1-00"), 86400);
  EXPECT_EQ(parseSlurmTime("1-02:03:04"), ((24 + 2) * 60 + 3) * 60 + 4);
  EXPECT_FALSE(parseSlurmTime("1h"));
  EXPECT_FALSE(parseSlurmTime(""));
  EXPECT_FALSE(parseSlurmTime("1:2:3:4"));
  // Numbers beyond a long were an uncaught std::out_of_range (status 1, issue 47): now refused.
  EXPECT_FALSE(parseSlurmTime("99999999999999999999"));
  EXPECT_FALSE(parseSlurmTime("99999999999999999999-00"));
  EXPECT_FALSE(parseSlurmTime("1:99999999999999999999"));
  EXPECT_EQ(parseSlurmTime("999999999"), 999999999L * 60);
  EXPECT_EQ(cluster::shellQuote("/data/run-1/frames"), "/data/run-1/frames");
  EXPECT_EQ(cluster::shellQuote("my frames"), "'my frames'");
  EXPECT_EQ(cluster::shellQuote("it's"), "'it'\\''s'");
  // The signal comes at most a quarter of a short time limit before it.
  cluster::Options o;
  o.time = "00:04:00";
  EXPECT_NE(cluster::scriptHeader("x", 3, "/logs", o).find("#SBATCH --signal=B:USR1@60\n"), std::string::npos);
  o.time = "10:00:00";
  EXPECT_NE(cluster::scriptHeader("x", 3, "/logs", o).find("#SBATCH --signal=B:USR1@120\n"), std::string::npos);
}

}  // namespace
}  // namespace dynbench
