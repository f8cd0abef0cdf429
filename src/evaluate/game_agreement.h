#pragma once
// How well a render of a frame agrees with the game's own image of it (`dynbench fidelity`,
// docs/fidelity.md), an image metric beside compare's:
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
#include <vector>

namespace dynbench::evaluate {

// Thresholds a frame must meet to pass.
inline constexpr double kFidelityMinDepthAgreement = 0.90;
inline constexpr double kFidelityMinCorrelation = 0.30;

// The comparison of one frame's images (exposed for tests): game colour (sRGB, 3 channels),
// game view depth (0: sky), render radiance (linear, 3 channels), render view depth, render hit
// flags, the render's light reach (render::PathTracer::lightReach: 1 where some light reaches the
// surface seen through the pixel's centre, for unlitShare); near and far of the game's projection.
struct GameImages {
  int width = 0, height = 0;
  std::vector<float> gameColour, gameDepth, renderRadiance, renderDepth, renderHit, renderLightReach;
  double near = 0.0, far = 0.0;
  // false: the game kept no depth for this frame (id Tech 3's buffer read back empty); depth and
  // sky agreement are NaN and gameDepth is only the mask of pixels compared
  bool gameDepthKnown = true;
};
// The agreement of one frame's images: the measures above, and whether it passes the thresholds.
struct GameAgreement {
  int width = 0, height = 0;
  double depthAgreement = 0.0;   // share, see above; NaN when the game kept no depth for the frame
  double skyAgreement = 0.0;     // share of pixels where both see sky or both see geometry; NaN likewise
  double correlation = 0.0;      // of the tone-mapped, blurred luminance over geometry
  double unlitShare = 0.0;       // share of the render's geometry pixels that no light reaches
  bool passed = false;
};
GameAgreement compareWithGame(const GameImages& images);
// Whether a rendered view depth agrees with the game's z (> 0): within four steps of a 24-bit depth
// buffer at z, plus 1 % (above).
bool depthAgrees(double rendered, double z, double near, double far);

// id Tech 3's game frames keep the window depth (0 at the near plane, 1 at the far plane and on the
// sky); the engine picks the far plane per frame and does not expose it: the view depth with the
// far plane solved for.
struct WindowDepthView {
  std::vector<float> depth;  // view depth, 0 on the sky
  double far = 0.0;          // the far plane solved for: the median over the pixels the render hits
};
WindowDepthView viewDepthFromWindow(const std::vector<float>& window, const std::vector<float>& renderDepth, const std::vector<float>& renderHit,
                                    double near);

}  // namespace dynbench::evaluate
