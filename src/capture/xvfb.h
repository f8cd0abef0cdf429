#pragma once
// A private virtual X display for the game: Xvfb started with -displayfd, which picks a free
// display number itself and writes it to a pipe once it accepts connections.
//
// Why not xvfb-run: Debian's xvfb-run learns that Xvfb is ready from a SIGUSR1, with
//   trap : USR1; (trap '' USR1; exec Xvfb ...) &; wait || :
// A signal that arrives before the shell reaches `wait` is handled then and lost, and `wait` waits
// for Xvfb to exit, which it never does: the capture hangs until its time limit. Under load (both
// cores busy) the shell can be descheduled for longer than Xvfb takes to start; that was the hang
// of `capture cube2` seen in CI and in full test runs (issue 32). -displayfd has no such window,
// and no race between two captures for a display number either.
#include <chrono>
#include <string>

#include <sys/types.h>

#include "core/error.h"

namespace dynbench::capture {

class XvfbDisplay {
 public:
  // Starts Xvfb with one screen of width x height x 24 bits and waits (at most `timeout`) until it
  // accepts connections. Fails (kExternalTool) with Xvfb's own message when it does not start.
  static Expected<XvfbDisplay> start(int width, int height, std::chrono::seconds timeout = std::chrono::seconds(60));

  XvfbDisplay(XvfbDisplay&& other) noexcept;
  XvfbDisplay& operator=(XvfbDisplay&&) = delete;
  XvfbDisplay(const XvfbDisplay&) = delete;
  ~XvfbDisplay();  // stops Xvfb: SIGTERM, SIGKILL if it is still there after 5 s

  const std::string& name() const { return name_; }  // for DISPLAY: ":N"

 private:
  XvfbDisplay(pid_t pid, std::string name) : pid_(pid), name_(std::move(name)) {}
  pid_t pid_ = -1;
  std::string name_;
};

}  // namespace dynbench::capture
