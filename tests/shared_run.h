#pragma once
// A run of the dynbench executable shared by the tests that make exactly the same one: the local
// demo (Demo.WholeChainOnAShortMatch checks it; Slurm.DemoAsAChainOfJobs compares its Slurm twin
// with it) and the local smoke suite (Suite.SmokeSuite... and Slurm.SuiteAsAChainOfJobs). The first
// test to ask makes it, under an exclusive lock (flock), in a folder keyed by the arguments and by
// the executable's path, size and modification time (a rebuilt dynbench makes it anew); the others wait
// for the lock and read it. Each of the two was made twice per test run before (about 110 s of
// CPU on a 2-core AMD EPYC). A test reads the folder and never writes into it: one that edits or
// resumes copies it first (copyOf).
#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/files.h"
#include "run_cli.h"

namespace dynbench::test {

struct SharedRun {
  std::filesystem::path output;  // the run's output folder (its `{out}`)
  Run run;                       // its exit status, stdout and stderr
};

// Every rebuild of dynbench makes its own shared runs (about 200 MB each): before making one, the
// runs of the same name from earlier builds are removed, but for the newest other (a second build
// tree, e.g. the debug preset's, keeps its own) and any another process holds locked.
inline void pruneOlderRuns(const std::filesystem::path& root, const std::string& name, const std::filesystem::path& keep) {
  namespace fs = std::filesystem;
  // Each folder's time read once, without throwing: another test process may remove one meanwhile.
  std::vector<std::pair<fs::file_time_type, fs::path>> older;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(root, ec)) {
    if (!entry.is_directory(ec) || !entry.path().filename().string().starts_with(name + "-") || entry.path() == keep) continue;
    const auto time = fs::last_write_time(entry.path(), ec);
    if (!ec) older.emplace_back(time, entry.path());
  }
  std::sort(older.begin(), older.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t i = 1; i < older.size(); ++i) {
    const fs::path lockPath = older[i].second.string() + ".lock";
    if (!fs::exists(lockPath, ec)) continue;
    // The empty lock file stays: a process that opened it a moment ago keeps a lock on that file.
    const auto lock = FileLock::tryTake(lockPath);
    if (lock && *lock) fs::remove_all(older[i].second, ec);
  }
}

// `arguments` names the output folder `{out}`: e.g. "suite smoke.json -o {out}".
inline SharedRun sharedRun(const std::string& name, const std::string& arguments) {
  namespace fs = std::filesystem;
  const fs::path exe(DYNBENCH_EXE);
  const auto stamp = fs::last_write_time(exe).time_since_epoch().count();
  const std::size_t key = std::hash<std::string>{}(fmt::format("{}\n{}\n{}\n{}", arguments, exe.string(), fs::file_size(exe), stamp));
  const fs::path root = fs::temp_directory_path() / "dynbench-shared-runs";
  fs::create_directories(root);
  const fs::path folder = root / fmt::format("{}-{:016x}", name, key);
  SharedRun shared{folder / "out", {}};
  const auto lock = FileLock::wait(folder.string() + ".lock");
  if (!lock) {
    ADD_FAILURE() << lock.error().message;
    return shared;
  }
  // run.json, written last and atomically, says the run is whole: a run cut short is made again.
  const fs::path result = folder / "run.json";
  if (!fs::exists(result)) {
    pruneOlderRuns(root, name, folder);
    fs::remove_all(folder);
    fs::create_directories(folder);
    std::string command = arguments;
    for (std::size_t at; (at = command.find("{out}")) != std::string::npos;) command.replace(at, 5, shared.output.string());
    const Run made = dynbench(command, folder);
    const nlohmann::json record{{"status", made.status}, {"out", made.out}, {"err", made.err}};
    if (!writeFileAtomic(result, record.dump())) ADD_FAILURE() << result << ": cannot write";
  }
  const auto record = nlohmann::json::parse(slurp(result), nullptr, false);
  if (!record.is_discarded()) {
    shared.run.status = record["status"];
    shared.run.out = record["out"];
    shared.run.err = record["err"];
  }
  return shared;  // the lock goes with `lock`
}

// A copy of a shared run's output to edit or resume in, with its files' times (which decide what
// a resumed run makes again).
inline void copyOf(const SharedRun& shared, const std::filesystem::path& to) {
  std::filesystem::remove_all(to);
  std::string out;
  EXPECT_EQ(runShell(fmt::format("cp -a '{}' '{}' 2>&1", shared.output.string(), to.string()), out), 0) << out;
}

}  // namespace dynbench::test
