#pragma once
// The history lookup: whether a reprojected surface pixel finds the same surface in the previous
// frame (the geometry tests of docs/metrics.md, "Geometry tests"), and where each pixel of a frame
// reads its history. Discard counts what fails (Table 6.7's position and normal columns); the
// temporal methods read what passes.
#include <optional>

#include <glm/glm.hpp>

#include "frames/feature_frame.h"
#include "reprojection/reprojection.h"

namespace dynbench::reprojection {

using frames::FeatureFrame;

// kTaps: each bilinear tap on its own, NRD's relative plane distance (discard::Thresholds says
// more); kBilinear: the thesis's bilinear sample of the four taps.
enum class GeometryTest { kTaps, kBilinear };

// The geometry test's default thresholds, shared by SurfaceThresholds and discard::Thresholds:
// position 0.01 (NRD's disocclusionThreshold: plane distance / view depth) and a shading-normal
// vector distance of 0.1 (a turn of about 5.7 degrees).
inline constexpr double kDefaultPositionThreshold = 0.01, kDefaultNormalThreshold = 0.1;

// The geometry test's thresholds, absolute: position (kTaps: plane distance / view depth;
// kBilinear: scene units) and the shading normals' vector distance.
struct SurfaceThresholds {
  GeometryTest test = GeometryTest::kTaps;
  double position = kDefaultPositionThreshold;
  double normal = kDefaultNormalThreshold;
};

// The geometry test of one reprojected surface pixel (SurfaceThresholds::test) against the
// previous frame's taps around where it lands: whether its position and its normal have history,
// and the taps its radiance history is read from (kTaps: those of the same surface, renormalised,
// or all on geometry when none is; kBilinear: all four). `viewDepth` is the current pixel's Z;
// thresholds absolute.
struct HistoryTest {
  bool position = false, normal = false;  // history found for the feature
  bool consistent = false;                // a tap is the same surface with the same normal
  BilinearTaps history{};
};
// The taps test's "same surface": q within position x |viewDepth| of the plane through p normal
// to n (NRD's relative plane distance).
bool onTangentPlane(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& q, double viewDepth, const SurfaceThresholds& absolute);
HistoryTest testHistory(const glm::dvec3& p, const glm::dvec3& n, double viewDepth, const FeatureFrame& previous, const BilinearTaps& taps,
                        const SurfaceThresholds& absolute);

// Where pixel (px, py) of `current` finds its history in `previous`: the bilinear taps in the
// previous frame's sample grid, or nullopt when it has none (off screen, Eq. 3.3; or a surface
// whose history fails the world-position and normal tests, or comes from the background, and the
// other way round). Surfaces are followed by their motion vector (useMotion) or by the camera
// matrices (thesis Eqs. 2.2-2.3); the background always by the matrices. One per pair of frames
// (the cameras' matrices are multiplied once); the frames must outlive it.
class HistoryLookup {
 public:
  HistoryLookup(const FeatureFrame& current, const FeatureFrame& previous, const SurfaceThresholds& absolute, bool useMotion);
  std::optional<BilinearTaps> operator()(int px, int py) const;

 private:
  const FeatureFrame& current_;
  const FeatureFrame& previous_;
  SurfaceThresholds absolute_;
  bool useMotion_;
  Projector currentProjector_, previousProjector_;
};

}  // namespace dynbench::reprojection
