#include "evaluate/evaluate.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <future>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "core/files.h"
#include "core/image_io.h"
#include "core/json_fields.h"
#include "evaluate/compare.h"
#include "evaluate/image_metrics.h"
#include "evaluate/method.h"
#include "frames/frame_io.h"

namespace dynbench::evaluate {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// PSNR (peak 1) of a difference of differences.
double psnrOfMse(double mse) { return mse == 0.0 ? std::numeric_limits<double>::infinity() : 10.0 * std::log10(1.0 / mse); }

MeanWithError meanOf(const std::vector<FrameScores>& frames, const std::function<std::optional<double>(const FrameScores&)>& get) {
  MeanWithError m;
  double sum = 0.0, sumSq = 0.0;
  for (const FrameScores& f : frames)
    if (auto v = get(f); v && std::isfinite(*v)) sum += *v, sumSq += *v * *v, ++m.count;
  if (m.count == 0) return m;
  m.mean = sum / m.count;
  if (m.count > 1) {
    const double variance = std::max(0.0, (sumSq - m.count * m.mean * m.mean) / (m.count - 1));
    m.standardError = std::sqrt(variance / m.count);
  }
  return m;
}

// What the temporal scores of frame t need of the reference, the same for every method: the
// display transform d() at frame t's reference exposure (applied to both frames of the pair), the
// reference pair through it, and where each pixel's error of frame t - 1 is fetched from (the
// reference's motion for surfaces, the camera matrices for the background; none where the
// reference itself has no valid history: off screen or disoccluded).
struct ReferencePair {
  const RgbImage* current = nullptr;
  const RgbImage* previous = nullptr;
  double scale = 1.0;
  const RgbImage* display = nullptr;  // the current reference's (PreparedReference's)
  RgbImage previousDisplay;
  std::vector<std::optional<reprojection::BilinearTaps>> warp;
  long warped = 0;  // pixels with a warp
};
ReferencePair referencePair(const PreparedReference& ref, const RgbImage& refPrev, const frames::FeatureFrame& refFrame,
                            const frames::FeatureFrame& refPrevFrame, const discard::Thresholds& absolute) {
  ReferencePair pair;
  pair.current = &ref.linear, pair.previous = &refPrev;
  pair.scale = ref.displayScale;
  pair.display = &ref.display, pair.previousDisplay = toDisplay(refPrev, pair.scale);
  pair.warp.resize(refFrame.pixelCount());
  const reprojection::HistoryLookup lookup(refFrame, refPrevFrame, absolute.surface(), /*useMotion=*/true);
  tbb::parallel_for(0, refFrame.height, [&](int y) {
    for (int x = 0; x < refFrame.width; ++x) pair.warp[static_cast<std::size_t>(y) * refFrame.width + x] = lookup(x, y);
  });
  for (const auto& taps : pair.warp) pair.warped += taps ? 1 : 0;
  return pair;
}

struct TemporalScores {
  double tPsnr, tRelMse, warpedErrorChange, warpValid;
};

// docs/metrics.md, "Temporal error".
TemporalScores temporalScores(const RgbImage& out, const RgbImage& outPrev, const ReferencePair& ref) {
  const RgbImage dOut = toDisplay(out, ref.scale), dOutPrev = toDisplay(outPrev, ref.scale);
  const RgbImage &dRef = *ref.display, &dRefPrev = ref.previousDisplay, &r = *ref.current, &rPrev = *ref.previous;
  TemporalScores s{};
  double sq = 0.0, rel = 0.0;
  for (std::size_t k = 0; k < r.rgb.size(); ++k) {
    // Frame differences (Noisebase's temporal metrics): display for tPSNR, linear for tRelMSE.
    const double dd = (static_cast<double>(dOut.rgb[k]) - dOutPrev.rgb[k]) - (static_cast<double>(dRef.rgb[k]) - dRefPrev.rgb[k]);
    sq += dd * dd;
    const double dl = (static_cast<double>(out.rgb[k]) - outPrev.rgb[k]) - (static_cast<double>(r.rgb[k]) - rPrev.rgb[k]);
    rel += dl * dl / (static_cast<double>(r.rgb[k]) * r.rgb[k] + 0.01);
  }
  s.tPsnr = psnrOfMse(sq / r.rgb.size());
  s.tRelMse = rel / r.rgb.size();
  // e_t - warp(e_{t-1}), e = d(output) - d(reference), over the pixels the reference's warp covers.
  double change = 0.0;
  for (std::size_t i = 0; i < ref.warp.size(); ++i) {
    if (!ref.warp[i]) continue;
    const reprojection::BilinearTaps& taps = *ref.warp[i];
    for (int c = 0; c < 3; ++c) {
      double previousError = 0.0;
      for (int k = 0; k < 4; ++k)
        previousError += taps.weight[k] * (static_cast<double>(dOutPrev.rgb[3 * taps.index[k] + c]) - dRefPrev.rgb[3 * taps.index[k] + c]);
      const double d = (static_cast<double>(dOut.rgb[3 * i + c]) - dRef.rgb[3 * i + c]) - previousError;
      change += d * d;
    }
  }
  s.warpValid = static_cast<double>(ref.warped) / static_cast<double>(ref.warp.size());
  s.warpedErrorChange = ref.warped ? std::sqrt(change / (3.0 * ref.warped)) : 0.0;
  return s;
}

Expected<void> writeOutput(const fs::path& path, const RgbImage& image) {
  FloatImage f;
  f.width = image.width, f.height = image.height, f.channels = 3, f.pixels = image.rgb;
  f.channelNames = {"R", "G", "B"};
  return writeImage(path, f);
}

json optionalJson(const std::optional<double>& v) { return v && std::isfinite(*v) ? json(*v) : json(nullptr); }
json meanJson(const MeanWithError& m) { return {{"mean", m.count ? json(m.mean) : json(nullptr)}, {"stderr", m.standardError}, {"frames", m.count}}; }

}  // namespace

