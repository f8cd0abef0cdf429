#include "suite/validity.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "evaluate/evaluate.h"

namespace dynbench::suite {

const std::vector<std::string>& measureKeys() {
  static const std::vector<std::string> measures = [] {
    std::vector<std::string> m;
    for (const auto& column : discard::kTable67Columns) m.push_back(column.key);
    for (const char* camera : {"camera_position", "camera_rotation", "camera_yaw", "camera_pitch", "camera_cuts"}) m.push_back(camera);
    return m;
  }();
  return measures;
}

const std::vector<std::string>& errorKeys() {
  static const std::vector<std::string> errors{"flip", "warped_error_change", "flip_over_none", "flip_ratio_to_none"};
  return errors;
}

std::string measureLabel(const std::string& measure) {
  static const std::map<std::string, std::string> labels = [] {
    std::map<std::string, std::string> l{
      {"camera_position", "camera position change (scene units per frame)"}, {"camera_rotation", "camera rotation (degrees per frame)"},
      {"camera_yaw", "camera yaw change (degrees per frame)"}, {"camera_pitch", "camera pitch change (degrees per frame)"},
      {"camera_cuts", "camera cuts in the window"}};
    for (const auto& column : discard::kTable67Columns) l[column.key] = fmt::format("{} discard (%)", column.label);
    return l;
  }();
  const auto it = labels.find(measure);
  return it == labels.end() ? measure : it->second;
}
// Below this many datasets a bootstrap interval is not shown: resamples of a few points are
// mostly ties and duplicates, and their rho takes only a handful of values.

std::map<std::string, std::map<std::string, double>> errorsOf(const pipeline::MethodsOnTheirInputs& methods) {
  auto e = errorsOf(methods.jittered);
  for (auto& [method, errors] : errorsOf(methods.still)) e[method == "none" ? kStillNone : method] = errors;
  return e;
}

bool withinNoiseFloor(const DatasetResult& d, const std::string& method) {
  if (method == "none" || method == kStillNone || !d.referenceFloor) return false;
  // flip_over_none is against `none` on the method's own input.
  const auto m = d.errors.find(method);
  if (m == d.errors.end() || !m->second.count("flip_over_none")) return false;
  return evaluate::withinNoiseFloor(m->second.at("flip_over_none"), *d.referenceFloor);
}

std::string rankingError(const std::string& method) { return method == "none" || method == kStillNone ? "flip" : "flip_ratio_to_none"; }

std::vector<ValidityCell> validity(const std::vector<DatasetResult>& datasets) {
  std::vector<ValidityCell> cells;
  if (datasets.empty()) return cells;
  std::vector<std::string> methods;
  for (const auto& [method, errors] : datasets.front().errors) methods.push_back(method);
  for (const std::string& measure : measureKeys())
    for (const std::string& method : methods)
      for (const std::string& error : errorKeys()) {
        std::vector<double> x, y;
        for (const DatasetResult& d : datasets) {
          const auto m = d.measures.find(measure);
          const auto e = d.errors.find(method);
          if (m == d.measures.end() || e == d.errors.end()) continue;
          const auto v = e->second.find(error);
          if (v == e->second.end()) continue;
          x.push_back(m->second), y.push_back(v->second);
        }
        if (x.empty()) continue;
        cells.push_back({measure, method, error, metrics::rankCorrelation(x, y), static_cast<int>(x.size())});
      }
  return cells;
}

std::vector<WithinMatchCell> withinMatches(const std::vector<DatasetResult>& datasets) {
  // Camera policies in a fixed order: the bot's own first, the fly-through last, others between.
  std::vector<std::string> cameras;
  for (const DatasetResult& d : datasets)
    if (!d.camera.empty() && std::find(cameras.begin(), cameras.end(), d.camera) == cameras.end()) cameras.push_back(d.camera);
  auto order = [](const std::string& c) { return c == "bot" ? 0 : c == "flythrough" ? 2 : 1; };
  std::stable_sort(cameras.begin(), cameras.end(), [&](const std::string& a, const std::string& b) {
    return order(a) != order(b) ? order(a) < order(b) : a < b;
  });
  std::map<std::pair<std::string, std::string>, const DatasetResult*> byMatch;  // (match, camera) -> dataset
  for (const DatasetResult& d : datasets)
    if (!d.match.empty()) byMatch[{d.match, d.camera}] = &d;
  std::vector<std::string> matches;
  for (const auto& [key, d] : byMatch)
    if (matches.empty() || matches.back() != key.first) matches.push_back(key.first);
  std::vector<WithinMatchCell> cells;
  if (datasets.empty()) return cells;
  std::vector<std::string> methods;
  for (const auto& [method, errors] : datasets.front().errors) methods.push_back(method);
  for (std::size_t i = 0; i < cameras.size(); ++i)
    for (std::size_t j = i + 1; j < cameras.size(); ++j)
      for (const std::string& measure : measureKeys())
        for (const std::string& method : methods) {
          WithinMatchCell c;
          c.cameraA = cameras[i];
          c.cameraB = cameras[j];
          c.measure = measure;
          c.method = method;
          c.error = rankingError(method);
          std::vector<double> dm, de;
          for (const std::string& match : matches) {
            const auto a = byMatch.find({match, cameras[i]}), b = byMatch.find({match, cameras[j]});
            if (a == byMatch.end() || b == byMatch.end()) continue;
            const auto value = [&](const DatasetResult* d, bool error) -> std::optional<double> {
              if (!error) return d->measures.count(measure) ? std::optional(d->measures.at(measure)) : std::nullopt;
              const auto e = d->errors.find(method);
              if (e == d->errors.end() || !e->second.count(c.error)) return std::nullopt;
              return e->second.at(c.error);
            };
            const auto ma = value(a->second, false), mb = value(b->second, false), ea = value(a->second, true), eb = value(b->second, true);
            if (!ma || !mb || !ea || !eb) continue;
            dm.push_back(*ma - *mb), de.push_back(*ea - *eb);
            c.measureHigher += *ma > *mb;
            c.errorHigher += *ea > *eb;
          }
          if (dm.empty()) continue;
          c.matches = static_cast<int>(dm.size());
          c.errorSignTestP = metrics::signTestOneSided(c.errorHigher, c.matches);
          c.correlation = metrics::rankCorrelation(dm, de);
          cells.push_back(c);
        }
  return cells;
}

// The difficulty measures of one dataset's window (DatasetResult).
std::map<std::string, double> measuresOf(const metrics::CameraMotion& motion, long first, long last, const discard::FramePercentages& d) {
  std::map<std::string, double> m;
  for (const auto& column : discard::kTable67Columns) m[column.key] = d.*column.member;
  std::vector<double> position, rotation, yaw, pitch;
  double cuts = 0;
  for (long i = first + 1; i <= last && i < static_cast<long>(motion.frames.size()); ++i) {
    const metrics::CameraFrame& f = motion.frames[static_cast<std::size_t>(i)];
    if (f.cut) {
      ++cuts;
      continue;
    }
    position.push_back(f.positionDelta), rotation.push_back(f.rotationDelta), yaw.push_back(f.yawDelta), pitch.push_back(f.pitchDelta);
  }
  m["camera_position"] = metrics::summarize(position).mean;
  m["camera_rotation"] = metrics::summarize(rotation).mean;
  m["camera_yaw"] = metrics::summarize(yaw).mean;
  m["camera_pitch"] = metrics::summarize(pitch).mean;
  m["camera_cuts"] = cuts;
  return m;
}

std::map<std::string, std::map<std::string, double>> errorsOf(const std::vector<evaluate::MethodScores>& methods, std::optional<double> noneFlip) {
  std::map<std::string, std::map<std::string, double>> e;
  const auto none = std::find_if(methods.begin(), methods.end(), [](const auto& m) { return m.name == "none"; });
  if (none != methods.end()) noneFlip = none->flip.mean;
  for (const auto& m : methods) {
    e[m.name]["flip"] = m.flip.mean;
    e[m.name]["warped_error_change"] = m.warpedErrorChange.mean;
    if (!noneFlip) continue;
    e[m.name]["flip_over_none"] = m.flip.mean - *noneFlip;
    // a ratio of the window's means: where the input is noisier, none's error and a method's
    // residual both grow, and the ratio keeps what history does apart from how noisy the input is
    if (*noneFlip > 0) e[m.name]["flip_ratio_to_none"] = m.flip.mean / *noneFlip;
  }
  return e;
}
}  // namespace dynbench::suite
