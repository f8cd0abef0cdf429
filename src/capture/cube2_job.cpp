#include "capture/cube2_job.h"

#include <array>

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
  // The values' ranges are the capture's to check (captureCube2), as for the command line's.
  for (auto ok : {r.string("/output", output), r.string("/map", o.map), r.string("/mode", o.mode), r.integer("/bots", o.bots),
                  r.integer("/skill", o.skill), r.number("/seconds", o.seconds), r.number("/fps", o.fps), r.integer("/seed", o.seed),
                  r.string("/follow", o.follow), r.number("/warmup", o.warmup), r.integer("/width", o.width), r.integer("/height", o.height),
                  r.boolean("/window", o.window), r.string("/client", client), r.string("/data", data)})
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
      if (auto ok = r.integer(fmt::format("/game_frames/{}", i), frame, 0); !ok) return std::unexpected(ok.error());
      o.gameFrames.push_back(frame);
    }
  }
  return o;
}

Expected<Cube2Options> readCube2Job(const fs::path& path) { return readJsonDocument(path, parseCube2Job); }

Expected<void> writeCube2Job(const Cube2Options& options, const fs::path& path) {
  return writeFileAtomic(path, jsonFileText(cube2JobJson(options)));
}

}  // namespace dynbench::capture