std::string methodFolder(const std::string& name) {
  std::string s = name;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return s;
}

Expected<MeanWithError> referenceNoiseFloor(const fs::path& reference, const fs::path& other, double pixelsPerDegree) {
  auto others = frames::listFrames(other);
  if (!others) return std::unexpected(others.error());
  if (others->empty()) return fail(ErrorCode::kInvalidData, "{}: no frames (frame_NNNNN.exr + .json)", other.string());
  std::vector<FrameScores> scores;
  for (const frames::FrameEntry& entry : *others) {
    const fs::path referenceImage = frames::frameImagePath(reference, entry.frame);
    auto referenceEntry = frames::frameEntry(referenceImage);
    if (!referenceEntry) return std::unexpected(referenceEntry.error());
    auto a = frames::readFrame(*referenceEntry);
    if (!a) return std::unexpected(a.error());
    auto b = frames::readFrame(entry);
    if (!b) return std::unexpected(b.error());
    if (a->width != b->width || a->height != b->height)
      return fail(ErrorCode::kInvalidData, "{}: {}x{} pixels, but {} is {}x{}", entry.image.string(), b->width, b->height, referenceImage.string(),
                  a->width, a->height);
    FrameScores s;
    s.frame = entry.frame;
    s.flip = scoreImage(frameRadiance(*a), frameRadiance(*b), /*hdr=*/true, pixelsPerDegree).scores.flip.mean;
    scores.push_back(s);
  }
  return meanOf(scores, [](const FrameScores& s) { return std::optional(s.flip); });
}

