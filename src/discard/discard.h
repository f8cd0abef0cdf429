#pragma once
// Reprojection discard (thesis §3.2.2, §6.3, Table 6.7): how much of a frame's history a temporal
// method must throw away. Every pixel of frame i is reprojected into frame i-1 (Eqs. 2.2, 2.3);
// it is a frustum discard when it lands outside the image (Eq. 3.3), otherwise frame i-1's
// buffers are sampled bilinearly there and compared feature by feature (the discard functions of
// §3.2.2). Percentages are of all w x h pixels (Eq. 3.4), averaged over the frames (Eq. 3.5).
// docs/metrics.md states every definition, default and the treatment of pixels that hit nothing.
#include <algorithm>
#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "frames/frame_io.h"
#include "frames/radiance_change.h"
#include "reprojection/history.h"
#include "reprojection/reprojection.h"

namespace dynbench::discard {

using frames::FeatureFrame;
using frames::FrameCamera;

struct Thresholds {
  // How a reprojected surface pixel's history is tested (docs/metrics.md, "Geometry tests"):
  //  kTaps (default): each of the four bilinear taps of the previous frame on its own, as SVGF and
  //    NVIDIA's NRD test history: a tap is the same surface when its world position lies within
  //    `position` x the pixel's view depth of the current point's tangent plane (NRD's relative
  //    plane distance, its disocclusionThreshold 0.01), and has the same normal when
  //    ||n_i - n_tap|| <= `normal`. Position is discarded when no tap passes its test, normal when
  //    neither a tap nor the normalised interpolation of the same-surface taps' normals does;
  //    radiance is compared with the Catmull-Rom cubic of the 4 x 4 taps where all are the same
  //    surface, else with the same-surface bilinear taps, their weights renormalised, and there
  //    (an edge) a change is the pixel's distance outside the range of the 2 x 2 taps. Free of scene
  //    units and of the first frame, and of resolution on smooth surfaces (the taps of a plane lie
  //    on it).
  //  kBilinear: the thesis's test: the bilinear sample of the four taps against the current pixel,
  //    position in scene units (or relativePosition), every tap on geometry.
  using GeometryTest = reprojection::GeometryTest;
  GeometryTest geometryTest = GeometryTest::kTaps;
  // kTaps: plane distance / view depth. kBilinear: world-position distance, in scene units; with
  // relativePosition, a fraction of the scene's size (the diagonal of the first frame's
  // world-position bounding box).
  double position = reprojection::kDefaultPositionThreshold;
  bool relativePosition = false;
  // Shading-normal vector distance ||n_i - n_{i-1}|| (0.1 is a turn of about 5.7 degrees).
  double normal = reprojection::kDefaultNormalThreshold;
  // Radiance vector distance ||L_i - L_{i-1}|| (RGB). By default a fraction of the current frame's
  // mean luminance of that buffer (the exposure-like tuning the thesis did by hand);
  // absoluteRadiance takes it in radiance units, as the thesis's functions literally do.
  double direct = frames::kDefaultRadianceThreshold, indirect = frames::kDefaultRadianceThreshold;
  bool absoluteRadiance = false;
  // How a radiance difference becomes a discard (docs/metrics.md, "Radiance discard"):
  //  kPairs (default): the frame's radiance-change pairs (render --pairs: each sample of frame i
  //    re-shaded in frame i-1 with the same random numbers, so no noise where nothing changed)
  //    decide each pixel by the sequential test of frames/radiance_change.h: changed, unchanged,
  //    or undecided (counted with the probability of a change, and bounding the column's interval
  //    both ways). Exact reprojection: the history is the same surface point, so the taps and the
  //    edge rule play no part in these columns.
  //  kExpected: each pixel counts with the probability that its true change exceeds the
  //    threshold, given its Monte Carlo noise (the variance channels) under the normal
  //    approximation; the column is the expected percentage, with a 95 % interval.
  //  kNoiseAware: the difference must also exceed noiseSigmas standard deviations of the noise.
  //  kPlain: the thesis's test on the rendered values (noise counts as change).
  enum class RadianceTest { kPairs, kExpected, kNoiseAware, kPlain };
  RadianceTest radianceTest = RadianceTest::kPairs;
  double noiseSigmas = 3.0;

