#pragma once
// `dynbench fidelity`: a dataset checked against the game it came from. `capture cube2
// --game-frames` keeps the game's own image of chosen frames (colour, and view depth read back
// from its depth buffer); this renders the same frames from the converted dataset and measures
// how well they agree (docs/fidelity.md):
//   - depth agreement: of the pixels where either sees geometry, the share where both do and
//     their view depths agree within tol(z) = 4 dz(z) + 0.01 z, dz(z) = z^2 (f - n) / (f n) / 2^24
//     the step of a 24-bit depth buffer at depth z (OpenGL's perspective with near n, far f); the
//     1 % covers pixel-centre sampling against rasterisation at depth edges and the engine's float
//     transforms;
//   - structure: the Pearson correlation, over pixels where both see geometry, of the two images'
//     luminance, each tone-mapped scale-free (Reinhard's L / (L + mean L)) and blurred (a Gaussian
//     of sigma = height / 90 pixels). The game is lightmapped (no global illumination, an
//     ambient floor, baked soft shadows) and the render path traced, so they cannot agree pixel
//     for pixel; where the same walls are lit and shadowed in the same places the correlation is
//     clearly positive, and a frame that is black, speckled or lit elsewhere has none.
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"

namespace dynbench::pipeline {

// Thresholds a frame must meet to pass.
inline constexpr double kFidelityMinDepthAgreement = 0.90;
inline constexpr double kFidelityMinCorrelation = 0.30;

struct FidelityStage {
  std::filesystem::path capture;  // a capture folder with game/ (capture cube2 --game-frames)
  std::filesystem::path dataset;  // its converted dataset
  std::filesystem::path output;   // renders, side-by-side PNGs, fidelity.json
  int samplesPerPixel = 16;
  int threads = 0;
};

struct FidelityFrame {
  long frame = 0;                // recorded frame (0-based)
  double time = 0.0;             // s
  int width = 0, height = 0;
  double depthAgreement = 0.0;   // share, see above; NaN when the game kept no depth for the frame
  double skyAgreement = 0.0;     // share of pixels where both see sky or both see geometry; NaN likewise
  double correlation = 0.0;      // of the tone-mapped, blurred luminance over geometry
  double unlitShare = 0.0;       // share of the render's geometry pixels with no direct light
  bool passed = false;
  std::filesystem::path sideBySide;  // game | render | depth difference, PNG
};

struct FidelityOutcome {
  std::vector<FidelityFrame> frames;
  bool passed = false;  // every frame passed
  std::string markdown;
};

// The comparison of one frame's images (exposed for tests): game colour (sRGB, 3 channels),
// game view depth (0: sky), render radiance (linear, 3 channels), render view depth, render hit
// flags, render direct radiance (for unlitShare); near and far of the game's projection.
struct FidelityImages {
  int width = 0, height = 0;
  std::vector<float> gameColour, gameDepth, renderRadiance, renderDepth, renderHit, renderDirect;
  double near = 0.0, far = 0.0;
  // false: the game kept no depth for this frame (id Tech 3's buffer read back empty); depth and
  // sky agreement are NaN and gameDepth is only the mask of pixels compared
  bool gameDepthKnown = true;
};
FidelityFrame compareWithGame(const FidelityImages& images);

// id Tech 3's game frames keep the window depth (game/frame_NNNNN_window_depth.pfm, 0 at the near
// plane, 1 at the far plane and on the sky) and game/window_depth.txt its near plane ("near 4");
// the engine picks the far plane per frame and does not expose it.
Expected<double> windowDepthNear(const std::filesystem::path& file);
struct WindowDepthView {
  std::vector<float> depth;  // view depth, 0 on the sky
  double far = 0.0;          // the far plane solved for: the median over the pixels the render hits
};
WindowDepthView viewDepthFromWindow(const std::vector<float>& window, const std::vector<float>& renderDepth, const std::vector<float>& renderHit,
                                    double near);

Expected<FidelityOutcome> runFidelity(const FidelityStage& stage);

}  // namespace dynbench::pipeline