Expected<EvaluateRun> runEvaluate(const EvaluateOptions& options, const EvaluateProgress& progress) {
  auto inputs = frames::listFrames(options.frames);
  if (!inputs) return std::unexpected(inputs.error());
  if (inputs->empty()) return fail(ErrorCode::kInvalidData, "{}: no frames (frame_NNNNN.exr + .json)", options.frames.string());
  auto references = frames::listFrames(options.reference);
  if (!references) return std::unexpected(references.error());
  std::map<long, frames::FrameEntry> referenceByFrame;
  for (const auto& e : *references) referenceByFrame[e.frame] = e;
  for (const auto& e : *inputs)
    if (!referenceByFrame.count(e.frame))
      return fail(ErrorCode::kInvalidData, "{}: no reference for frame {} of {} (expected {})", options.reference.string(), e.frame,
                  options.frames.string(), frames::frameImagePath(options.reference, e.frame).string());
  if (options.methods.empty() && options.callerMethods.empty())
    return fail(ErrorCode::kUsage, "no methods to evaluate (expected some of {})", methodSpecHelp());

  EvaluateRun run;
  run.frames = options.frames, run.reference = options.reference;
  // The first input frame fixes the size and the scene size of a relative position threshold.
  auto first = frames::readFrame(inputs->front());
  if (!first) return std::unexpected(first.error());
  run.width = first->width, run.height = first->height;
  MethodContext context{options.thresholds, discard::sceneSize(*first)};
  std::vector<std::shared_ptr<TemporalMethod>> methods;
  for (const std::string& spec : options.methods) {
    auto m = createMethod(spec, context);
    if (!m) return std::unexpected(m.error());
    methods.push_back(std::move(*m));
  }
  methods.insert(methods.end(), options.callerMethods.begin(), options.callerMethods.end());
  for (const auto& m : methods) {
    MethodScores scores;
    scores.name = m->name(), scores.parameters = m->parameters();
    run.methods.push_back(std::move(scores));
  }
  if (!options.outDir.empty())
    for (const auto& m : run.methods) {
      std::error_code ec;
      fs::create_directories(options.outDir / methodFolder(m.name), ec);
      if (ec) return fail(ErrorCode::kIo, "{}: {}", (options.outDir / methodFolder(m.name)).string(), ec.message());
    }

  std::optional<frames::FeatureFrame> previousReference;
  std::optional<RgbImage> previousReferenceImage;
  std::vector<std::optional<RgbImage>> previousOutput(methods.size());
  long previousFrame = std::numeric_limits<long>::min();
  // Frame f + 1's input and reference are read on another thread while frame f is scored (each
  // file once): reading and decompressing two EXR frames is a tenth of a 1080p frame's time.
  using Read = Expected<frames::FeatureFrame>;
  auto readPair = [&](std::size_t f) {
    return std::async(std::launch::async, [&, f] {
      const frames::FrameEntry& entry = (*inputs)[f];
      return std::pair<Read, Read>(frames::readFrame(entry), frames::readFrame(referenceByFrame.at(entry.frame)));
    });
  };
  std::future<std::pair<Read, Read>> next;
  for (std::size_t f = 0; f < inputs->size(); ++f) {
    const frames::FrameEntry& entry = (*inputs)[f];
    Read input = std::unexpected(Error{}), reference = std::unexpected(Error{});
    if (f == 0) {
      input = std::move(first), reference = frames::readFrame(referenceByFrame.at(entry.frame));
    } else {
      std::tie(input, reference) = next.get();
    }
    if (f + 1 < inputs->size()) next = readPair(f + 1);
    if (!input) return std::unexpected(input.error());
    if (!reference) return std::unexpected(reference.error());
    if (input->width != run.width || input->height != run.height || reference->width != run.width || reference->height != run.height)
      return fail(ErrorCode::kInvalidData, "frame {}: input {}x{} and reference {}x{}, but the first frame is {}x{} (every frame must be the same size)",
                  entry.frame, input->width, input->height, reference->width, reference->height, run.width, run.height);
    // A cut: the first frame, the sidecar's cut flag (input or reference), or a gap in the frames.
    const bool cut = f == 0 || input->cut || reference->cut || entry.frame != previousFrame + 1;
    const RgbImage referenceImage = frameRadiance(*reference);
    const discard::Thresholds absolute = discard::absoluteThresholds(options.thresholds, *reference, context.sceneSize);
    // The reference's share of the scores (its HDR-ꟻLIP exposures, its display image), once for
    // every method.
    const PreparedReference preparedReference(referenceImage, /*hdr=*/true, options.pixelsPerDegree);
    std::optional<ReferencePair> pair;
    if (!cut && previousReference) pair = referencePair(preparedReference, *previousReferenceImage, *reference, *previousReference, absolute);
    for (std::size_t m = 0; m < methods.size(); ++m) {
      if (cut) methods[m]->reset(), previousOutput[m].reset();
      auto output = methods[m]->process(*input);
      if (!output) return std::unexpected(output.error());
      const ScoredImage scored = scoreImage(preparedReference, output->image);
      FrameScores s;
      s.frame = entry.frame, s.cut = cut;
      s.flip = scored.scores.flip.mean, s.psnr = scored.scores.psnr, s.ssim = scored.scores.ssim, s.relMse = scored.scores.relMse;
      s.historyUse = output->historyUse;
      if (pair && previousOutput[m]) {
        const TemporalScores t = temporalScores(output->image, *previousOutput[m], *pair);
        s.tPsnr = t.tPsnr, s.tRelMse = t.tRelMse, s.warpedErrorChange = t.warpedErrorChange, s.warpValid = t.warpValid;
      }
      if (!options.outDir.empty()) {
        auto written = writeOutput(frames::frameImagePath(options.outDir / methodFolder(run.methods[m].name), entry.frame), output->image);
        if (!written) return std::unexpected(written.error());
      }
      run.methods[m].frames.push_back(s);
      previousOutput[m] = std::move(output->image);
    }
    previousReference = std::move(*reference);
    previousReferenceImage = referenceImage;
    previousFrame = entry.frame;
    if (progress) progress(f + 1, inputs->size());
  }

  for (MethodScores& m : run.methods) {
    m.flip = meanOf(m.frames, [](const FrameScores& s) { return std::optional(s.flip); });
    m.psnr = meanOf(m.frames, [](const FrameScores& s) { return std::optional(s.psnr); });
    m.ssim = meanOf(m.frames, [](const FrameScores& s) { return s.ssim; });
    m.relMse = meanOf(m.frames, [](const FrameScores& s) { return std::optional(s.relMse); });
    m.tPsnr = meanOf(m.frames, [](const FrameScores& s) { return s.tPsnr; });
    m.tRelMse = meanOf(m.frames, [](const FrameScores& s) { return s.tRelMse; });
    m.warpedErrorChange = meanOf(m.frames, [](const FrameScores& s) { return s.warpedErrorChange; });
    m.historyUse = meanOf(m.frames, [](const FrameScores& s) { return s.historyUse; });
    const auto worst = std::max_element(m.frames.begin(), m.frames.end(), [](const FrameScores& a, const FrameScores& b) { return a.flip < b.flip; });
    m.worstFrame = worst->frame;
    if (!options.outDir.empty()) {
      // The worst frame's heatmap, from the output just written and its reference.
      const fs::path folder = options.outDir / methodFolder(m.name);
      auto out = loadImage(frames::frameImagePath(folder, m.worstFrame));
      if (!out) return std::unexpected(out.error());
      auto ref = frames::readFrame(referenceByFrame[m.worstFrame]);
      if (!ref) return std::unexpected(ref.error());
      const ScoredImage scored = scoreImage(frameRadiance(*ref), out->linear, true, options.pixelsPerDegree);
      FloatImage heat;
      heat.width = run.width, heat.height = run.height, heat.channels = 3, heat.pixels = magma(scored.flipError);
      auto written = writeImage(folder / "flip_worst.png", heat);
      if (!written) return std::unexpected(written.error());
    }
  }

  if (!options.json.empty())
    if (auto w = writeFileAtomic(options.json, jsonFileText(evaluateJson(run))); !w) return std::unexpected(w.error());
  if (!options.csv.empty()) {
    std::string csv = "method,frame,cut,flip,psnr,ssim,relmse,tpsnr,trelmse,warped_error_change,warp_valid,history_use\n";
    auto num = [](const std::optional<double>& v) { return v && std::isfinite(*v) ? fmt::format("{:.6g}", *v) : std::string(); };
    for (const MethodScores& m : run.methods)
      for (const FrameScores& s : m.frames)
        csv += fmt::format("{},{},{},{:.6g},{},{},{:.6g},{},{},{},{},{}\n", m.name, s.frame, s.cut ? 1 : 0, s.flip, num(s.psnr), num(s.ssim), s.relMse,
                           num(s.tPsnr), num(s.tRelMse), num(s.warpedErrorChange), num(s.warpValid), num(s.historyUse));
    if (auto w = writeFileAtomic(options.csv, csv); !w) return std::unexpected(w.error());
  }
  return run;
}

