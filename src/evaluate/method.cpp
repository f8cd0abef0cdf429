#include "evaluate/method.h"

#include <algorithm>

#include <tbb/parallel_for.h>

namespace dynbench::evaluate {

RgbImage frameRadiance(const frames::FeatureFrame& frame) {
  RgbImage img{frame.width, frame.height, std::vector<float>(3 * frame.pixelCount())};
  for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = frame.direct[i] + frame.indirect[i];
  return img;
}

HistoryLookup::HistoryLookup(const frames::FeatureFrame& current, const frames::FeatureFrame& previous, const discard::Thresholds& absolute,
                             bool useMotion)
    : current_(current), previous_(previous), absolute_(absolute), useMotion_(useMotion), currentProjector_(current.camera), previousProjector_(previous.camera) {}

std::optional<discard::BilinearTaps> HistoryLookup::operator()(int px, int py) const {
  const frames::FeatureFrame &current = current_, &previous = previous_;
  const std::size_t i = static_cast<std::size_t>(py) * current.width + px;
  const glm::dvec2 sample(px + 0.5 + current.camera.jitter.x, py + 0.5 + current.camera.jitter.y);
  const bool hit = current.hit[i] > 0;
  const glm::dvec3 p(hit ? glm::dvec3(current.position[3 * i], current.position[3 * i + 1], current.position[3 * i + 2]) : glm::dvec3(0.0));
  std::optional<glm::dvec2> q;
  if (!hit) {
    q = previousProjector_.direction(currentProjector_.pixelDirection(sample.x, sample.y));
  } else if (useMotion_ && !current.motion.empty()) {
    const glm::dvec2 motion(current.motion[2 * i], current.motion[2 * i + 1]);
    if (std::abs(motion.x) < 1e8 && std::abs(motion.y) < 1e8) q = sample + motion;  // -1e9: behind the previous camera
  } else {
    q = previousProjector_.point(p);
  }
  if (!q || q->x < 0 || q->y < 0 || q->x > previous.width || q->y > previous.height) return std::nullopt;
  // The previous frame's buffers are at its samples: centre + its jitter.
  const discard::BilinearTaps taps =
      discard::bilinearTaps(q->x - previous.camera.jitter.x, q->y - previous.camera.jitter.y, previous.width, previous.height);
  if (!hit) {
    // The background's history is the background.
    for (int k = 0; k < 4; ++k)
      if (taps.weight[k] > 0 && previous.hit[taps.index[k]] > 0) return std::nullopt;
    return taps;
  }
  // A surface's: the taps the discard's geometry test keeps (discard::testHistory).
  const glm::dvec3 n(current.normal[3 * i], current.normal[3 * i + 1], current.normal[3 * i + 2]);
  const double viewDepth = -(current.camera.view * glm::dvec4(p, 1.0)).z;
  const discard::HistoryTest test = discard::testHistory(p, n, viewDepth, previous, taps, absolute_);
  if (!test.consistent) return std::nullopt;
  return test.history;
}

long sumOverRows(int height, const std::function<long(int)>& row) {
  std::vector<long> perRow(static_cast<std::size_t>(std::max(height, 0)), 0);
  tbb::parallel_for(0, height, [&](int y) { perRow[static_cast<std::size_t>(y)] = row(y); });
  long sum = 0;
  for (long n : perRow) sum += n;
  return sum;
}

frames::FeatureFrame historyFrame(const frames::FeatureFrame& frame) {
  frames::FeatureFrame h;
  h.frame = frame.frame, h.time = frame.time, h.camera = frame.camera, h.width = frame.width, h.height = frame.height;
  h.position = frame.position, h.normal = frame.normal, h.hit = frame.hit;
  return h;
}

const std::vector<MethodInfo>& builtInMethods() {
  static const std::vector<MethodInfo> methods{
      {"none", "the input as it is, reusing nothing: the floor the others must beat",
       [](const MethodContext&) { return makeNoneMethod(); }},
      {"accumulate", "reprojected history blended in, rejected by the discard stage's tests",
       [](const MethodContext& context) { return makeAccumulateMethod(context); }},
      {"taa", "temporal anti-aliasing (Karis 2014, Salvi 2016): Catmull-Rom history, variance clipping",
       [](const MethodContext&) { return makeTaaMethod(); }},
      {"svgf", "spatiotemporal variance-guided filtering (Schied et al. 2017)", [](const MethodContext&) { return makeSvgfMethod(); }},
  };
  return methods;
}

std::vector<std::string> builtInMethodNames() {
  std::vector<std::string> names;
  for (const auto& m : builtInMethods()) names.emplace_back(m.name);
  return names;
}

std::string methodSpecHelp() {
  std::string text;
  for (const auto& m : builtInMethods()) {
    text += m.name;
    text += ", ";
  }
  return text + "external:DIR";
}

Expected<std::unique_ptr<TemporalMethod>> createMethod(const std::string& spec, const MethodContext& context) {
  for (const auto& m : builtInMethods())
    if (spec == m.name) return m.make(context);
  if (spec.starts_with("external:")) return makeExternalMethod(spec.substr(9));
  return fail(ErrorCode::kUsage, "unknown method '{}' (expected one of {})", spec, methodSpecHelp());
}

}  // namespace dynbench::evaluate
