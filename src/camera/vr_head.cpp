#include "camera/vr_head.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "core/checksum.h"
#include "core/math.h"
#include "render/raytracing_scene.h"
#include "scene/load.h"

namespace dynbench::camera {

namespace fs = std::filesystem;

Expected<std::vector<CameraPoseKey>> readHeadTrace(const fs::path& csv) {
  return readPoseCsv(csv, PoseCsvRules{kHeadTraceUnitTolerance, 2});
}

CameraPoseKey headPoseAt(const std::vector<CameraPoseKey>& trace, double t) {
  if (t <= trace.front().time) return trace.front();
  if (t >= trace.back().time) return trace.back();
  const auto after = std::upper_bound(trace.begin(), trace.end(), t, [](double time, const CameraPoseKey& k) { return time < k.time; });
  const CameraPoseKey& a = *(after - 1);
  const CameraPoseKey& b = *after;
  const double u = (t - a.time) / (b.time - a.time);
  // The shorter arc: q and -q are one rotation.
  const glm::dquat to = glm::dot(a.rotation, b.rotation) < 0 ? -b.rotation : b.rotation;
  return {t, glm::mix(a.position, b.position, u), glm::normalize(glm::slerp(a.rotation, to, u))};
}

namespace {

// The least cosine between a head's offset and the normal of the wall it meets that the clamp
// takes at face value: at a more grazing angle the offset stops clearance / kGrazing short.
constexpr double kGrazing = 0.05;

// The point on the polyline (times, points) at time t, linearly between keys.
glm::dvec3 pointAt(const std::vector<CameraPoseKey>& keys, const std::vector<glm::dvec3>& points, double t) {
  if (t <= keys.front().time) return points.front();
  if (t >= keys.back().time) return points.back();
  const auto k = static_cast<std::size_t>(
      std::upper_bound(keys.begin(), keys.end(), t, [](double time, const CameraPoseKey& key) { return time < key.time; }) - keys.begin() - 1);
  return glm::mix(points[k], points[k + 1], (t - keys[k].time) / (keys[k + 1].time - keys[k].time));
}

}  // namespace

Expected<VrCameraReport> writeVrCameraCsv(const fs::path& dataset, const fs::path& csv, const VrCameraOptions& o) {
  if (!(o.metresPerUnit > 0) || !(o.clearance >= 0) || !(o.traceStart >= 0))
    return fail(ErrorCode::kUsage, "vr camera: metres per unit must be positive, the clearance and the trace start at least 0");
  auto trace = readHeadTrace(o.trace);
  if (!trace) return std::unexpected(trace.error());
  auto digest = sha256File(o.trace);
  if (!digest) return std::unexpected(digest.error());
  // One load and one build of the static geometry for the body's path and the head's clamp.
  auto loaded = loadAnimatedCamera(dataset, "fly along");
  if (!loaded) return std::unexpected(loaded.error());
  auto walls = render::StaticGeometry::create(loaded->scene);
  if (!walls) return std::unexpected(walls.error());
  auto body = flyThroughPoses(*loaded, *walls, dataset, o.body);
  if (!body) return std::unexpected(body.error());
  const std::vector<CameraPoseKey>& keys = body->keys;
  const double duration = keys.back().time - keys.front().time;
  const double traceFrom = trace->front().time + o.traceStart;
  if (traceFrom + duration > trace->back().time + 1e-9)
    return fail(ErrorCode::kInvalidData, "{}: the trace covers {:.3f} s; the dataset needs {:.3f} s from {:.3f} s into it", o.trace.string(),
                trace->back().time - trace->front().time, duration, o.traceStart);


  VrCameraReport report;
  report.body = body->report;
  report.traceSha256 = *digest;
  report.traceStart = o.traceStart;
  report.traceSeconds = duration;
  report.poses = keys.size();
  const CameraPoseKey start = headPoseAt(*trace, traceFrom);
  const double traceHeading = eulerYawPitchRoll(start.rotation).yaw;
  const double unitsPerMetre = 1.0 / o.metresPerUnit, clearance = o.clearance * unitsPerMetre;
  report.headingTurn = wrapDegrees(degrees(eulerYawPitchRoll(keys.front().rotation).yaw - traceHeading));

  // Whether a static surface is nearer to p than `distance`: probes along the 26 directions of a
  // cube's faces, edges and corners (a ray-traced stand-in for a closest-point query; 0.99: the
  // offset's clamp below puts a head at the clearance exactly, which is clear).
  auto nearerThan = [&](const glm::dvec3& p, double distance) {
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          if (x == 0 && y == 0 && z == 0) continue;
          if (walls->firstObstacle(p, glm::normalize(glm::dvec3(x, y, z)), distance).distance < 0.99 * distance) return true;
        }
    return false;
  };

