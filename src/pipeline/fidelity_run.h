#pragma once
// `dynbench fidelity`: a dataset checked against the game it came from. `capture cube2
// --game-frames` keeps the game's own image of chosen frames (colour, and view depth read back
// from its depth buffer); this renders the same frames from the converted dataset and measures
// how well they agree with evaluate/game_agreement.h's measures (docs/fidelity.md).
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "evaluate/game_agreement.h"

namespace dynbench::pipeline {

struct FidelityStage {
  std::filesystem::path capture;  // a capture folder with game/ (capture cube2 --game-frames)
  std::filesystem::path dataset;  // its converted dataset
  std::filesystem::path output;   // renders, side-by-side PNGs, fidelity.json
  int samplesPerPixel = 16;
  int threads = 0;
};

// One frame's agreement (evaluate/game_agreement.h) and where its images are.
struct FidelityFrame : evaluate::GameAgreement {
  long frame = 0;                // recorded frame (0-based)
  double time = 0.0;             // s
  std::filesystem::path sideBySide;  // game | render | depth difference, PNG
};

struct FidelityOutcome {
  std::vector<FidelityFrame> frames;
  bool passed = false;  // every frame passed
  std::string markdown;
};

// id Tech 3's game frames keep the window depth (game/frame_NNNNN_window_depth.pfm, read with
// evaluate::viewDepthFromWindow) and game/window_depth.txt its near plane ("near 4"): that plane.
Expected<double> windowDepthNear(const std::filesystem::path& file);
Expected<FidelityOutcome> runFidelity(const FidelityStage& stage);
// fidelity.json (docs/fidelity.md): the capture, the dataset, the thresholds and each frame's measures.
nlohmann::json fidelityJson(const FidelityOutcome& outcome, const FidelityStage& stage);

}  // namespace dynbench::pipeline
