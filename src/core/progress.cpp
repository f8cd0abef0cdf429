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
  // total == 0: the amount of work is not known in advance; no fraction, no time left.
  std::string line = total ? fmt::format("{}: {}/{} {}", label, done, total, unit) : fmt::format("{}: {} {}", label, done, unit);
  if (done > 0 && elapsedSeconds > 0) {
    const double rate = static_cast<double>(done) / elapsedSeconds;
    line += rate >= 100 ? fmt::format(", {:.0f} {}/s", rate, unit) : fmt::format(", {:.3g} {}/s", rate, unit);
    if (total >= done && total) line += fmt::format(", {:.0f} s left", static_cast<double>(total - done) / rate);
  }
  if (!current.empty()) line += ": " + current;
  return line;
}

void Progress::update(std::size_t done, const std::string& current) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  // Redraw at most 5 times a second, but always the first time.
  if (drawn_ && now - lastDraw_ < std::chrono::milliseconds(200) && (total_ == 0 || done < total_)) return;
  lastDraw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  fmt::print(stderr, "\r{}\033[K", format(label_, done, total_, unit_, elapsed, current));
  std::fflush(stderr);
}

}  // namespace dynbench
