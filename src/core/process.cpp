#include "core/process.h"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <map>

#include <fmt/format.h>

extern char** environ;

namespace dynbench {

Expected<ProcessResult> runProcess(const ProcessOptions& options) {
  if (options.argv.empty()) return fail(ErrorCode::kExternalTool, "runProcess: no program given");
  // The environment: ours, with the options' variables added or replaced.
  std::map<std::string, std::string> env;
  for (char** e = environ; e && *e; ++e) {
    const std::string entry(*e);
    const auto eq = entry.find('=');
    if (eq != std::string::npos) env[entry.substr(0, eq)] = entry.substr(eq + 1);
  }
  for (const auto& [name, value] : options.environment) env[name] = value;
  std::vector<std::string> envStrings;
  for (const auto& [name, value] : env) envStrings.push_back(name + "=" + value);
  std::vector<char*> envp, argv;
  for (auto& s : envStrings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::vector<std::string> args = options.argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) return fail(ErrorCode::kExternalTool, "cannot run {}: pipe: {}", options.argv[0], std::strerror(errno));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  // glibc 2.29+ (Debian bookworm has 2.36): change folder in the child before exec.
  if (!options.workingDirectory.empty()) posix_spawn_file_actions_addchdir_np(&actions, options.workingDirectory.c_str());
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  if (rc != 0) {
    ::close(fds[0]);
    return fail(ErrorCode::kExternalTool, "cannot run {}: {}", options.argv[0], std::strerror(rc));
  }

  ProcessResult result;
  std::string pending;
  char buffer[4096];
  auto keep = [&](std::string_view text) {
    result.tail.append(text);
    if (result.tail.size() > options.tailBytes) result.tail.erase(0, result.tail.size() - options.tailBytes);
  };
  auto stop = [&] {
    result.stoppedByCaller = true;
    ::kill(pid, SIGTERM);  // then keep reading until it has gone
  };
  while (true) {
    if (!result.stoppedByCaller && options.stopIf && options.stopIf()) stop();
    pollfd readable{fds[0], POLLIN, 0};
    const int ready = ::poll(&readable, 1, options.stopIf ? 1000 : -1);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;  // quiet for a second: ask stopIf again
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    keep(std::string_view(buffer, static_cast<std::size_t>(n)));
    if (!options.onLine) continue;
    pending.append(buffer, static_cast<std::size_t>(n));
    for (std::size_t end; (end = pending.find('\n')) != std::string::npos;) {
      if (!result.stoppedByCaller && !options.onLine(std::string_view(pending).substr(0, end))) stop();
      pending.erase(0, end + 1);
    }
  }
  if (options.onLine && !result.stoppedByCaller && !pending.empty()) options.onLine(pending);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status)) result.exitStatus = WEXITSTATUS(status);
  else if (WIFSIGNALED(status)) result.signal = WTERMSIG(status);
  while (!result.tail.empty() && result.tail.back() == '\n') result.tail.pop_back();
  return result;
}

}  // namespace dynbench