std::string evaluateMarkdown(const EvaluateRun& run) {
  auto cell = [](const MeanWithError& m, int digits) {
    return m.count ? fmt::format("{:.{}f} ± {:.{}f}", m.mean, digits, m.standardError, digits) : std::string("n/a");
  };
  std::string md = fmt::format("Temporal methods on {} ({}x{}, {} frames), against {} (mean ± standard error over frames)\n\n",
                               run.frames.string(), run.width, run.height, run.methods.empty() ? 0 : run.methods.front().frames.size(),
                               run.reference.string());
  md += "| method | ꟻLIP ↓ | PSNR (dB) ↑ | SSIM ↑ | relMSE ↓ | tPSNR (dB) ↑ | tRelMSE ↓ | warped error change ↓ | history use |\n";
  md += "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const MethodScores& m : run.methods)
    md += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", m.name, cell(m.flip, 4), cell(m.psnr, 2), cell(m.ssim, 4),
                      cell(m.relMse, 4), cell(m.tPsnr, 2), cell(m.tRelMse, 4), cell(m.warpedErrorChange, 4), cell(m.historyUse, 3));
  return md;
}

json evaluateJson(const EvaluateRun& run) {
  json j = {{"format", "dynbench-evaluate"}, {"version", 1}, {"frames", run.frames.string()}, {"reference", run.reference.string()},
            {"width", run.width}, {"height", run.height}, {"methods", json::array()}};
  for (const MethodScores& m : run.methods) {
    json method = {{"name", m.name}, {"parameters", m.parameters}, {"worst_frame", m.worstFrame}};
    method["mean"] = {{"flip", meanJson(m.flip)},       {"psnr", meanJson(m.psnr)},       {"ssim", meanJson(m.ssim)},
                      {"relmse", meanJson(m.relMse)},   {"tpsnr", meanJson(m.tPsnr)},     {"trelmse", meanJson(m.tRelMse)},
                      {"warped_error_change", meanJson(m.warpedErrorChange)}, {"history_use", meanJson(m.historyUse)}};
    method["frames"] = json::array();
    for (const FrameScores& s : m.frames)
      method["frames"].push_back({{"frame", s.frame}, {"cut", s.cut}, {"flip", s.flip}, {"psnr", optionalJson(s.psnr)}, {"ssim", optionalJson(s.ssim)},
                                  {"relmse", s.relMse}, {"tpsnr", optionalJson(s.tPsnr)}, {"trelmse", optionalJson(s.tRelMse)},
                                  {"warped_error_change", optionalJson(s.warpedErrorChange)}, {"warp_valid", optionalJson(s.warpValid)},
                                  {"history_use", optionalJson(s.historyUse)}});
    j["methods"].push_back(method);
  }
  return j;
}

