#include "evaluate/method.h"

#include <algorithm>

#include <tbb/parallel_for.h>

namespace dynbench::evaluate {

RgbImage frameRadiance(const frames::FeatureFrame& frame) {
  RgbImage img{frame.width, frame.height, std::vector<float>(3 * frame.pixelCount())};
  for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = frame.direct[i] + frame.indirect[i];
  return img;
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
      {kNoneMethod, "the input as it is, reusing nothing: the floor the others must beat",
       [](const MethodContext&) { return makeNoneMethod(); }},
      {kAccumulateMethod, "reprojected history blended in, rejected by the discard stage's tests",
       [](const MethodContext& context) { return makeAccumulateMethod(context); }, kStillInput},
      {kTaaMethod, "temporal anti-aliasing (Karis 2014, Salvi 2016): Catmull-Rom history, variance clipping",
       [](const MethodContext&) { return makeTaaMethod(); }},
      // [S17] §3 filters "1 sample per pixel path traced" frames at the pixel centre; its temporal
      // reprojection has no jitter to undo.
      {kSvgfMethod, "spatiotemporal variance-guided filtering (Schied et al. 2017)", [](const MethodContext&) { return makeSvgfMethod(); }, kStillInput},
  };
  return methods;
}

std::vector<std::string> builtInMethodNames() {
  std::vector<std::string> names;
  for (const auto& m : builtInMethods()) names.emplace_back(m.name);
  return names;
}

std::string_view builtForInput(const std::string& spec) {
  for (const auto& m : builtInMethods())
    if (spec == m.name) return m.input;
  return kJitteredInput;
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
