// dynbench fidelity's comparison (evaluate/game_agreement.h) against known answers: a render that matches the game's frame
// passes with full agreement; one whose depth is off, or that is black or speckled where the game
// shows lit walls, fails (docs/fidelity.md).
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "pipeline/fidelity_run.h"

namespace dynbench::evaluate {
namespace {

// A corridor-like frame: depth rising towards the centre, a lit band and a dark band, sky on top.
GameImages corridor(int w = 96, int h = 54) {
  GameImages m;
  m.width = w;
  m.height = h;
  m.near = 0.54;
  m.far = 4096;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  m.gameColour.resize(3 * n);
  m.gameDepth.resize(n);
  m.renderRadiance.resize(3 * n);
  m.renderDepth.resize(n);
  m.renderHit.resize(n);
  m.renderLightReach.resize(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * w + x);
      const bool sky = y < h / 6;
      const double z = sky ? 0.0 : 40.0 + 300.0 * std::exp(-std::abs(x - w / 2.0) / 10.0);
      const double lit = 0.1 + 0.8 * (0.5 + 0.5 * std::sin(x / 7.0)) * (y > h / 2 ? 1.0 : 0.4);
      m.gameDepth[i] = static_cast<float>(z);
      m.renderDepth[i] = static_cast<float>(z);
      m.renderHit[i] = sky ? 0.0f : 1.0f;
      for (int c = 0; c < 3; ++c) {
        m.gameColour[3 * i + c] = static_cast<float>(std::pow(lit, 1 / 2.2));  // sRGB-ish
        m.renderRadiance[3 * i + c] = static_cast<float>(1000.0 * lit);      // a different exposure
      }
      m.renderLightReach[i] = sky ? 0.0f : 1.0f;
    }
  return m;
}

TEST(Fidelity, ARenderOfTheSameFramePassesWithFullAgreement) {
  const GameAgreement f = compareWithGame(corridor());
  EXPECT_EQ(f.depthAgreement, 1.0);
  EXPECT_EQ(f.skyAgreement, 1.0);
  EXPECT_GT(f.correlation, 0.99);  // exposure and tone curve do not matter
  EXPECT_EQ(f.unlitShare, 0.0);
  EXPECT_TRUE(f.passed);
}

TEST(Fidelity, ADepthOffByMoreThanItsToleranceFails) {
  GameImages m = corridor();
  for (auto& z : m.renderDepth) z *= 1.03f;  // 3 %: beyond 1 % + four 24-bit depth steps at these depths
  GameAgreement f = compareWithGame(m);
  EXPECT_LT(f.depthAgreement, 0.05);
  EXPECT_FALSE(f.passed);
  m = corridor();
  for (auto& z : m.renderDepth) z *= 1.005f;  // 0.5 %: within
  EXPECT_EQ(compareWithGame(m).depthAgreement, 1.0);
}

TEST(Fidelity, ABlackOrSpeckledRenderFails) {
  GameImages black = corridor();
  for (auto& v : black.renderRadiance) v = 0.0f;
  for (auto& v : black.renderLightReach) v = 0.0f;
  GameAgreement f = compareWithGame(black);
  EXPECT_EQ(f.depthAgreement, 1.0);  // the geometry is right
  EXPECT_EQ(f.unlitShare, 1.0);
  EXPECT_FALSE(f.passed);
  // Speckle: each pixel black or bright at random (what two_towers rendered as when its lights were
  // culled), whatever the game shows.
  GameImages speckle = corridor();
  std::mt19937 rng(1);
  for (std::size_t i = 0; i < speckle.renderRadiance.size() / 3; ++i) {
    const float v = rng() % 8 == 0 ? 5000.0f : 0.0f;
    for (int c = 0; c < 3; ++c) speckle.renderRadiance[3 * i + c] = v;
  }
  f = compareWithGame(speckle);
  EXPECT_LT(std::abs(f.correlation), kFidelityMinCorrelation);
  EXPECT_FALSE(f.passed);
}

// id Tech 3's window depth with its per-frame far plane: written from known view depths with
// near 4 and far 3000, read back with the far plane solved from the render's depths. A fifth of
// the pixels where the render sees other geometry (twice as far) leave the median, so the far plane
// and the other pixels' depths come back, and those pixels disagree.
TEST(Fidelity, IdTech3WindowDepthWithItsFarPlaneSolved) {
  GameImages m = corridor();
  const double near = 4.0, far = 3000.0;
  std::vector<float> window(m.gameDepth.size());
  for (std::size_t i = 0; i < window.size(); ++i) {
    const double z = m.gameDepth[i];
    window[i] = z > 0 ? static_cast<float>((1.0 / near - 1.0 / z) / (1.0 / near - 1.0 / far)) : 1.0f;  // the sky at depth 1
    if (i % 5 == 0 && z > 0) m.renderDepth[i] = static_cast<float>(2.0 * z);
  }
  const WindowDepthView view = viewDepthFromWindow(window, m.renderDepth, m.renderHit, near);
  EXPECT_NEAR(view.far, far, 1e-3 * far);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < window.size(); ++i) {
    if (m.gameDepth[i] <= 0) {
      EXPECT_EQ(view.depth[i], 0.0f);
      continue;
    }
    EXPECT_NEAR(view.depth[i], m.gameDepth[i], 1e-3 * m.gameDepth[i]) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
  m.gameDepth = view.depth;
  m.near = near;
  m.far = view.far;
  const GameAgreement f = compareWithGame(m);
  EXPECT_NEAR(f.depthAgreement, 0.8, 0.02);  // the fifth placed twice as far disagrees
  // a frame whose depth the game did not keep: no depth measures, judged on correlation alone
  m.gameDepthKnown = false;
  m.gameDepth = m.renderHit;
  const GameAgreement g = compareWithGame(m);
  EXPECT_TRUE(std::isnan(g.depthAgreement));
  EXPECT_TRUE(std::isnan(g.skyAgreement));
  EXPECT_GT(g.correlation, 0.99);
  EXPECT_TRUE(g.passed);
  EXPECT_FALSE(pipeline::windowDepthNear("/nonexistent/window_depth.txt"));
}

}  // namespace
}  // namespace dynbench::evaluate
