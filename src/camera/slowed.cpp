#include "camera/slowed.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include "camera/merge_camera.h"
#include "core/files.h"
#include "core/math.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace dynbench::camera {

namespace fs = std::filesystem;

namespace {

// The centred moving average over time: each value the mean of those within +-h seconds, h the
// half width, shrunk symmetrically near a stretch's ends (h = min(half, time to either end)) so a
// stretch keeps its end values and a heading turning at a constant rate is left as it is.
std::vector<double> averageOverTime(const std::vector<double>& times, const std::vector<double>& values, double half) {
  std::vector<double> out(values.size());
  for (std::size_t k = 0; k < values.size(); ++k) {
    const double h = std::min({half, times[k] - times.front(), times.back() - times[k]}) + 1e-9;
    double sum = 0;
    int count = 0;
    for (std::size_t j = k; j-- > 0 && times[j] >= times[k] - h;) sum += values[j], ++count;
    for (std::size_t j = k; j < values.size() && times[j] <= times[k] + h; ++j) sum += values[j], ++count;
    out[k] = sum / count;
  }
  return out;
}

}  // namespace

Expected<SlowedTurnsReport> makeSlowedTurnsDataset(const fs::path& dataset, const fs::path& output, const fs::path& csv,
                                                   const SlowedTurnsOptions& o) {
  if (!(o.window >= 0) || !(o.rate > 0)) return fail(ErrorCode::kUsage, "slowed turns: the window must be >= 0 s and the rate > 0");
  auto loaded = loadAnimatedCamera(dataset, "slow");
  if (!loaded) return std::unexpected(loaded.error());
  const scene::Scene& scene = loaded->scene;
  const int cameraNode = loaded->node;
  const auto range = loaded->range;
  const double duration = loaded->duration();
  const scene::Node& node = scene.nodes[static_cast<std::size_t>(cameraNode)];

  // Pose times: an even grid and both ends of every cut, so each jump stays a jump between keys.
  std::vector<double> times;
  const auto samples = static_cast<std::size_t>(std::ceil(duration * o.rate)) + 1;
  for (std::size_t n = 0; n < samples; ++n) times.push_back(std::min(range.end, range.start + static_cast<double>(n) / o.rate));
  for (const scene::Node::Cut& cut : node.cuts)
    for (double t : {cut.from, cut.time})
      if (t >= range.start && t <= range.end) times.push_back(t);
  std::sort(times.begin(), times.end());
  // within 10 µs is one key (glTF key times are floats; a cut on the grid is the grid point)
  times.erase(std::unique(times.begin(), times.end(), [](double a, double b) { return std::abs(a - b) < 1e-5; }), times.end());

  const scene::Evaluator evaluator(scene);
  std::vector<glm::dvec3> positions;
  std::vector<double> yaw, pitch;
  for (double t : times) {
    const glm::dmat4 world = evaluator.worldMatrix(cameraNode, t);
    positions.emplace_back(world[3]);
    const EulerYawPitchRoll angles = eulerYawPitchRoll(decomposeRigid(world).rotation);
    const double y = angles.yaw, p = angles.pitch;
    // unwrapped: the average of 179° and -179° is 180°, not 0°
    yaw.push_back(yaw.empty() || scene::cameraCutBetween(node, times[yaw.size() - 1], t)
                      ? y
                      : yaw.back() + std::remainder(y - yaw.back(), 2.0 * kPi));
    pitch.push_back(p);
  }
  // Each cut-free stretch smoothed on its own.
  SlowedTurnsReport report;
  report.window = o.window;
  std::vector<double> smoothYaw(yaw.size()), smoothPitch(pitch.size());
  for (std::size_t begin = 0; begin < times.size();) {
    std::size_t end = begin + 1;
    while (end < times.size() && !scene::cameraCutBetween(node, times[end - 1], times[end])) ++end;
    const std::vector<double> t(times.begin() + begin, times.begin() + end);
    const auto y = averageOverTime(t, std::vector<double>(yaw.begin() + begin, yaw.begin() + end), o.window / 2);
    const auto p = averageOverTime(t, std::vector<double>(pitch.begin() + begin, pitch.begin() + end), o.window / 2);
    std::copy(y.begin(), y.end(), smoothYaw.begin() + begin);
    std::copy(p.begin(), p.end(), smoothPitch.begin() + begin);
    ++report.stretches;
    begin = end;
  }
  std::vector<CameraPoseKey> keys;
  for (std::size_t k = 0; k < times.size(); ++k)  // no roll, as the fly-through's
    keys.push_back({times[k] - range.start, positions[k], quatFromYawPitchRoll(smoothYaw[k], smoothPitch[k], 0.0)});
  if (auto ok = writeCameraRunCsv(csv, keys); !ok) return std::unexpected(ok.error());
  report.poses = times.size();
  MergeCameraOptions merge;
  merge.dataset = dataset;
  merge.run = csv;
  merge.output = output;
  merge.keepCuts = true;  // the same positions jump at the same times
  if (auto merged = mergeCamera(merge); !merged) return std::unexpected(merged.error());
  return report;
}

std::string describe(const SlowedTurnsReport& r) {
  return fmt::format("the bot's camera with its turns slowed: heading and pitch averaged over {:.2f} s in each of {} cut-free stretches, "
                     "positions and cuts the bot's ({} poses)",
                     r.window, r.stretches, r.poses);
}

}  // namespace dynbench::camera
