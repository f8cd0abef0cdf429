#include "camera/flythrough.h"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <cmath>
#include <optional>

#include <fmt/format.h>

#include "camera/merge_camera.h"
#include "core/files.h"
#include "core/math.h"
#include "render/raytracing_scene.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"
#include "report/reference.h"

namespace dynbench::camera {

namespace fs = std::filesystem;

double OrcaCheck::distance() const {
  const double width = std::max(high - low, 1e-3);
  return value < low ? (low - value) / width : value > high ? (value - high) / width : 0.0;
}

bool FlythroughReport::insideOrca() const {
  return std::all_of(checks.begin(), checks.end(), [](const OrcaCheck& c) { return c.inside(); });
}

OrcaRange orcaRange(const std::string& table, std::size_t column) {
  static const Expected<report::Reference> reference = report::thesisReference();
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (!reference) return {kNaN, kNaN};
  OrcaRange range{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const auto& t : reference->tables) {
    if (t.table != table) continue;
    for (const auto& row : t.rows) {
      if (row.dataset != "Bistro Interior" && row.dataset != "Bistro Exterior" && row.dataset != "Emerald Square") continue;
      if (column >= row.cells.size()) return {kNaN, kNaN};
      const double v = std::strtod(row.cells[column].c_str(), nullptr);
      range.low = std::min(range.low, v);
      range.high = std::max(range.high, v);
    }
  }
  return range.low <= range.high ? range : OrcaRange{kNaN, kNaN};
}

std::vector<OrcaCheck> orcaChecks(const metrics::CameraMotionSummary& m, double metresPerUnit) {
  // Each check's range is the smallest and largest of the thesis's three ORCA rows (orcaRange).
  // Table 6.5 is the half angle (Eq. 2.4 taken literally): dynbench's full angle halved, its
  // variance quartered.
  const double half = 0.5;
  auto check = [](const char* measure, double value, const char* table, std::size_t column) {
    const OrcaRange r = orcaRange(table, column);
    return OrcaCheck{measure, value, r.low, r.high, table, column};
  };
  return {
      check("Table 6.4 position mean (m)", m.position.mean * metresPerUnit, "6.4", 0),
      check("Table 6.4 position variance (m²)", m.position.variance * metresPerUnit * metresPerUnit, "6.4", 1),
      check("Table 6.4 position max (m)", m.position.max * metresPerUnit, "6.4", 2),
      check("Table 6.5 rotation mean (°, half angle)", m.rotation.mean * half, "6.5", 0),
      check("Table 6.5 rotation variance (half angle)", m.rotation.variance * half * half, "6.5", 1),
      check("Table 6.5 rotation max (°, half angle)", m.rotation.max * half, "6.5", 2),
      check("Table 6.6 pitch mean (°)", m.pitch.mean, "6.6", 0),
      check("Table 6.6 pitch variance", m.pitch.variance, "6.6", 1),
      check("Table 6.6 yaw mean (°)", m.yaw.mean, "6.6", 2),
      check("Table 6.6 yaw variance", m.yaw.variance, "6.6", 3),
      check("Table 6.6 roll mean (°)", m.roll.mean, "6.6", 4),
      check("Table 6.6 roll variance", m.roll.variance, "6.6", 5),
  };
}

namespace {

// Linear interpolation along a polyline by arc length s (clamped to its ends).
struct Polyline {
  std::vector<glm::dvec3> points;
  std::vector<double> arc;  // cumulative length at each point
  explicit Polyline(std::vector<glm::dvec3> p) : points(std::move(p)) {
    arc.assign(points.size(), 0.0);
    for (std::size_t k = 1; k < points.size(); ++k) arc[k] = arc[k - 1] + glm::length(points[k] - points[k - 1]);
  }
  double length() const { return arc.empty() ? 0.0 : arc.back(); }
  glm::dvec3 at(double s) const {
    if (points.size() == 1 || s <= 0) return points.front();
    if (s >= length()) return points.back();
    const auto k = static_cast<std::size_t>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin()) - 1;
    const double span = arc[k + 1] - arc[k];
    return span > 0 ? glm::mix(points[k], points[k + 1], (s - arc[k]) / span) : points[k];
  }
};

// Moving average over +-half samples. kKeep: the window shrinks symmetrically at the ends, so
// the first and last values stay where they are (a path keeps its ends); kHold: the values
// beyond the ends are the end values held, so the ends are as smooth as the middle (a heading).
enum class Ends { kKeep, kHold };
template <typename T>
std::vector<T> movingAverage(const std::vector<T>& v, std::size_t half, Ends ends) {
  const std::size_t n = v.size();
  // Prefix sums over v padded with `half` held values on each side.
  std::vector<T> prefix(n + 2 * half + 1, T(0));
  for (std::size_t k = 0; k < n + 2 * half; ++k) prefix[k + 1] = prefix[k] + v[std::clamp(k, half, half + n - 1) - half];
  std::vector<T> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t h = ends == Ends::kKeep ? std::min({half, k, n - 1 - k}) : half;
    out[k] = (prefix[k + half + h + 1] - prefix[k + half - h]) / static_cast<double>(2 * h + 1);
  }
  return out;
}

