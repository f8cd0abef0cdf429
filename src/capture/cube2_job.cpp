#include "capture/cube2_job.h"

#include <array>
#include <climits>

#include "core/files.h"
#include "core/json_fields.h"

namespace dynbench::capture {
namespace {

namespace fs = std::filesystem;

constexpr std::array kKeys = {"dynbench_cube2_capture", "output", "map", "mode", "bots", "skill", "seconds", "fps", "seed", "game_frames",
                              "follow", "warmup", "width", "height", "window", "client", "data"};

}  // namespace

nlohmann::json cube2JobJson(const Cube2Options& o) {
  nlohmann::json j = {{"dynbench_cube2_capture", kCube2JobVersion},
                      {"map", o.map},
                      {"mode", o.mode},
                      {"bots", o.bots},
                      {"skill", o.skill},
                      {"seconds", o.seconds},
                      {"fps", o.fps},
                      {"seed", o.seed},
                      {"game_frames", o.gameFrames},
                      {"follow", o.follow},
                      {"warmup", o.warmup},
                      {"width", o.width},
                      {"height", o.height},
                      {"window", o.window},
                      {"data", o.data.string()}};
  if (!o.output.empty()) j["output"] = o.output.string();
  if (!o.client.empty()) j["client"] = o.client.string();
  return j;
}

Expected<Cube2Options> parseCube2Job(const nlohmann::json& document, const fs::path& source) {
  const JsonSettingsReader r(document, source);
  if (auto ok = r.jobDocument("the Cube 2 capture job", kKeys, "dynbench_cube2_capture", kCube2JobVersion); !ok) return std::unexpected(ok.error());
  Cube2Options o;
  std::string output = o.output.string(), client = o.client.string(), data = o.data.string();
  for (auto ok : {r.string("/output", output), r.string("/map", o.map), r.string("/mode", o.mode), r.integer("/bots", o.bots, INT_MIN, INT_MAX),
                  r.integer("/skill", o.skill, INT_MIN, INT_MAX), r.number("/seconds", o.seconds, -1e300, 1e300),
                  r.number("/fps", o.fps, -1e300, 1e300), r.integer("/seed", o.seed, 0, UINT_MAX), r.string("/follow", o.follow),
                  r.number("/warmup", o.warmup, -1e300, 1e300), r.integer("/width", o.width, INT_MIN, INT_MAX),
                  r.integer("/height", o.height, INT_MIN, INT_MAX), r.boolean("/window", o.window), r.string("/client", client),
                  r.string("/data", data)})
    if (!ok) return std::unexpected(ok.error());
  o.output = output;
  o.client = client;
  o.data = data;
  if (r.has("/game_frames")) {
    const auto& frames = document.at("game_frames");
    if (!frames.is_array()) return r.bad("/game_frames", fmt::format("an array of frame numbers, found {}", frames.dump()));
    o.gameFrames.clear();
    for (std::size_t i = 0; i < frames.size(); ++i) {
      long frame = 0;
      if (auto ok = r.integer(fmt::format("/game_frames/{}", i), frame, 0, LONG_MAX); !ok) return std::unexpected(ok.error());
      o.gameFrames.push_back(frame);
    }
  }
  return o;
}

Expected<Cube2Options> readCube2Job(const fs::path& path) { return readJsonDocument(path, parseCube2Job); }

Expected<void> writeCube2Job(const Cube2Options& options, const fs::path& path) {
  return writeFileAtomic(path, cube2JobJson(options).dump(2) + "\n");
}

}  // namespace dynbench::capture
