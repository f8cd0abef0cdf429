#include "suite/manifest.h"

#include <algorithm>
#include <set>

#include <fmt/format.h>

#include "core/checksum.h"
#include "core/files.h"
#include "core/json_fields.h"
#include "suite/validity.h"

namespace dynbench::suite {

namespace fs = std::filesystem;
using pipeline::DatasetRunSettings;

namespace {

bool validName(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.'; }) &&
         s != "." && s != "..";
}

}  // namespace

Expected<Manifest> readManifest(const fs::path& path) {
  auto doc = readJsonFile(path);
  if (!doc) return std::unexpected(doc.error());
  return parseManifest(*doc, path);
}

Expected<Manifest> parseManifest(const nlohmann::json& document, const fs::path& path) {
  Manifest m;
  m.document = document;
  const JsonFields f(m.document, path);
  m.path = path;
  auto bad = [&](const std::string& pointer, const std::string& expected) {
    return fail(ErrorCode::kInvalidData, "{}: {}: expected {}", path.string(), pointer, expected);
  };
  if (!m.document.is_object()) return bad("", "an object");
  auto version = f.integer("/dynbench_suite");
  if (!version) return std::unexpected(version.error());
  if (*version != kManifestVersion) return bad("/dynbench_suite", fmt::format("{} (the manifest version this dynbench reads), found {}", kManifestVersion, *version));
  auto name = f.string("/name");
  if (!name) return std::unexpected(name.error());
  if (!validName(*name)) return bad("/name", "letters, digits, '-', '_' or '.'");
  m.name = *name;
  if (f.has("/description")) {
    auto d = f.string("/description");
    if (!d) return std::unexpected(d.error());
    m.description = *d;
  }
  // The render window: every field optional, defaulting to DatasetRunSettings' (but for the
  // noise floor, which a suite reports for every dataset).
  m.run.floorFrames = kDefaultFloorFrames;
  if (auto ok = readDatasetRunSettings(JsonSettingsReader(m.document, path), "/render", m.run, false); !ok) return std::unexpected(ok.error());
  DatasetRunSettings& r = m.run;
  if (f.has("/methods")) {
    auto methods = f.value("/methods");
    if (!(*methods)->is_array() || (*methods)->empty()) return bad("/methods", "a non-empty array of method names");
    r.methods.clear();
    for (std::size_t i = 0; i < (*methods)->size(); ++i) {
      auto method = f.string(fmt::format("/methods/{}", i));
      if (!method) return std::unexpected(method.error());
      r.methods.push_back(*method);
    }
  }
  // Each method's input: its own unless /method_inputs says otherwise (issue 48).
  for (const std::string& method : r.methods) r.methodInputs[method] = std::string(evaluate::builtForInput(method));
  if (f.has("/method_inputs")) {
    auto inputs = f.value("/method_inputs");
    if (!(*inputs)->is_object()) return bad("/method_inputs", "an object: method name -> \"jittered\" or \"still\"");
    for (const auto& [method, value] : (*inputs)->items()) {
      const std::string at = "/method_inputs/" + method;
      if (!r.methodInputs.count(method)) return bad(at, fmt::format("one of /methods ({})", fmt::join(r.methods, ", ")));
      auto input = f.string(at);
      if (!input) return std::unexpected(input.error());
      if (*input != evaluate::kJitteredInput && *input != evaluate::kStillInput)
        return bad(at, fmt::format("\"jittered\" or \"still\", found \"{}\"", *input));
      r.methodInputs[method] = *input;
    }
  }
  if (r.methodInputs.count(kStillNone)) return bad("/methods", fmt::format("no method named \"{}\" (suite.json's name for none on the still input)", kStillNone));
  auto datasets = f.value("/datasets");
  if (!datasets) return std::unexpected(datasets.error());
  if (!(*datasets)->is_array() || (*datasets)->empty()) return bad("/datasets", "a non-empty array of datasets");
  std::set<std::string> names;
  for (std::size_t i = 0; i < (*datasets)->size(); ++i) {
    const std::string at = fmt::format("/datasets/{}", i);
    DatasetSpec d;
    auto dname = f.string(at + "/name");
    if (!dname) return std::unexpected(dname.error());
    if (!validName(*dname)) return bad(at + "/name", "letters, digits, '-', '_' or '.'");
    if (!names.insert(*dname).second) return bad(at + "/name", fmt::format("a name no other dataset has ('{}' is repeated)", *dname));
    d.name = *dname;
    if (f.has(at + "/engine")) {
      auto engine = f.string(at + "/engine");
      if (!engine) return std::unexpected(engine.error());
      d.engine = *engine;
    }
    if (d.engine != "cube2" && d.engine != "openarena")
      return bad(at + "/engine", fmt::format("\"cube2\" or \"openarena\" (the engines dynbench captures), found \"{}\"", d.engine));
    const bool openArena = d.engine == "openarena";
    for (const auto& [key, target] : {std::pair{"/preset", &d.preset}, std::pair{"/map", &d.map}}) {
      if (!f.has(at + key)) continue;
      auto v = f.string(at + key);
      if (!v) return std::unexpected(v.error());
      *target = *v;
    }
    if (!d.preset.empty()) {
      if (openArena) return bad(at + "/preset", "no preset: OpenArena has none (give map and bots)");
      capture::Cube2Options probe;
      if (auto ok = capture::applyCube2Preset(d.preset, probe); !ok) return bad(at + "/preset", ok.error().message);
    }
    if (f.has(at + "/bots")) {
      auto bots = f.integer(at + "/bots");
      if (!bots) return std::unexpected(bots.error());
      const auto range = openArena ? capture::kOpenArenaBotsRange : capture::kBotsRange;
      if (*bots < range.first || *bots > range.second) return bad(at + "/bots", fmt::format("a whole number in [{}, {}]", range.first, range.second));
      d.bots = static_cast<int>(*bots);
    }
    if (f.has(at + "/game_cpu")) {
      if (!openArena) return bad(at + "/game_cpu", "no game_cpu: Cube 2 runs on the host (its build has no reciprocal estimates)");
      auto cpu = f.string(at + "/game_cpu");
      if (!cpu) return std::unexpected(cpu.error());
      auto parsed = capture::parseGameCpu(*cpu);
      if (!parsed) return bad(at + "/game_cpu", fmt::format("{}, found \"{}\"", capture::gameCpuChoices(), *cpu));
      d.gameCpu = *parsed;
    }
    auto seed = f.count(at + "/seed");
    if (!seed) return std::unexpected(seed.error());
    d.seed = static_cast<unsigned>(*seed);
    auto seconds = f.number(at + "/seconds");
    if (!seconds) return std::unexpected(seconds.error());
    if (!(*seconds > 0 && *seconds <= 3600)) return bad(at + "/seconds", "a number of game seconds in (0, 3600]");
    d.seconds = *seconds;
    auto camera = f.string(at + "/camera");
    if (!camera) return std::unexpected(camera.error());
    if (*camera != "bot" && *camera != "slowed" && *camera != "flythrough" && *camera != "vr")
      return bad(at + "/camera", fmt::format("\"bot\", \"slowed\", \"flythrough\" or \"vr\", found \"{}\"", *camera));
    d.camera = *camera;
    if (d.camera == "vr") {
      if (!f.has(at + "/trace")) return bad(at + "/trace", "the head trace of a \"vr\" camera (a CSV, relative to the manifest's folder)");
      auto trace = f.string(at + "/trace");
      if (!trace) return std::unexpected(trace.error());
      if (trace->empty()) return bad(at + "/trace", "a file name, found \"\"");
      d.trace = *trace;
      d.tracePath = fs::absolute(path.parent_path() / d.trace).lexically_normal();  // Slurm jobs run elsewhere
    } else if (f.has(at + "/trace")) {
      return bad(at + "/trace", "no trace: only a \"vr\" camera has one");
    }
    if (f.has(at + "/sha256")) {
      auto pins = f.value(at + "/sha256");
      if (!(*pins)->is_object()) return bad(at + "/sha256", "an object with \"capture\" and/or \"dataset\" SHA-256s");
      for (const auto& [key, value] : (*pins)->items())
        if (key != "capture" && key != "dataset") return bad(at + "/sha256/" + key, "no other key than \"capture\" and \"dataset\"");
      for (const auto& [key, target] : {std::pair{"capture", &d.captureSha256}, std::pair{"dataset", &d.datasetSha256}}) {
        const std::string pointer = at + "/sha256/" + key;
        if (!f.has(pointer)) continue;
        auto v = f.string(pointer);
        if (!v) return std::unexpected(v.error());
        if (v->size() != 64 || v->find_first_not_of("0123456789abcdef") != std::string::npos)
          return bad(pointer, fmt::format("a SHA-256 as 64 lower-case hex digits, found \"{}\"", *v));
        *target = *v;
      }
    }
    m.datasets.push_back(d);
  }
  return m;
}

std::string DatasetSpec::cameraLabel() const { return camera == "vr" ? "vr-" + fs::path(trace).stem().string() : camera; }

Expected<std::string> captureDigest(const fs::path& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(folder, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->path().filename().string().starts_with(".")) {
      if (it->is_directory()) it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file()) files.push_back(fs::relative(it->path(), folder).generic_string());
  }
  if (ec) return fail(ErrorCode::kIo, "{}: cannot list the capture: {}", folder.string(), ec.message());
  if (files.empty()) return fail(ErrorCode::kIo, "{}: no capture there", folder.string());
  return sha256Listing(folder, std::move(files));
}

}  // namespace dynbench::suite