Expected<void> writeNoiseFloorJson(const fs::path& path, const MeanWithError& floor, unsigned referenceSeed, unsigned otherSeed) {
  const json j = {{"format", "dynbench-noise-floor"},
                  {"flip", {{"mean", floor.mean}, {"stderr", floor.standardError}}},
                  {"frames", floor.count},
                  {"seeds", {referenceSeed, otherSeed}}};
  return writeFileAtomic(path, jsonFileText(j));
}

Expected<MeanWithError> readNoiseFloorJson(const fs::path& path) {
  auto j = readJsonFile(path);
  if (!j) return std::unexpected(j.error());
  const JsonFields f(*j, path);
  if (!j->is_object() || j->value("format", "") != "dynbench-noise-floor")
    return fail(ErrorCode::kInvalidData, "{}: /format: expected \"dynbench-noise-floor\" (a suite's or the demo's RUN/floor.json)", path.string());
  MeanWithError floor;
  auto mean = f.number("/flip/mean");
  if (!mean) return std::unexpected(mean.error());
  auto error = f.number("/flip/stderr");
  if (!error) return std::unexpected(error.error());
  auto frames = f.count("/frames");
  if (!frames) return std::unexpected(frames.error());
  floor.mean = *mean, floor.standardError = *error, floor.count = static_cast<long>(*frames);
  return floor;
}

