#pragma once
// A temporal method: a real-time algorithm that turns a sequence of noisy frames (radiance plus
// G-buffers and motion, the feature-buffer contract) into output images, reusing its own history.
// Each method is one file behind this interface (docs/metrics.md, "Temporal methods"); `evaluate`
// runs it over a frames folder in order and scores every output against a converged reference.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "discard/discard.h"
#include "evaluate/flip.h"
#include "frames/feature_frame.h"

namespace dynbench::evaluate {

struct MethodOutput {
  RgbImage image;                     // linear radiance, the input's size
  std::optional<double> historyUse;   // fraction of pixels whose history was kept (unknown: external)
};

class TemporalMethod {
 public:
  virtual ~TemporalMethod() = default;
  virtual std::string name() const = 0;
  // The parameters that define the method's output (recorded with its scores).
  virtual nlohmann::json parameters() const = 0;
  // Forgets all history: at the first frame and at every camera cut.
  virtual void reset() = 0;
  // The next frame in order; its output image.
  virtual Expected<MethodOutput> process(const frames::FeatureFrame& frame) = 0;
};

struct MethodContext {
  // The history tests of `accumulate` (and the scene size a relative position threshold needs):
  // the discard stage's own tests.
  discard::Thresholds thresholds;
  double sceneSize = 0.0;
};

// A built-in method: its name as the CLI, manifests and Python spell it, a line for help texts,
// and its factory. Adding a method is one file (its class and factory) and one entry in
// builtInMethods() (CONTRIBUTING.md, "Adding a temporal method").
// The input a method is built for (issue 48): "jittered", the projection jittered from frame to
// frame (render --jitter, the Halton sequence TAA turns into anti-aliasing), or "still", the pixel
// centres every frame, as accumulation and SVGF's paper feed them path-traced frames.
inline constexpr std::string_view kJitteredInput = "jittered", kStillInput = "still";
struct MethodInfo {
  std::string_view name;
  std::string_view description;
  std::function<std::unique_ptr<TemporalMethod>(const MethodContext&)> make;
  std::string_view input = kJitteredInput;  // the input it is built for
};
// Every built-in method, in the order tables list them (none first: the floor the others must beat).
const std::vector<MethodInfo>& builtInMethods();
// Their names: the default of `evaluate --methods`, the demo, suites and Python.
std::vector<std::string> builtInMethodNames();
// The input a method spec is built for: a built-in method's own, "jittered" for any other.
std::string_view builtForInput(const std::string& spec);
// "none, accumulate, taa, svgf, external:DIR": the methods a spec may name, for help texts.
std::string methodSpecHelp();

// A built-in method's name or "external:DIR". Errors name the unknown method.
Expected<std::unique_ptr<TemporalMethod>> createMethod(const std::string& spec, const MethodContext& context);

// Shared by the methods: the frame's full radiance (direct + indirect) as an RgbImage.
RgbImage frameRadiance(const frames::FeatureFrame& frame);
// An image resampled at continuous pixel coordinates (x, y) (pixel centres at +0.5) by the
// Catmull-Rom cubic in x and in y (Keys 1981, a = -0.5), edges clamped: TAA's history fetch.
// Interpolates (a pixel centre returns that pixel) and keeps constants; its lobes may overshoot.
glm::dvec3 sampleCatmullRom(const RgbImage& image, double x, double y);

// Runs row(y) for every row y in [0, height), rows in parallel (each row's work must depend on
// the inputs alone), and returns the sum of what they return: a method's count of pixels that kept
// their history, independent of the schedule.
long sumOverRows(int height, const std::function<long(int)>& row);

// The parts of a frame that reprojection::HistoryLookup reads of the previous one (number, camera, size,
// position, normal, hit): what a method keeps as its history's geometry, instead of a copy of
// every buffer (at 1080p about 150 MB a frame).
frames::FeatureFrame historyFrame(const frames::FeatureFrame& frame);

// Factories, one per method file.
// The built-in methods' names: the registry's (builtInMethods) and each method's name().
inline constexpr const char *kNoneMethod = "none", *kAccumulateMethod = "accumulate", *kTaaMethod = "taa", *kSvgfMethod = "svgf";
std::unique_ptr<TemporalMethod> makeNoneMethod();
std::unique_ptr<TemporalMethod> makeAccumulateMethod(const MethodContext& context);
std::unique_ptr<TemporalMethod> makeTaaMethod();
std::unique_ptr<TemporalMethod> makeSvgfMethod();
Expected<std::unique_ptr<TemporalMethod>> makeExternalMethod(const std::filesystem::path& dir);

}  // namespace dynbench::evaluate