// A cut-free stretch of the bot's camera.
struct Stretch {
  double start = 0, end = 0;  // s
  std::vector<glm::dvec3> points;
  double length = 0;
};

// The flight along one stretch: poses at options.rate over the whole duration.
struct Flight {
  FlythroughReport report;
  std::vector<glm::dvec3> positions;
  std::vector<double> yaw, pitch;  // radians
};

glm::dquat orientation(double yaw, double pitch) {
  return glm::angleAxis(yaw, glm::dvec3(0, 1, 0)) * glm::angleAxis(pitch, glm::dvec3(1, 0, 0));
}

class Flyer {
 public:
  Flyer(const FlythroughOptions& o, double duration, std::size_t samples, const render::StaticGeometry& walls)
      : o_(o), duration_(duration), samples_(samples), walls_(walls) {}

  double poseTime(std::size_t n) const { return duration_ * static_cast<double>(n) / static_cast<double>(samples_ - 1); }
  // Time t (from the start) between poses k and k + 1, at fraction a of the way.
  std::pair<std::size_t, double> between(double t) const {
    const double u = std::clamp(t / duration_, 0.0, 1.0) * static_cast<double>(samples_ - 1);
    const auto k = std::min(static_cast<std::size_t>(u), samples_ - 2);
    return {k, u - static_cast<double>(k)};
  }

  // Tables 6.4-6.6 of the flight's poses at the frame rate (linear interpolation between poses).
  metrics::CameraMotionSummary motion(const Flight& f) const {
    std::vector<glm::dvec3> positions;
    std::vector<glm::dquat> rotations;
    for (double t = 0; t <= duration_ + 1e-9; t += 1.0 / o_.frameRate) {
      const auto [k, a] = between(t);
      positions.push_back(glm::mix(f.positions[k], f.positions[k + 1], a));
      rotations.push_back(orientation(f.yaw[k] + a * (f.yaw[k + 1] - f.yaw[k]), f.pitch[k] + a * (f.pitch[k + 1] - f.pitch[k])));
    }
    return metrics::measurePoses(positions, rotations);
  }