Expected<EvaluateRun> readEvaluateJson(const fs::path& path) {
  auto text = readWholeFile(path);
  if (!text) return std::unexpected(text.error());
  const json j = json::parse(*text, nullptr, false);
  if (j.is_discarded()) return fail(ErrorCode::kParse, "{}: not valid JSON", path.string());
  if (j.value("format", "") != "dynbench-evaluate")
    return fail(ErrorCode::kInvalidData, "{}: /format: expected \"dynbench-evaluate\" (a `dynbench evaluate --json` file)", path.string());
  EvaluateRun run;
  // A number at `pointer` below `node`, whose own pointer is `base` (for the error message).
  auto number = [&](const json& node, const std::string& base, const std::string& pointer) -> Expected<std::optional<double>> {
    const json::json_pointer p(pointer);
    if (!node.contains(p) || node.at(p).is_null()) return std::optional<double>();
    if (!node.at(p).is_number()) return fail(ErrorCode::kInvalidData, "{}: {}{}: expected a number", path.string(), base, pointer);
    return std::optional<double>(node.at(p).get<double>());
  };
  if (!j.contains("methods") || !j["methods"].is_array()) return fail(ErrorCode::kInvalidData, "{}: /methods: expected an array", path.string());
  run.frames = j.value("frames", ""), run.reference = j.value("reference", "");
  run.width = j.value("width", 0), run.height = j.value("height", 0);
  for (std::size_t mi = 0; mi < j["methods"].size(); ++mi) {
    const json& mj = j["methods"][mi];
    const std::string base = fmt::format("/methods/{}", mi);
    if (!mj.contains("name") || !mj["name"].is_string()) return fail(ErrorCode::kInvalidData, "{}: {}/name: expected a string", path.string(), base);
    MethodScores m;
    m.name = mj["name"].get<std::string>();
    m.parameters = mj.value("parameters", json::object());
    m.worstFrame = mj.value("worst_frame", -1L);
    auto mean = [&](const char* key, MeanWithError& out) -> Expected<void> {
      auto v = number(mj, base, fmt::format("/mean/{}/mean", key));
      if (!v) return std::unexpected(v.error());
      auto e = number(mj, base, fmt::format("/mean/{}/stderr", key));
      if (!e) return std::unexpected(e.error());
      out.mean = v->value_or(0.0), out.standardError = e->value_or(0.0), out.count = v->has_value() ? mj["mean"][key].value("frames", 1L) : 0;
      return {};
    };
    for (auto [key, target] : {std::pair{"flip", &m.flip}, {"psnr", &m.psnr}, {"ssim", &m.ssim}, {"relmse", &m.relMse}, {"tpsnr", &m.tPsnr},
                               {"trelmse", &m.tRelMse}, {"warped_error_change", &m.warpedErrorChange}, {"history_use", &m.historyUse}})
      if (auto ok = mean(key, *target); !ok) return std::unexpected(ok.error());
    if (mj.contains("frames") && mj["frames"].is_array())
      for (const json& fj : mj["frames"]) {
        FrameScores s;
        s.frame = fj.value("frame", 0L), s.cut = fj.value("cut", false), s.flip = fj.value("flip", 0.0), s.relMse = fj.value("relmse", 0.0);
        auto get = [&](const char* key) { return fj.contains(key) && fj[key].is_number() ? std::optional<double>(fj[key].get<double>()) : std::nullopt; };
        s.psnr = get("psnr").value_or(std::numeric_limits<double>::infinity()), s.ssim = get("ssim"), s.tPsnr = get("tpsnr");
        s.tRelMse = get("trelmse"), s.warpedErrorChange = get("warped_error_change"), s.warpValid = get("warp_valid"), s.historyUse = get("history_use");
        m.frames.push_back(s);
      }
    run.methods.push_back(std::move(m));
  }
  return run;
}

}  // namespace dynbench::evaluate