  // The play space turns with the path: its yaw is the body's heading less the trace's starting one.
  std::vector<glm::dvec3> bodyPoints, offsets;
  std::vector<glm::dquat> rotations;
  for (const CameraPoseKey& key : keys) {
    const CameraPoseKey head = headPoseAt(*trace, traceFrom + (key.time - keys.front().time));
    const glm::dquat space = glm::angleAxis(eulerYawPitchRoll(key.rotation).yaw - traceHeading, glm::dvec3(0, 1, 0));
    rotations.push_back(glm::normalize(space * head.rotation));
    glm::dvec3 offset = space * (head.position - start.position) * unitsPerMetre;
    // Cut short where it would come within `clearance` of the first static surface between the
    // body and the head (measured along that surface's normal: an offset meeting a wall at a
    // grazing angle stops further from it along the offset).
    const double length = glm::length(offset);
    if (length > 0) {
      const glm::dvec3 direction = offset / length;
      const auto obstacle = walls->firstObstacle(key.position, direction, length + clearance / kGrazing);
      const double facing = std::abs(glm::dot(direction, obstacle.normal));
      const double allowed = obstacle.distance - clearance / std::max(facing, kGrazing);
      bool cut = false;
      if (allowed < length) {
        // On a grid of 1/1024 unit: Embree's distances may differ in their last bits between its
        // ISAs, and the dataset must not (the same bytes on every machine).
        offset *= std::floor(std::max(0.0, allowed) * 1024.0) / 1024.0 / length;
        cut = true;
      }
      // A surface beside the offset's line (a wall's end, a corner) can still be nearer than the
      // clearance: halved until no probe finds one (then dropped: the body's own place is the bot's).
      for (int halving = 0; halving < 8 && glm::length(offset) > 0 && nearerThan(key.position + offset, clearance); ++halving)
        offset = halving == 7 ? glm::dvec3(0.0) : 0.5 * offset, cut = true;
      report.clamped += cut ? 1 : 0;
    }
    bodyPoints.push_back(key.position);
    offsets.push_back(offset);
  }

  // Chords between poses, and between the frames the renderer will interpolate, kept clear: the
  // offsets around a crossing chord are halved (six times at most, then dropped: the body's own
  // path is clear of static geometry, so this ends).
  std::vector<double> scale(keys.size(), 1.0);
  std::vector<bool> everShrunk(keys.size(), false);
  std::vector<glm::dvec3> heads(keys.size());
  for (int round = 0;; ++round) {
    for (std::size_t n = 0; n < keys.size(); ++n) heads[n] = bodyPoints[n] + scale[n] * offsets[n];
    std::vector<double> frameTimes;
    std::vector<glm::dvec3> framePoints;
    for (double t = keys.front().time; t <= keys.back().time + 1e-9; t += 1.0 / o.body.frameRate) {
      frameTimes.push_back(t);
      framePoints.push_back(pointAt(keys, heads, t));
    }
    std::vector<bool> shrink(keys.size(), false);
    for (std::size_t k : walls->segmentsThrough(heads)) shrink[k] = shrink[k + 1] = true;
    for (std::size_t f : walls->segmentsThrough(framePoints))
      for (std::size_t n = 0; n < keys.size(); ++n)
        if (keys[n].time >= frameTimes[f] - 1.0 / o.body.rate && keys[n].time <= frameTimes[f + 1] + 1.0 / o.body.rate) shrink[n] = true;
    if (std::none_of(shrink.begin(), shrink.end(), [](bool s) { return s; })) break;
    if (round > 6)
      return fail(ErrorCode::kInvalidData, "{}: the fly-through's own path crosses static geometry; no head can follow it", dataset.string());
    for (std::size_t n = 0; n < keys.size(); ++n)
      if (shrink[n]) scale[n] = round == 6 ? 0.0 : 0.5 * scale[n], everShrunk[n] = true;
  }
  report.shrunk = static_cast<std::size_t>(std::count(everShrunk.begin(), everShrunk.end(), true));

