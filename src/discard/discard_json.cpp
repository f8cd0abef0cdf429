// discard.json: what `discard --json` writes and `report` and `suite verify` read back.
#include "discard/discard.h"

#include "core/json_fields.h"
#include "core/math.h"
#include "frames/radiance_change.h"
#include "frames/preview.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>


namespace dynbench::discard {

namespace {

nlohmann::json percentagesJson(const FramePercentages& p) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& column : kTable67Columns) j[column.key] = p.*column.member;
  if (p.directInterval && p.indirectInterval)
    for (const auto& column : kTable67Columns) {
      if (!column.interval) continue;
      const Interval& interval = *(p.*column.interval);
      j["interval"][column.key] = {interval.low, interval.high};
      j["noisy"][column.key] = p.*column.noisy;
    }
  return j;
}

}  // namespace

nlohmann::json discardJson(const DiscardRun& run, const std::string& framesDir) {
  const auto& t = run.thresholds;
  nlohmann::json j;
  j["frames_dir"] = framesDir;
  j["width"] = run.width;
  j["height"] = run.height;
  j["scene_size"] = run.sceneSize;
  j["thresholds"] = {{"geometry_test", geometryTestName(t.geometryTest)},
                     {"position", t.position},       {"relative_position", t.relativePosition}, {"normal", t.normal},
                     {"direct", t.direct},           {"indirect", t.indirect},                 {"absolute_radiance", t.absoluteRadiance},
                     {"radiance_test", radianceTestName(t.radianceTest)}, {"noise_sigmas", t.noiseSigmas}};
  j["mean"] = percentagesJson(run.mean);
  j["cut_pairs"] = run.cutPairs;
  j["cuts_in_mean"] = run.cutsInMean;
  j["frames"] = nlohmann::json::array();
  for (const auto& f : run.frames) {
    auto row = percentagesJson(f);
    row["frame"] = f.frame;
    row["time"] = f.time;
    if (f.cut) row["cut"] = true;
    j["frames"].push_back(row);
  }
  j["warnings"] = run.warnings;
  return j;
}

namespace {

Expected<FramePercentages> readPercentages(const JsonFields& f, const std::string& base) {
  FramePercentages p;
  for (const auto& column : kTable67Columns) {
    auto v = f.number(base + "/" + column.key);
    if (!v) return std::unexpected(v.error());
    p.*column.member = *v;
  }
  // The radiance columns' intervals (files of the other radiance tests and of earlier versions have
  // none) and uncertain shares (files of earlier versions have none): both optional.
  for (const auto& column : kTable67Columns) {
    if (!column.interval) continue;
    if (f.has(base + "/interval")) {
      const std::string pointer = base + "/interval/" + column.key;
      auto low = f.number(pointer + "/0");
      if (!low) return std::unexpected(low.error());
      auto high = f.number(pointer + "/1");
      if (!high) return std::unexpected(high.error());
      p.*column.interval = Interval{*low, *high};
    }
    const std::string pointer = base + "/noisy/" + column.key;
    if (!f.has(pointer)) continue;
    auto v = f.number(pointer);
    if (!v) return std::unexpected(v.error());
    p.*column.noisy = *v;
  }
  return p;
}

}  // namespace

Expected<DiscardRun> readDiscardJson(const std::filesystem::path& path) {
  auto j = readJsonFile(path);
  if (!j) return std::unexpected(j.error());
  const JsonFields f(*j, path);
  DiscardRun run;
  for (auto [key, target] : {std::pair{"/width", &run.width}, {"/height", &run.height}}) {
    auto v = f.integer(key);
    if (!v) return std::unexpected(v.error());
    *target = static_cast<int>(*v);
  }
  // The radiance test: optional (files of earlier versions have none, and were the expected test's).
  run.thresholds.radianceTest = Thresholds::RadianceTest::kExpected;
  if (f.has("/thresholds/radiance_test")) {
    auto name = f.string("/thresholds/radiance_test");
    if (!name) return std::unexpected(name.error());
    const auto& tests = radianceTestsByName();
    const auto known = std::find_if(tests.begin(), tests.end(), [&](const auto& t) { return t.first == *name; });
    if (known == tests.end()) {
      std::vector<std::string> names;
      for (const auto& t : tests) names.push_back(t.first);
      return fail(ErrorCode::kInvalidData, "{}: /thresholds/radiance_test: expected one of {} (got '{}')", path.string(), fmt::join(names, ", "),
                  *name);
    }
    run.thresholds.radianceTest = known->second;
  }
  auto mean = readPercentages(f, "/mean");
  if (!mean) return std::unexpected(mean.error());
  run.mean = *mean;
  run.mean.frame = -1;
  auto frames = f.value("/frames");
  if (!frames) return std::unexpected(frames.error());
  if (!(*frames)->is_array()) return fail(ErrorCode::kInvalidData, "{}: /frames: expected an array", path.string());
  for (std::size_t k = 0; k < (*frames)->size(); ++k) {
    const std::string base = fmt::format("/frames/{}", k);
    auto p = readPercentages(f, base);
    if (!p) return std::unexpected(p.error());
    auto frame = f.integer(base + "/frame");
    if (!frame) return std::unexpected(frame.error());
    auto time = f.number(base + "/time");
    if (!time) return std::unexpected(time.error());
    p->frame = static_cast<long>(*frame);
    if (f.has(base + "/cut")) {
      auto cut = f.boolean(base + "/cut");
      if (!cut) return std::unexpected(cut.error());
      p->cut = *cut;
      run.cutPairs += p->cut ? 1 : 0;
    }
    p->time = *time;
    run.frames.push_back(*p);
  }
  return run;
}

}  // namespace dynbench::discard
