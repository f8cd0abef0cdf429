#include "capture/xvfb.h"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <thread>
#include <vector>

#include <fmt/format.h>

extern char** environ;

namespace dynbench::capture {

namespace {
constexpr int kDisplayFd = 3;  // the descriptor Xvfb writes its display number to

// What Xvfb said on stdout and stderr (an unnamed file: a pipe nobody reads could fill and stop
// the server), for the error message.
std::string readBack(int fd) {
  std::string text;
  char buffer[4096];
  if (::lseek(fd, 0, SEEK_SET) < 0) return text;
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<std::size_t>(n));
  while (!text.empty() && text.back() == '\n') text.pop_back();
  if (text.size() > 3000) text.erase(0, text.size() - 3000);
  return text;
}

void stopAndReap(pid_t pid) {
  ::kill(pid, SIGTERM);
  for (int i = 0; i < 50; ++i) {
    if (::waitpid(pid, nullptr, WNOHANG) == pid) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ::kill(pid, SIGKILL);
  while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
  }
}
}  // namespace

Expected<XvfbDisplay> XvfbDisplay::start(int width, int height, std::chrono::seconds timeout) {
  int ready[2];
  if (::pipe2(ready, O_CLOEXEC) != 0) return fail(ErrorCode::kExternalTool, "cannot start Xvfb: pipe: {}", std::strerror(errno));
  const int log = ::open("/tmp", O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  if (log >= 0) {
    posix_spawn_file_actions_adddup2(&actions, log, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, log, STDERR_FILENO);
  }
  posix_spawn_file_actions_adddup2(&actions, ready[1], kDisplayFd);  // dup2 clears close-on-exec
  std::vector<std::string> args = {"Xvfb", "-displayfd", std::to_string(kDisplayFd), "-screen", "0", fmt::format("{}x{}x24", width, height),
                                   "-nolisten", "tcp", "-noreset"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(ready[1]);
  auto failed = [&](const std::string& why) -> Expected<XvfbDisplay> {
    ::close(ready[0]);
    const std::string said = log >= 0 ? readBack(log) : std::string();
    if (log >= 0) ::close(log);
    return fail(ErrorCode::kExternalTool, "Xvfb {}{}", why, said.empty() ? "" : ":\n" + said);
  };
  if (rc != 0) return failed(fmt::format("cannot be started ({}); install Debian's xvfb (scripts/setup.sh does)", std::strerror(rc)));

  // The display number, then a newline, once the server accepts connections; EOF if it exits.
  std::string number;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (number.empty() || number.back() != '\n') {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      stopAndReap(pid);
      return failed(fmt::format("did not accept connections within {} s", timeout.count()));
    }
    pollfd readable{ready[0], POLLIN, 0};
    const int polled = ::poll(&readable, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (polled < 0 && errno == EINTR) continue;
    if (polled <= 0) continue;
    char c = 0;
    const ssize_t n = ::read(ready[0], &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      stopAndReap(pid);
      return failed("exited before it accepted connections");
    }
    number += c;
  }
  ::close(ready[0]);
  if (log >= 0) ::close(log);
  number.pop_back();
  if (number.empty() || number.find_first_not_of("0123456789") != std::string::npos) {
    stopAndReap(pid);
    return fail(ErrorCode::kExternalTool, "Xvfb wrote '{}' where its display number was expected", number);
  }
  return XvfbDisplay(pid, ":" + number);
}

XvfbDisplay::XvfbDisplay(XvfbDisplay&& other) noexcept : pid_(other.pid_), name_(std::move(other.name_)) { other.pid_ = -1; }

XvfbDisplay::~XvfbDisplay() {
  if (pid_ > 0) stopAndReap(pid_);
}

}  // namespace dynbench::capture
