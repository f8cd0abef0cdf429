#pragma once
// The slowed camera: the bot's own camera with its turns slowed (the third camera of the suites' paired design).
// Its positions are the bot's, key for key, cuts included; its heading and pitch are the bot's
// smoothed by a centred moving average `window` seconds wide within each cut-free stretch, so
// flicks and aim corrections shorter than the window are gone while turns to a new direction stay.
// It sees what the bot sees from where the bot is (the content of the match held fixed) and turns
// at a rate between the bot's and the fly-through's: of the three, only the camera's rotation
// differs from the bot's, and only the path and rotation together from the fly-through's.
#include <filesystem>
#include <string>

#include "core/error.h"

namespace dynbench::camera {

struct SlowedTurnsOptions {
  double window = 2.0;  // s: the moving average's width (chosen from the cameras' rotation alone, before any suite ran with it: docs/suite.md)
  double rate = 60.0;   // poses per second in the CSV, beside the bot's cuts
};
struct SlowedTurnsReport {
  std::size_t poses = 0, stretches = 0;  // poses written; cut-free stretches smoothed
  double window = 0;
};
// The bot's camera of `dataset` with its turns slowed, as a merge-camera CSV pose log (`csv`) merged
// into a copy of `dataset` (`output`), the bot's cuts kept.
Expected<SlowedTurnsReport> makeSlowedTurnsDataset(const std::filesystem::path& dataset, const std::filesystem::path& output,
                                                   const std::filesystem::path& csv, const SlowedTurnsOptions& options = {});
// One line for logs.
std::string describe(const SlowedTurnsReport& report);

}  // namespace dynbench::camera
