// `dynbench suite MANIFEST -o DIR`, `dynbench suite score DIR --method NAME=SPEC` and `dynbench suite
// verify DIR` (suite/suite.h, suite/score.h, suite/verify.h).
#include <cstdio>

#include <filesystem>

#include "cli/commands.h"
#include "suite/record.h"
#include "suite/score.h"
#include "suite/suite.h"
#include "suite/verify.h"

namespace dynbench::cli {
namespace {

namespace fs = std::filesystem;

struct SuiteCli {
  std::string manifest, output, verifyDir, scoreDir;
  std::vector<std::string> scoreMethods;
  std::string scoreInput{evaluate::kJitteredInput};
  int threads = 0;
  std::string part = "all";
  int renderTask = 0, framesPerTask = 8;
  bool slurm = false;
  cluster::Options slurmOptions;
  std::vector<std::string> only, records;
  bool assemble = false;
  std::vector<std::string> verifyRecords;  // suite verify --record
  std::size_t verifySample = 0;            // suite verify --sample
  std::uint64_t verifySeed = 1;
  std::string verifyWork;
  std::string publishDir, publishTo;       // suite publish
  bool publishPartial = false;
};

// One line per stage, flushed: a suite runs for an hour, and its log (redirected, so fully
// buffered) should show where it is.
void printLine(const std::string& line) {
  fmt::print("{}\n", line);
  std::fflush(stdout);
}

// suite --slurm: the chain of jobs, its changes of state printed once each.
Expected<void> suiteOnSlurm(const suite::SuiteOptions& options, cluster::Options slurm) {
  slurm.framesPerTask = options.framesPerTask;
  std::string last;
  auto outcome = suite::runSuiteOnSlurm(options, slurm, [&](const cluster::ChainStatus& s) {
    const std::string line = fmt::format("datasets {}, render tasks {} pending, {} running, {} done, suite {}", s.datasets, s.render.pending,
                                         s.render.running, s.render.done, s.report);
    if (line != last) printLine(line);
    last = line;
  });
  if (!outcome) return std::unexpected(outcome.error());
  fmt::print("Slurm jobs: datasets {} ({}), render {} ({} tasks, {}), suite {} ({})\n", outcome->datasetsJob, outcome->datasetsScript.string(),
             outcome->renderJob, outcome->renderTasks, outcome->renderScript.string(), outcome->reportJob, outcome->reportScript.string());
  if (!outcome->waited) return {};
  if (!outcome->failure.empty())
    return fail(ErrorCode::kIncomplete, "suite --slurm: {}. Rerun `dynbench suite ... --slurm`: every part reuses what is complete", outcome->failure);
  fmt::print("suite: {}\n", outcome->report.string());
  return {};
}

Expected<void> runSuiteCli(const SuiteCli& cli) {
  suite::SuiteOptions options;
  options.manifest = cli.manifest;
  options.output = cli.output;
  options.threads = cli.threads;
  options.part = cli.part == "datasets" ? suite::SuitePart::kDatasets : cli.part == "render" ? suite::SuitePart::kRenderTask : suite::SuitePart::kAll;
  options.renderTask = cli.renderTask;
  options.framesPerTask = cli.framesPerTask;
  options.only = cli.only;
  options.records.assign(cli.records.begin(), cli.records.end());
  options.assembleOnly = cli.assemble;
  if (options.part != suite::SuitePart::kAll && (!cli.only.empty() || !cli.records.empty() || cli.assemble))
    return fail(ErrorCode::kUsage, "--only, --records and --assemble: with --part all only (they choose what of the whole suite is made)");
  if (cli.slurm) {
    if (!cli.only.empty() || !cli.records.empty() || cli.assemble) return fail(ErrorCode::kUsage, "--only, --records and --assemble: not with --slurm");
    if (options.part != suite::SuitePart::kAll) return fail(ErrorCode::kUsage, "--part: not with --slurm (the jobs it submits run the parts)");
    return suiteOnSlurm(options, cli.slurmOptions);
  }
  auto outcome = suite::runSuite(options, printLine);
  if (!outcome) return std::unexpected(outcome.error());
  if (options.part != suite::SuitePart::kAll) return {};
  if (outcome->json.empty())
    fmt::print("suite: {} records made, {} there before; {} of {} datasets still without one\n", outcome->recordsMade, outcome->recordsReused,
               outcome->missing.size(), outcome->recordsMade + outcome->recordsReused + outcome->missing.size());
  else
    fmt::print("suite: {} datasets ({} records made, {} there before); {} and {}\n", outcome->datasets.size(), outcome->recordsMade,
               outcome->recordsReused, outcome->json.string(), outcome->markdown.string());
  return {};
}

// suite verify DIR --record NAME... / --sample K: each record made again from nothing and compared.
Expected<void> runVerifyRecords(const SuiteCli& cli) {
  const fs::path dir = cli.verifyDir;
  std::vector<fs::path> files;
  for (const std::string& name : cli.verifyRecords) {
    const fs::path given(name);
    files.push_back(given.extension() == ".json" && fs::exists(given) ? given : suite::recordPath(dir, name));
    if (!fs::exists(files.back())) return fail(ErrorCode::kIo, "{}: no such record (--record {})", files.back().string(), name);
  }
  if (cli.verifySample > 0) {
    const std::vector<fs::path> all = suite::recordFiles(dir / "records");
    if (all.empty()) return fail(ErrorCode::kIo, "{}: no records to sample", (dir / "records").string());
    for (const fs::path& f : suite::sampleRecords(all, cli.verifySample, cli.verifySeed)) files.push_back(f);
  }
  std::size_t differing = 0;
  for (const fs::path& file : files) {
    const std::string name = file.stem().string();
    const fs::path work = cli.verifyWork.empty() ? dir / "remade" / name : fs::path(cli.verifyWork) / name;
    printLine(fmt::format("{}: made again from nothing in {}", file.string(), work.string()));
    auto compared = suite::verifyRecord(file, work, cli.threads, [](const std::string& line) { printLine("  " + line); });
    if (!compared) return std::unexpected(compared.error());
    for (const std::string& d : compared->differences) fmt::print("differs: {}\n", d);
    fmt::print("verify {}: {} numbers{}, {} differ{}\n", compared->dataset, compared->numbers,
               compared->filesCompared ? fmt::format(" and {} file digests", compared->files) : std::string(), compared->differences.size(),
               compared->filesNote.empty() ? std::string() : "; " + compared->filesNote);
    differing += compared->differences.empty() ? 0 : 1;
  }
  if (differing > 0)
    return fail(ErrorCode::kInvalidData, "{}: {} of {} records differ from what making them again gives", dir.string(), differing, files.size());
  return {};
}

Expected<void> runVerify(const SuiteCli& cli) {
  if (!cli.verifyRecords.empty() || cli.verifySample > 0) return runVerifyRecords(cli);
  auto outcome = suite::verifySuite(cli.verifyDir, printLine);
  if (!outcome) return std::unexpected(outcome.error());
  for (const std::string& d : outcome->differences) fmt::print("differs: {}\n", d);
  fmt::print("verify: {} files and {} numbers checked, {} differ\n", outcome->files, outcome->numbers, outcome->differences.size());
  if (!outcome->differences.empty())
    return fail(ErrorCode::kInvalidData, "{}: {} of the recorded files and numbers differ from what the files give now", cli.verifyDir,
                outcome->differences.size());
  return {};
}

Expected<void> runPublish(const SuiteCli& cli) {
  auto outcome = suite::publishSuite(cli.publishDir, cli.publishTo, cli.publishPartial, printLine);
  if (!outcome) return std::unexpected(outcome.error());
  if (outcome->json.empty())
    fmt::print("suite publish: {} records, {} datasets still without one (no tables until every dataset has one)\n", outcome->recordsReused,
               outcome->missing.size());
  else
    fmt::print("suite publish: {} records; {} and {}\n", outcome->recordsReused, outcome->json.string(), outcome->markdown.string());
  return {};
}

Expected<void> runScore(const SuiteCli& cli) {
  std::vector<suite::MethodToScore> methods;
  for (const std::string& text : cli.scoreMethods) {
    auto m = suite::parseMethodToScore(text);
    if (!m) return std::unexpected(m.error());
    m->input = cli.scoreInput;
    methods.push_back(std::move(*m));
  }
  auto outcome = suite::scoreSuite(cli.scoreDir, methods, printLine);
  if (!outcome) return std::unexpected(outcome.error());
  fmt::print("suite score: {} scored on every dataset; {} and {}\n", fmt::join(outcome->methods, ", "), outcome->json.string(),
             outcome->markdown.string());
  return {};
}

}  // namespace

void addSuiteCommand(CLI::App& app, CommandRun& run) {
  auto cli = std::make_shared<SuiteCli>();
  auto* cmd = app.add_subcommand("suite", "A benchmark of many datasets from one manifest: capture to method scores, and their validity");
  cmd->footer(
      "Captures, converts, flies through, renders (converged reference and real-time input), discards and evaluates every\n"
      "dataset of MANIFEST into DIR (resuming what is complete), then writes DIR/suite.json (tool version, manifest,\n"
      "numbers, SHA-256 of every file they come from) and DIR/suite.md (the validity table: Spearman's rho of each\n"
      "difficulty measure with each method's error, bootstrap 95 % intervals). Each dataset leaves DIR/records/NAME.json as\n"
      "soon as it is finished: a dataset with a record is not made again, and records made elsewhere (--records) complete\n"
      "the suite. Format and definitions: docs/suite.md.\n"
      "Example: dynbench suite suites/smoke.json -o smoke && dynbench suite verify smoke\n"
      "Split:   dynbench suite suites/v2.json -o a --only calm-1-bot,calm-1-slowed   (elsewhere: -o b --only ...)\n"
      "         dynbench suite suites/v2.json -o a --records b/records --assemble");
  cmd->add_option("MANIFEST", cli->manifest, "The suite manifest (JSON, docs/suite.md)");
  cmd->add_option("-o,--output", cli->output, "The suite's folder");
  cmd->add_option("--threads", cli->threads, "Render threads (0: all cores)")->check(CLI::Range(0, 1024));
  cmd->add_option("--frames-per-task", cli->framesPerTask, "Frame renders per render task (with --slurm, or --part render)")->check(positive());
  cmd->add_option("--part", cli->part, "Run one part, as `suite --slurm`'s jobs do: datasets (capture, convert, fly-through of every "
                                       "dataset) or render (task --render-task's frame renders); all: everything")
      ->check(CLI::IsMember({"all", "datasets", "render"}));
  cmd->add_option("--render-task", cli->renderTask, "With --part render: which task's frame renders")->check(nonNegative());
  cmd->add_option("--only", cli->only, "Make only these datasets (names, comma-separated or repeated); the others are left to other runs, "
                                       "whose records (DIR/records) complete the suite")
      ->delimiter(',');
  cmd->add_option("--records", cli->records, "Folders (or files) of records made elsewhere (their DIR/records): each checked against MANIFEST, "
                                             "copied into DIR/records and counted as done; repeat for several");
  cmd->add_flag("--assemble", cli->assemble, "Make nothing: write suite.json and suite.md from the records alone (an error naming the "
                                             "datasets that have none)");
  addSlurmOptions(cmd, cli->slurm, cli->slurmOptions,
                  "DIR/slurm: the datasets, then an array of render tasks of --frames-per-task frame renders, then the whole suite, chained with afterok",
                  false);
  auto* verify = cmd->add_subcommand("verify", "Recompute every number of DIR/suite.json from its files and report any that differ");
  verify->add_option("DIR", cli->verifyDir, "The suite's folder")->required();
  verify->add_option("--record", cli->verifyRecords, "Make this dataset's record (DIR/records/NAME.json, or a record file) again from "
                                                     "nothing in a fresh folder and compare every number with it, instead of re-deriving "
                                                     "suite.json from the files; repeat for several");
  verify->add_option("--sample", cli->verifySample, "Make K records of DIR/records, chosen at random with --seed, again from nothing and compare");
  verify->add_option("--seed", cli->verifySeed, "The seed of --sample's choice (the same records on every machine)");
  verify->add_option("--work", cli->verifyWork, "Where records are made again (WORK/NAME, emptied first; default DIR/remade)");
  verify->add_option("--threads", cli->threads, "Render threads (0: all cores)")->check(CLI::Range(0, 1024));
  auto* score = cmd->add_subcommand("score", "Score a method that is not in the manifest on every dataset of a finished suite, "
                                             "from its stored frames (nothing captured or rendered), and add it to suite.json and suite.md");
  score->add_option("DIR", cli->scoreDir, "The suite's folder (with suite.json)")->required();
  score->add_option("--method", cli->scoreMethods,
                    "NAME=external:PATH (PATH/DATASET/frame_NNNNN.exr for each dataset, or {dataset} in PATH) or a built-in "
                    "method's name; repeat for several")
      ->required();
  score->add_option("--input", cli->scoreInput,
                    "The input every --method is scored on: jittered (RUN/input, TAA's) or still (RUN/input-still, the same render "
                    "without the jitter, accumulate's and SVGF's); its ratio is to none on the same input")
      ->check(CLI::IsMember({"jittered", "still"}));
  score->footer("Example: dynbench suite score smoke --method mine=external:my-outputs   (my-outputs/fps-1-bot/frame_00034.exr, ...)\n"
                "Outputs are kept in DIR/scored/DATASET/NAME, so `suite verify` re-derives the new column. docs/suite.md.");
  auto* publish = cmd->add_subcommand("publish", "Copy a finished suite's records to a folder of published results and assemble its "
                                                 "suite.json and suite.md there from them alone");
  publish->add_option("DIR", cli->publishDir, "The suite's folder (its records in DIR/records)")->required();
  publish->add_option("-o,--output", cli->publishTo, "The published results' folder (suites/results/SUITE for a versioned suite)")->required();
  publish->add_flag("--partial", cli->publishPartial, "A suite still being run: copy the records it has so far, write no tables");
  publish->footer("Example: dynbench suite publish runs/v1 -o suites/results/v1   (then commit it; docs/suite.md, \"Records\")");
  cmd->callback([cmd, verify, score, publish, cli, &run] {
    if (publish->parsed()) {
      run = [cli] { return runPublish(*cli); };
      return;
    }
    if (verify->parsed()) {
      run = [cli] { return runVerify(*cli); };
      return;
    }
    if (score->parsed()) {
      run = [cli] { return runScore(*cli); };
      return;
    }
    if (cli->manifest.empty() || cli->output.empty()) throw CLI::RequiredError("MANIFEST and --output");
    run = [cli] { return runSuiteCli(*cli); };
  });
}

}  // namespace dynbench::cli