  // nullopt when even the bot's own path crosses static geometry.
  std::optional<Flight> fly(const Stretch& stretch) const {
    Flight f;
    FlythroughReport& report = f.report;
    report.stretchStart = stretch.start, report.stretchEnd = stretch.end, report.stretchLength = stretch.length;
    const Polyline bot(stretch.points);
    const double unitSpeed = o_.speed / o_.metresPerUnit;
    // The stretch resampled every scene unit, then smoothed as widely as keeps the path out of walls.
    std::vector<glm::dvec3> even;
    for (double s = 0; s < bot.length(); s += 1.0) even.push_back(bot.at(s));
    even.push_back(bot.at(bot.length()));  // the stretch's own end
    if (even.size() < 2) even.push_back(even.back());
    std::optional<Polyline> path;
    f.positions.resize(samples_);
    std::vector<double> widths;
    for (double width = o_.maxSmoothing; width >= 4.0; width /= 2) widths.push_back(width);
    widths.push_back(0.0);
    for (double width : widths) {
      Polyline candidate(movingAverage(even, static_cast<std::size_t>(width / 2), Ends::kKeep));
      report.length = std::min(candidate.length(), unitSpeed * duration_);  // smoothing shortens the path
      for (std::size_t n = 0; n < samples_; ++n) f.positions[n] = candidate.at(report.length * poseTime(n) / duration_);
      // The chords the renderer's frames make (dataset frame rate) as well as the poses' own.
      std::vector<glm::dvec3> frames;
      for (double t = 0; t <= duration_ + 1e-9; t += 1.0 / o_.frameRate) frames.push_back(candidate.at(report.length * t / duration_));
      report.smoothing = width;
      path.emplace(std::move(candidate));
      if (walls_.segmentsThrough(f.positions).empty() && walls_.segmentsThrough(frames).empty()) break;
      if (width == 0.0) return std::nullopt;
    }

    // Heading: towards the path lookAhead further on, level but for half the path's slope (at most
    // 10 degrees); yaw and pitch then averaged over a window that widens until their per-frame
    // changes at frameRate are within the ORCA bounds.
    const double ahead = o_.lookAhead / o_.metresPerUnit;
    std::vector<double> rawYaw(samples_), rawPitch(samples_);
    for (std::size_t n = 0; n < samples_; ++n) {
      const double s = report.length * poseTime(n) / duration_;
      glm::dvec3 d = path->at(s + ahead) - path->at(s);
      if (glm::length(glm::dvec2(d.x, d.z)) < 1e-6) d = path->at(s) - path->at(std::max(0.0, s - ahead));
      const double horizontal = glm::length(glm::dvec2(d.x, d.z));
      double yaw = horizontal > 1e-6 ? std::atan2(-d.x, -d.z) : (n > 0 ? rawYaw[n - 1] : 0.0);
      if (n > 0) yaw = rawYaw[n - 1] + std::remainder(yaw - rawYaw[n - 1], 2.0 * kPi);  // unwrapped
      rawYaw[n] = yaw;
      rawPitch[n] = std::clamp(0.5 * std::atan2(d.y, std::max(horizontal, 1e-6)), -radians(10.0), radians(10.0));
    }
    // Mean and variance of |change| per frame at frameRate, the poses interpolated linearly.
    auto perFrame = [&](const std::vector<double>& angle) {
      std::vector<double> changes;
      auto at = [&](double t) {
        const auto [k, a] = between(t);
        return angle[k] + a * (angle[k + 1] - angle[k]);
      };
      for (double t = 1.0 / o_.frameRate; t <= duration_ + 1e-9; t += 1.0 / o_.frameRate)
        changes.push_back(std::abs(degrees(at(t) - at(t - 1.0 / o_.frameRate))));
      return metrics::summarize(changes);
    };
    // Yaw and pitch each get the narrowest window (in steps of 10 %) that meets their bounds, so
    // they keep as much of the path's motion as ORCA's cameras have.
    auto smooth = [&](const std::vector<double>& raw, double maxMean, double maxVariance, double maxChange, std::vector<double>& out, double& window,
                      double& mean, double& variance) {
      for (window = 1.0;; window *= 1.1) {
        out = movingAverage(raw, static_cast<std::size_t>(0.5 * window * o_.rate), Ends::kHold);
        const metrics::Summary s = perFrame(out);
        mean = s.mean, variance = s.variance;
        if ((mean <= maxMean && variance <= maxVariance && s.max <= maxChange) || window > duration_) return;
      }
    };
    smooth(rawYaw, o_.maxYawMean, o_.maxYawVariance, o_.maxYawChange, f.yaw, report.headingWindow, report.yawMean, report.yawVariance);
    smooth(rawPitch, o_.maxPitchMean, o_.maxPitchVariance, o_.maxYawChange, f.pitch, report.pitchWindow, report.pitchMean, report.pitchVariance);
    // The pitch's floor: a nod A sin(2 pi t / T) changes by 4 A / (T frameRate) a frame on average;
    // raised in steps of 10 % from that estimate until the mean reaches the target.
    if (o_.pitchTarget > 0 && report.pitchMean < o_.minPitchMean) {
      const std::vector<double> smoothed = f.pitch;
      for (double amplitude = radians(o_.pitchTarget * o_.nodPeriod * o_.frameRate / 4.0) * 0.5;; amplitude *= 1.1) {
        for (std::size_t n = 0; n < samples_; ++n) f.pitch[n] = smoothed[n] + amplitude * std::sin(2.0 * kPi * poseTime(n) / o_.nodPeriod);
        const metrics::Summary nodded = perFrame(f.pitch);
        report.pitchMean = nodded.mean, report.pitchVariance = nodded.variance;
        report.nodAmplitude = degrees(amplitude);
        if (report.pitchMean >= o_.pitchTarget || amplitude > radians(10.0)) break;
      }
    }
    report.poses = samples_;
    report.speed = report.length / duration_;
    report.checks = orcaChecks(motion(f), o_.metresPerUnit);
    return f;
  }