  // The geometry test's part (reprojection/history.h), for absolute thresholds.
  reprojection::SurfaceThresholds surface() const { return {geometryTest, position, normal}; }
};

const char* radianceTestName(Thresholds::RadianceTest test);  // "pairs", "expected", "noise-aware", "plain"
// Every radiance test with its name, in that order: the one list the CLI, the Python module and
// discard.json's reader take the names from.
const std::vector<std::pair<std::string, Thresholds::RadianceTest>>& radianceTestsByName();
const char* geometryTestName(Thresholds::GeometryTest test);  // "taps", "bilinear"
// The thesis's default world-position threshold of the bilinear test: 0.05 scene units.
inline constexpr double kBilinearPositionThreshold = 0.05;
// `thresholds` as `discard` (the CLI and the Python module) takes them: relativePosition asks for
// the thesis's bilinear test; the position threshold is `position` or else the geometry test's
// default (0.01 of the view depth for taps, kBilinearPositionThreshold for bilinear).
Thresholds withPositionDefault(Thresholds thresholds, std::optional<double> position);

// A 95 % interval of a percentage.
struct Interval {
  double low = 0.0, high = 0.0;
  double halfWidth() const { return 0.5 * (high - low); }
};

// Why a pixel was discarded, per feature (a pixel may be discarded for several features).
enum DiscardBit : unsigned char {
  kFrustum = 1,
  kPosition = 2,
  kNormal = 4,
  kDirect = 8,
  kIndirect = 16,
  // The pairs test left the pixel's direct or indirect change undecided at the render's pair cap
  // (neither kDirect nor kIndirect is set for it then): drawn apart in the masks, not as change.
  kUndecided = 32,
};

struct FramePercentages {
  long frame = 0;       // the current frame i (compared with i - 1)
  double time = 0.0;
  double frustum = 0, position = 0, normal = 0, direct = 0, indirect = 0;  // percent of w x h
  // The radiance columns' 95 % intervals (the kPairs and kExpected tests; absent otherwise).
  std::optional<Interval> directInterval, indirectInterval;
  // Percent of w x h whose outcome the noise leaves open. kPairs: the pixels the sequential test
  // left undecided at the render's pair cap. kExpected: those whose noise (on the threshold's
  // scale) exceeds half the threshold, where noise alone counts as change with probability 5 % or
  // more. A column whose share is large measures the render's noise more than the dataset (a
  // warning says so, and the report marks it †).
  double directNoisy = 0, indirectNoisy = 0;
  bool cut = false;  // frame i's sidecar marks a camera cut: a jump, not motion
};

// Table 6.7's five columns, in its order: each one's key, the one spelling every machine-readable
// output uses (discard.json, discard.csv, suite.json), its label in tables and plots, and the
// FramePercentages members holding it (a radiance column also its interval and uncertain share;
// null for the geometric columns).
struct Table67Column {
  const char* key;
  const char* label;
  double FramePercentages::*member;
  std::optional<Interval> FramePercentages::*interval = nullptr;
  double FramePercentages::*noisy = nullptr;
};
inline constexpr std::array<Table67Column, 5> kTable67Columns{
    {{"frustum", "frustum", &FramePercentages::frustum},
     {"world_position", "world position", &FramePercentages::position},
     {"shading_normal", "shading normal", &FramePercentages::normal},
     {"direct_radiance", "direct radiance", &FramePercentages::direct, &FramePercentages::directInterval, &FramePercentages::directNoisy},
     {"indirect_radiance", "indirect radiance", &FramePercentages::indirect, &FramePercentages::indirectInterval, &FramePercentages::indirectNoisy}}};

// The share of uncertain pixels (FramePercentages::directNoisy) above which discard warns and the
// report marks the column: kExpected's noisy pixels, and kPairs' undecided ones.
inline constexpr double kNoisyWarning = 5.0;
inline constexpr double kUndecidedWarning = 0.5;
double uncertainLimit(Thresholds::RadianceTest test);  // kUndecidedWarning for kPairs, else kNoisyWarning

struct DiscardResult {
  FramePercentages percentages;
  std::vector<unsigned char> mask;  // DiscardBit per pixel
};

// Scales thresholds that are relative (position by scene size, radiance by the current frame's
// mean luminance) into absolute ones for this pair.
Thresholds absoluteThresholds(const Thresholds& thresholds, const FeatureFrame& current, double sceneSize);

// Compares frame `current` (i) with `previous` (i - 1); thresholds are absolute here. The pairs
// test reads `current`'s radiance-change pairs; a frame without them gets the expected test.
DiscardResult discardFrame(const FeatureFrame& current, const FeatureFrame& previous, const Thresholds& absolute);

// The diagonal of the world-position bounding box of a frame's hit pixels (0 when none).
double sceneSize(const FeatureFrame& frame);

}  // namespace dynbench::discard

namespace dynbench::discard {

struct DiscardRun {
  std::vector<FramePercentages> frames;  // one per compared pair (i - 1, i)
  FramePercentages mean;                 // Eq. (3.5) over those pairs (frame = -1)
  Thresholds thresholds;                 // as given
  double sceneSize = 0.0;                // used by relativePosition
  int width = 0, height = 0;
  std::size_t cutPairs = 0;              // pairs whose frame i is a camera cut
  bool cutsInMean = false;               // whether the mean covers them (by default it leaves them out)
  std::vector<std::string> warnings;
};

// Called with each compared frame (the current one and its mask), e.g. to write a mask image.
using MaskSink = std::function<Expected<void>(const FeatureFrame& current, const DiscardResult& result)>;
// Called after each frame read: (frames done, frames total).
using DiscardProgress = std::function<void(std::size_t, std::size_t)>;

// Streams a frames folder (two frames in memory at a time) and compares each frame with the one
// before it. Frames must be consecutive; a gap skips that pair with a warning. Pairs whose frame i
// is a camera cut (sidecar `cut`) are compared and listed but left out of the mean unless
// cutsInMean: after a jump every temporal method starts afresh, so its discard is not a property of
// the motion.
Expected<DiscardRun> discardFolder(const std::filesystem::path& dir, const Thresholds& thresholds, const MaskSink& masks = {},
                                   const DiscardProgress& progress = {}, bool cutsInMean = false);

// The `discard --json` document: frames folder, size, thresholds, mean and per-frame percentages
// (docs/cli.md); what `dynbench report` reads.
nlohmann::json discardJson(const DiscardRun& run, const std::string& framesDir);
// Reads back what discardJson wrote: size, mean and per-frame percentages (thresholds and warnings
// are not read). Errors name the file and the JSON pointer of a missing or malformed value.
Expected<DiscardRun> readDiscardJson(const std::filesystem::path& path);

// The mask image of Figure 6.2: the frame's direct + indirect radiance, tone-mapped and dimmed,
// with discarded pixels coloured by their first reason (frustum red, world position yellow,
// shading normal blue, direct magenta, indirect cyan), and pixels whose radiance change the pairs
// test left undecided white. 8-bit RGB values in [0, 1].
std::vector<float> maskImage(const FeatureFrame& frame, const std::vector<unsigned char>& mask);

}  // namespace dynbench::discard
