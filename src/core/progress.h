#pragma once
// Progress for long work: items done, rate and time left, redrawn on one terminal line at most
// a few times a second. Silent when stderr is not a terminal (logs, CI) or when disabled.
#include <chrono>
#include <cstddef>
#include <string>

namespace dynbench {

class Progress {
 public:
  // `label` names the work ("stats"), `unit` the items ("files", "frames").
  Progress(std::string label, std::size_t total, std::string unit);
  ~Progress();  // clears the line
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // `done` items finished; `current` says what is being worked on next (may be empty).
  void update(std::size_t done, const std::string& current = {});
  bool enabled() const { return enabled_; }

  // The line that update() draws, for tests: "stats: 3/10 files, 1.5 files/s, 5 s left: x.gltf".
  static std::string format(const std::string& label, std::size_t done, std::size_t total, const std::string& unit,
                            double elapsedSeconds, const std::string& current);

 private:
  std::string label_, unit_;
  std::size_t total_;
  bool enabled_;
  std::chrono::steady_clock::time_point start_, lastDraw_;
  bool drawn_ = false;
};

}  // namespace dynbench