  std::vector<CameraPoseKey> out;
  double sum = 0;
  for (std::size_t n = 0; n < keys.size(); ++n) {
    const double metres = glm::length(heads[n] - bodyPoints[n]) * o.metresPerUnit;
    sum += metres;
    report.maxOffset = std::max(report.maxOffset, metres);
    out.push_back({keys[n].time, heads[n], rotations[n]});
  }
  report.meanOffset = sum / static_cast<double>(keys.size());
  if (auto ok = writeCameraRunCsv(csv, out); !ok) return std::unexpected(ok.error());
  return report;
}

Expected<VrCameraDataset> makeVrCameraDataset(const fs::path& dataset, const fs::path& output, const fs::path& csv, const VrCameraOptions& o) {
  VrCameraDataset made;
  auto report = writeVrCameraCsv(dataset, csv, o);
  if (!report) return std::unexpected(report.error());
  made.report = *report;
  auto motion = mergeAndMeasure(dataset, csv, output, o.body.frameRate);
  if (!motion) return std::unexpected(motion.error());
  made.motion = *motion;
  return made;
}

std::string describe(const VrCameraReport& r) {
  return fmt::format("a head trace ({:.2f} s from {:.2f} s, sha256 {}) on the fly-through's path ({:.0f} units at {:.2f} units/s), its heading "
                     "turned {:.1f}° onto the path's; head {:.2f} m from the body on average, {:.2f} m at most; {} of {} poses cut short by a "
                     "wall, {} shrunk to keep chords clear",
                     r.traceSeconds, r.traceStart, r.traceSha256.substr(0, 12), r.body.length, r.body.speed, r.headingTurn, r.meanOffset,
                     r.maxOffset, r.clamped, r.poses, r.shrunk);
}

nlohmann::json vrCameraJson(const VrCameraDataset& made, const fs::path& dataset, const fs::path& output, const fs::path& csv,
                            const VrCameraOptions& o) {
  const VrCameraReport& r = made.report;
  auto summary = [](const metrics::Summary& s) { return nlohmann::json{{"mean", s.mean}, {"variance", s.variance}, {"max", s.max}}; };
  const metrics::CameraMotionSummary& m = made.motion;
  return {{"dataset", dataset.string()},
          {"output", output.string()},
          {"csv", csv.string()},
          {"trace", {{"file", o.trace.string()}, {"sha256", r.traceSha256}, {"start", r.traceStart}, {"seconds", r.traceSeconds}}},
          {"metres_per_unit", o.metresPerUnit},
          {"clearance", o.clearance},
          {"heading_turn", r.headingTurn},
          {"body", {{"stretch", {{"start", r.body.stretchStart}, {"end", r.body.stretchEnd}}}, {"length", r.body.length}, {"speed", r.body.speed}}},
          {"poses", r.poses},
          {"clamped", r.clamped},
          {"shrunk", r.shrunk},
          {"offset", {{"mean", r.meanOffset}, {"max", r.maxOffset}}},
          {"motion",
           {{"fps", o.body.frameRate},
            {"position", summary(m.position)},
            {"rotation", summary(m.rotation)},
            {"pitch", summary(m.pitch)},
            {"yaw", summary(m.yaw)},
            {"roll", summary(m.roll)}}}};
}

}  // namespace dynbench::camera