 private:
  const FlythroughOptions& o_;
  double duration_;
  std::size_t samples_;
  const render::StaticGeometry& walls_;
};

double totalDistance(const FlythroughReport& r) {
  double d = 0;
  for (const OrcaCheck& c : r.checks) d += c.distance();
  return d;
}

Expected<void> checkOptions(const FlythroughOptions& o) {
  if (!(o.speed > 0) || !(o.lookAhead > 0) || !(o.rate > 0) || !(o.frameRate > 0) || !(o.maxSmoothing >= 0) || !(o.metresPerUnit > 0) ||
      o.candidates < 1)
    return fail(ErrorCode::kUsage, "fly-through: speed, look-ahead, rates and metres per unit must be positive, candidates at least 1");
  return {};
}

}  // namespace

Expected<FlythroughPoses> flyThroughPoses(const fs::path& dataset, const FlythroughOptions& o) {
  if (auto ok = checkOptions(o); !ok) return std::unexpected(ok.error());  // before any file is read
  auto loaded = loadAnimatedCamera(dataset, "fly along");
  if (!loaded) return std::unexpected(loaded.error());
  auto walls = render::StaticGeometry::create(loaded->scene);  // built once for every stretch and width tried
  if (!walls) return std::unexpected(walls.error());
  return flyThroughPoses(*loaded, *walls, dataset, o);
}

Expected<FlythroughPoses> flyThroughPoses(const AnimatedCamera& loaded, const render::StaticGeometry& walls, const fs::path& dataset,
                                          const FlythroughOptions& o) {
  if (auto ok = checkOptions(o); !ok) return std::unexpected(ok.error());
  const scene::Scene& scene = loaded.scene;
  const int cameraNode = loaded.node;
  const auto range = loaded.range;
  const double duration = loaded.duration();
  const auto& node = scene.nodes[static_cast<std::size_t>(cameraNode)];
  const scene::Evaluator evaluator(scene);
  const std::size_t samples = std::max<std::size_t>(2, static_cast<std::size_t>(std::ceil(duration * o.rate)) + 1);
  auto timeAt = [&](std::size_t n) { return range.start + duration * static_cast<double>(n) / static_cast<double>(samples - 1); };

  // The bot's stretches between camera cuts, longest first.
  std::vector<Stretch> stretches(1);
  for (std::size_t n = 0; n < samples; ++n) {
    if (n > 0 && scene::cameraCutBetween(node, timeAt(n - 1), timeAt(n))) {
      stretches.back().end = timeAt(n - 1);
      stretches.emplace_back().start = timeAt(n);
    }
    stretches.back().points.emplace_back(evaluator.worldMatrix(cameraNode, timeAt(n))[3]);
  }
  stretches.back().end = timeAt(samples - 1);
  for (Stretch& s : stretches) s.length = Polyline(s.points).length();
  std::stable_sort(stretches.begin(), stretches.end(), [](const Stretch& a, const Stretch& b) { return a.length > b.length; });

  const Flyer flyer(o, duration, samples, walls);
  // The longest stretch whose flight is inside every ORCA range; where none is, the one closest.
  std::optional<Flight> best;
  int compared = 0;
  for (std::size_t k = 0; k < stretches.size() && compared < o.candidates; ++k) {
    if (stretches[k].points.size() < 2) continue;
    auto flight = flyer.fly(stretches[k]);
    ++compared;
    if (!flight) continue;
    if (!best || totalDistance(flight->report) < totalDistance(best->report)) best = std::move(flight);
    if (best->report.insideOrca()) break;  // the longest inside
  }
  if (!best)
    return fail(ErrorCode::kInvalidData, "{}: the bot's own path crosses static geometry on each of the {} longest stretches; no fly-through made",
                dataset.string(), compared);
  best->report.stretchesCompared = compared;
  FlythroughPoses flown;
  flown.report = best->report;
  for (std::size_t n = 0; n < samples; ++n)
    flown.keys.push_back({flyer.poseTime(n), best->positions[n], orientation(best->yaw[n], best->pitch[n])});
  return flown;
}

