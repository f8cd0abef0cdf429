#include "core/progress.h"

#include <cstdio>

#include <fmt/format.h>
#include <unistd.h>

namespace dynbench {

Progress::Progress(std::string label, std::size_t total, std::string unit)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total), enabled_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()), lastDraw_(start_) {}

Progress::~Progress() {
  if (drawn_) fmt::print(stderr, "\r\033[K");
}

std::string Progress::format(const std::string& label, std::size_t done, std::size_t total, const std::string& unit,
                             double elapsedSeconds, const std::string& current) {
  std::string line = fmt::format("{}: {}/{} {}", label, done, total, unit);
  if (done > 0 && elapsedSeconds > 0) {
    const double rate = static_cast<double>(done) / elapsedSeconds;
    const double left = static_cast<double>(total - done) / rate;
    line += fmt::format(", {:.3g} {}/s, {:.0f} s left", rate, unit, left);
  }
  if (!current.empty()) line += ": " + current;
  return line;
}

void Progress::update(std::size_t done, const std::string& current) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  // Redraw at most 5 times a second, but always the first time.
  if (drawn_ && now - lastDraw_ < std::chrono::milliseconds(200) && done < total_) return;
  lastDraw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  fmt::print(stderr, "\r{}\033[K", format(label_, done, total_, unit_, elapsed, current));
  std::fflush(stderr);
}

}  // namespace dynbench