Expected<FlythroughReport> writeFlythroughCsv(const fs::path& dataset, const fs::path& csv, const FlythroughOptions& o) {
  auto flown = flyThroughPoses(dataset, o);
  if (!flown) return std::unexpected(flown.error());
  if (auto ok = writeCameraRunCsv(csv, flown->keys); !ok) return std::unexpected(ok.error());
  return flown->report;
}

bool FlythroughDataset::insideOrca() const {
  return std::all_of(checks.begin(), checks.end(), [](const OrcaCheck& c) { return c.inside(); });
}

Expected<FlythroughDataset> makeFlythroughDataset(const fs::path& dataset, const fs::path& output, const fs::path& csv, const FlythroughOptions& o) {
  FlythroughDataset made;
  auto flight = writeFlythroughCsv(dataset, csv, o);
  if (!flight) return std::unexpected(flight.error());
  made.flight = *flight;
  auto motion = mergeAndMeasure(dataset, csv, output, o.frameRate);
  if (!motion) return std::unexpected(motion.error());
  made.checks = orcaChecks(*motion, o.metresPerUnit);
  return made;
}

std::string describe(const FlythroughDataset& made) {
  const FlythroughReport& r = made.flight;
  std::string verdict = "inside every ORCA range of Tables 6.4-6.6";
  if (!made.insideOrca()) {
    verdict = "outside ORCA's range in";
    for (const OrcaCheck& c : made.checks)
      if (!c.inside()) verdict += fmt::format(" {} {:.3f} (ORCA {:.3f}-{:.3f});", c.measure, c.value, c.low, c.high);
  }
  return fmt::format("along the bot's path from {:.2f} s to {:.2f} s (no cut between; the best of {} stretches), {:.0f} of its {:.0f} units at "
                     "{:.2f} units/s, smoothed over {:.0f} units, heading over {:.2f} s, pitch over {:.2f} s{}: yaw {:.3f} (variance {:.3f}), "
                     "pitch {:.3f} ({:.4f}) degrees per frame; {}",
                     r.stretchStart, r.stretchEnd, r.stretchesCompared, r.length, r.stretchLength, r.speed, r.smoothing, r.headingWindow,
                     r.pitchWindow, r.nodAmplitude > 0 ? fmt::format(" with a {:.2f}° nod", r.nodAmplitude) : "", r.yawMean, r.yawVariance,
                     r.pitchMean, r.pitchVariance, verdict);
}

nlohmann::json flythroughJson(const FlythroughDataset& made, const fs::path& dataset, const fs::path& output, const fs::path& csv) {
  const auto& f = made.flight;
  nlohmann::json doc = {{"dataset", dataset.string()},
                        {"output", output.string()},
                        {"csv", csv.string()},
                        {"stretch", {{"start", f.stretchStart}, {"end", f.stretchEnd}, {"length", f.stretchLength}}},
                        {"stretches_compared", f.stretchesCompared},
                        {"length", f.length},
                        {"speed", f.speed},
                        {"smoothing", f.smoothing},
                        {"heading_window", f.headingWindow},
                        {"pitch_window", f.pitchWindow},
                        {"nod_amplitude", f.nodAmplitude},
                        {"inside_orca", made.insideOrca()},
                        {"checks", nlohmann::json::array()}};
  for (const auto& c : made.checks)
    doc["checks"].push_back({{"measure", c.measure}, {"value", c.value}, {"low", c.low}, {"high", c.high}, {"inside", c.inside()}});
  return doc;
}

}  // namespace dynbench::camera
