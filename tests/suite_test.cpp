// `dynbench suite` and `suite verify` (pipeline/suite.h): the manifest's errors, and the smoke suite
// run for real (Cube 2, the renderer, discard, evaluate), resumed, verified, and caught when a frame
// is edited by hand.
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "core/files.h"
#include "frames/frame_io.h"
#include "metrics/rank_correlation.h"
#include "suite/record.h"
#include "suite/score.h"
#include "suite/suite.h"
#include "suite/verify.h"
#include "external_tools.h"
#include "gltf_builder.h"
#include "other_machine.h"
#include "run_cli.h"
#include "shared_run.h"
#include "scene/dataset_digest.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

const fs::path kSmoke = fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "smoke.json";

TEST(Suite, V2IsPairedAcrossBothEnginesPinnedAndAtItsSize) {
  // Issue 48's design as the manifest states it: both engines (Cube 2's three presets, two
  // OpenArena maps), every match (capture) seen by the bot's, the slowed and the fly-through camera,
  // several seeds, 320x180 or more, windows of at least 48 frames, a noise floor, every dataset
  // pinned (a capture's pin the same for its three cameras).
  auto m = suite::readManifest(fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "v2.json");
  ASSERT_TRUE(m) << m.error().message;
  EXPECT_GE(m->run.width, 320);
  EXPECT_GE(m->run.height, 180);
  EXPECT_GE(m->run.renderFrames, 48);
  EXPECT_GT(m->run.floorFrames, 0);
  std::map<std::string, std::set<std::string>> camerasByMatch;
  std::map<std::string, std::set<std::string>> capturePinsByMatch;
  std::set<std::string> presets, openArenaMaps;
  std::set<unsigned> seeds;
  for (const auto& d : m->datasets) {
    const std::string match = d.engine + "/" + (d.preset.empty() ? d.map : d.preset) + "/" + std::to_string(d.seed);
    camerasByMatch[match].insert(d.camera);
    capturePinsByMatch[match].insert(d.captureSha256);
    EXPECT_EQ(d.captureSha256.size(), 64u) << d.name;
    EXPECT_EQ(d.datasetSha256.size(), 64u) << d.name;
    if (d.engine == "cube2") presets.insert(d.preset);
    else openArenaMaps.insert(d.map);
    seeds.insert(d.seed);
  }
  EXPECT_EQ(presets, (std::set<std::string>{"calm", "fps", "hard"}));
  EXPECT_GE(openArenaMaps.size(), 2u);
  EXPECT_GE(seeds.size(), 2u);
  for (const auto& [match, cameras] : camerasByMatch) {
    EXPECT_EQ(cameras, (std::set<std::string>{"bot", "slowed", "flythrough"})) << match;
    EXPECT_EQ(capturePinsByMatch[match].size(), 1u) << match;
  }
}

TEST(Suite, ManifestErrorsNameTheFileAndPointer) {
  const fs::path dir = test::freshDir("suite_manifest");
  // The repository's manifests read.
  for (const char* name : {"smoke.json", "v1.json", "v2.json", "engines.json", "slurm-1080p.json"}) {
    auto m = suite::readManifest(fs::path(DYNBENCH_SOURCE_DIR) / "suites" / name);
    ASSERT_TRUE(m) << m.error().message;
    EXPECT_GE(m->datasets.size(), 1u) << name;
  }
  const auto good = nlohmann::json::parse(test::slurp(kSmoke));
  struct Case {
    std::string pointer;
    nlohmann::json value;  // null: remove the member
    std::string expected;  // in the message
  };
  const std::vector<Case> cases{
      {"/dynbench_suite", 2, "/dynbench_suite: expected 1"},
      {"/datasets", nlohmann::json::array(), "/datasets: expected a non-empty array"},
      {"/datasets/0/camera", "drone", "/datasets/0/camera: expected \"bot\", \"slowed\", \"flythrough\" or \"vr\""},
      {"/datasets/1/name", "fps-1-bot", "/datasets/1/name: expected a name no other dataset has"},
      {"/datasets/0/preset", "frantic", "/datasets/0/preset"},
      {"/datasets/0/engine", "quake", "/datasets/0/engine: expected \"cube2\" or \"openarena\""},
      {"/datasets/0/engine", "openarena", "/datasets/0/preset: expected no preset"},  // dataset 0 has preset fps
      {"/datasets/0/game_cpu", "host", "/datasets/0/game_cpu: expected no game_cpu: Cube 2 runs on the host"},
      {"/datasets/2/seconds", -3, "/datasets/2/seconds"},
      {"/datasets/0/seed", nullptr, "/datasets/0/seed: missing"},
      {"/render/width", 3, "/render/width: expected a whole number in [8, 7680]"},
      {"/render/max_spp", 0, "/render/max_spp"},
      {"/methods/1", 7, "/methods/1: expected a string"},
      {"/name", "../up", "/name"},
      {"/datasets/0/sha256", "05aa", "/datasets/0/sha256: expected an object"},
      {"/datasets/0/sha256/capture", "05AA494F", "/datasets/0/sha256/capture: expected a SHA-256 as 64 lower-case hex digits"},
      {"/datasets/0/sha256/bin", "00", "/datasets/0/sha256/bin: expected no other key"},
      {"/method_inputs", "still", "/method_inputs: expected an object"},
      {"/method_inputs/taa", "wobbly", "/method_inputs/taa: expected \"jittered\" or \"still\", found \"wobbly\""},
      {"/method_inputs/dlss", "still", "/method_inputs/dlss: expected one of /methods (none, accumulate, taa, svgf)"},
      {"/render/floor_frames", -1, "/render/floor_frames: expected a whole number in [0, 100000]"},
  };
  // Each method's input: its own unless the manifest says otherwise.
  {
    nlohmann::json doc = good;
    doc["method_inputs"] = {{"svgf", "jittered"}};
    ASSERT_TRUE(writeFileAtomic(dir / "inputs.json", doc.dump()));
    auto m = suite::readManifest(dir / "inputs.json");
    ASSERT_TRUE(m) << m.error().message;
    EXPECT_EQ(m->run.methodInputs, (std::map<std::string, std::string>{{"none", "jittered"}, {"accumulate", "still"}, {"taa", "jittered"}, {"svgf", "jittered"}}));
    EXPECT_EQ(m->run.floorFrames, suite::kDefaultFloorFrames);
  }
  for (const Case& c : cases) {
    nlohmann::json doc = good;
    const nlohmann::json::json_pointer p(c.pointer);
    if (c.value.is_null()) doc[p.parent_pointer()].erase(p.back());
    else doc[p] = c.value;
    const fs::path file = dir / "bad.json";
    ASSERT_TRUE(writeFileAtomic(file, doc.dump()));
    auto m = suite::readManifest(file);
    ASSERT_FALSE(m) << c.pointer;
    EXPECT_EQ(m.error().code, ErrorCode::kInvalidData) << c.pointer;
    EXPECT_NE(m.error().message.find("bad.json"), std::string::npos) << m.error().message;
    EXPECT_NE(m.error().message.find(c.expected), std::string::npos) << m.error().message;
    // Through the command: status 5, and nothing written.
    const auto r = dynbench(fmt::format("suite {} -o {}", file.string(), (dir / "out").string()), dir);
    EXPECT_EQ(r.status, 5) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out" / "suite.json"));
  }
  ASSERT_TRUE(writeFileAtomic(dir / "syntax.json", "{\"dynbench_suite\": 1,"));
  EXPECT_EQ(dynbench(fmt::format("suite {} -o {}", (dir / "syntax.json").string(), (dir / "out").string()), dir).status, 4);
  EXPECT_EQ(dynbench(fmt::format("suite {}", kSmoke.string()), dir).status, 2);  // no -o
  EXPECT_EQ(dynbench(fmt::format("suite verify {}", (dir / "nowhere").string()), dir).status, 3);
}

TEST(Suite, ValidityRanksEachMeasureAgainstEachMethodsError) {
  // Three datasets whose direct discard orders taa's cost of history exactly, and frustum the
  // other way round.
  std::vector<suite::DatasetResult> datasets;
  for (int k = 0; k < 3; ++k) {
    suite::DatasetResult d;
    d.name = fmt::format("d{}", k);
    d.measures = {{"direct_radiance", 10.0 * k}, {"frustum", 5.0 - k}};
    d.errors["none"] = {{"flip", 0.2}, {"warped_error_change", 0.1}, {"flip_over_none", 0.0}, {"flip_ratio_to_none", 1.0}};
    d.errors["taa"] = {{"flip", 0.1 + 0.01 * k}, {"warped_error_change", 0.05}, {"flip_over_none", -0.1 + 0.01 * k}, {"flip_ratio_to_none", 0.5 + 0.05 * k}};
    datasets.push_back(d);
  }
  const auto cells = suite::validity(datasets);
  auto cell = [&](const std::string& measure, const std::string& method, const std::string& error) {
    for (const auto& c : cells)
      if (c.measure == measure && c.method == method && c.error == error) return c;
    ADD_FAILURE() << measure << " " << method << " " << error;
    return suite::ValidityCell{};
  };
  EXPECT_DOUBLE_EQ(*cell("direct_radiance", "taa", "flip_over_none").correlation.rho, 1.0);
  EXPECT_DOUBLE_EQ(*cell("frustum", "taa", "flip_over_none").correlation.rho, -1.0);
  EXPECT_EQ(cell("direct_radiance", "taa", "flip_over_none").datasets, 3);
  EXPECT_FALSE(cell("direct_radiance", "none", "flip").correlation.rho);  // none's error is constant: no ranking
  EXPECT_DOUBLE_EQ(*cell("frustum", "taa", "flip_ratio_to_none").correlation.rho, -1.0);
  EXPECT_EQ(suite::rankingError("taa"), "flip_ratio_to_none");
  EXPECT_EQ(suite::rankingError("none"), "flip");
}

// Within matches: each match's bot dataset against its fly-through, by hand.
TEST(Suite, WithinMatchDifferencesCountSignsAndRankTheDifferences) {
  std::vector<suite::DatasetResult> datasets;
  // Three matches with both cameras; a fourth with the bot's camera alone (left out of the pairs).
  const double frustumDifference[] = {1, 2, 3}, errorDifference[] = {0.1, -0.2, 0.3};
  for (int m = 0; m < 3; ++m)
    for (const char* camera : {"bot", "flythrough"}) {
      suite::DatasetResult d;
      const bool bot = std::string(camera) == "bot";
      d.name = fmt::format("m{}-{}", m, camera), d.match = fmt::format("m{}", m), d.camera = camera;
      for (const auto& key : suite::measureKeys()) d.measures[key] = 1.0;
      d.measures["frustum"] = 5.0 + (bot ? frustumDifference[m] : 0.0);
      d.errors["none"]["flip"] = 0.2;
      d.errors["taa"]["flip_ratio_to_none"] = 0.7 + (bot ? errorDifference[m] : 0.0);
      datasets.push_back(d);
    }
  suite::DatasetResult alone = datasets.front();
  alone.match = "m3", alone.measures["frustum"] = 100.0;
  datasets.push_back(alone);
  const auto cells = suite::withinMatches(datasets);
  auto cell = [&](const std::string& measure, const std::string& method) {
    for (const auto& c : cells)
      if (c.measure == measure && c.method == method) return c;
    ADD_FAILURE() << measure << " " << method;
    return suite::WithinMatchCell{};
  };
  const auto frustumTaa = cell("frustum", "taa");
  EXPECT_EQ(frustumTaa.cameraA, "bot");
  EXPECT_EQ(frustumTaa.cameraB, "flythrough");
  EXPECT_EQ(frustumTaa.error, "flip_ratio_to_none");
  EXPECT_EQ(frustumTaa.matches, 3);
  EXPECT_EQ(frustumTaa.measureHigher, 3);
  EXPECT_EQ(frustumTaa.errorHigher, 2);
  EXPECT_NEAR(frustumTaa.errorSignTestP, 0.5, 1e-12);  // 2 or 3 of 3: (3 + 1) / 8
  // Differences (1, 2, 3) against (0.1, -0.2, 0.3): ranks (1, 2, 3) and (2, 1, 3), rho = 1 - 6 * 2 / 24.
  ASSERT_TRUE(frustumTaa.correlation.rho);
  EXPECT_NEAR(*frustumTaa.correlation.rho, 0.5, 1e-12);
  // A measure equal on both cameras everywhere: never higher, rho undefined.
  EXPECT_EQ(cell("camera_yaw", "taa").measureHigher, 0);
  EXPECT_FALSE(cell("camera_yaw", "taa").correlation.rho);
  EXPECT_EQ(cell("frustum", "none").error, "flip");
}

TEST(Suite, MethodsToScoreAreNamedAndTheirRatioUsesTheRecordedNone) {
  auto external = suite::parseMethodToScore("mine=external:out/{dataset}/mine");
  ASSERT_TRUE(external) << external.error().message;
  EXPECT_EQ(external->name, "mine");
  EXPECT_EQ(external->spec, "external:out/{dataset}/mine");
  ASSERT_TRUE(suite::parseMethodToScore("svgf"));
  for (const char* bad : {"taa2=taa", "x=bilateral", "a b=external:x", "x=external:", "../x=external:y"}) {
    auto parsed = suite::parseMethodToScore(bad);
    ASSERT_FALSE(parsed) << bad;
    EXPECT_EQ(parsed.error().code, ErrorCode::kUsage) << bad;
    EXPECT_NE(parsed.error().message.find(bad), std::string::npos) << parsed.error().message;
  }
  // Without none among the scores, the ratio and difference use the recorded none's ꟻLIP.
  evaluate::MethodScores added;
  added.name = "mine", added.flip.mean = 0.06, added.warpedErrorChange.mean = 0.01;
  auto errors = suite::errorsOf({added}, 0.08);
  EXPECT_DOUBLE_EQ(errors["mine"]["flip_ratio_to_none"], 0.75);
  EXPECT_DOUBLE_EQ(errors["mine"]["flip_over_none"], 0.06 - 0.08);
  EXPECT_FALSE(suite::errorsOf({added}).at("mine").count("flip_ratio_to_none"));
  // none among the scores wins over a recorded one.
  evaluate::MethodScores none;
  none.name = "none", none.flip.mean = 0.12;
  EXPECT_DOUBLE_EQ(suite::errorsOf({none, added}, 0.08)["mine"]["flip_ratio_to_none"], 0.5);
}

// A record (suite/record.h) as a run writes it, read back; then refused, naming the file and the
// JSON pointer, when it is of another manifest, another dataset or pins, other settings, a version
// that cannot be compared, or malformed. No game needed: the record is made here.
TEST(Suite, RecordsOfAnotherManifestSettingsOrVersionAndMalformedOnesAreRefused) {
  const fs::path dir = test::freshDir("suite_records");
  auto manifest = suite::readManifest(kSmoke);
  ASSERT_TRUE(manifest) << manifest.error().message;
  const nlohmann::json entry = {{"name", "fps-1-flythrough"},
                                {"dataset", "captures/x/flythrough.gltf"},
                                {"run", "runs/fps-1-flythrough"},
                                {"sha256", manifest->document["datasets"][1]["sha256"]},
                                {"window", {{"first", 30}, {"last", 35}}},
                                {"measures", {{"frustum", 1.25}, {"direct_radiance", 0.5}}},
                                {"errors", {{"none", {{"flip", 0.2}}}, {"taa", {{"flip", 0.1}, {"flip_ratio_to_none", 0.5}}}}},
                                {"match", "x"},
                                {"camera", "flythrough"},
                                {"reference_floor", {{"flip", 0.01}, {"frames", 4}}}};
  const std::map<std::string, std::string> files{{"runs/fps-1-flythrough/frames/frame_00030.exr", std::string(64, 'a')}};
  const nlohmann::json record =
      suite::recordJson(*manifest, 1, entry, files, {{"measure", {2.5, 4.0}}}, 12345, core::MachineInfo{"A CPU", "AuthenticAMD", "x86-64-v3", 2});
  const fs::path good = dir / "good.json";
  ASSERT_TRUE(writeFileAtomic(good, record.dump(2)));
  auto read = suite::readRecord(good, *manifest);
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->dataset, "fps-1-flythrough");
  EXPECT_EQ(read->entry, entry);
  EXPECT_EQ(read->result.measures.at("frustum"), 1.25);
  EXPECT_EQ(read->result.errors.at("taa").at("flip_ratio_to_none"), 0.5);
  EXPECT_EQ(read->result.referenceFloor, 0.01);
  EXPECT_EQ(read->files, files);
  EXPECT_EQ(record["machine"]["isa"], "x86-64-v3");
  EXPECT_EQ(record["seconds"]["measure"]["cpu"], 4.0);
  EXPECT_EQ(record["manifest_sha256"].get<std::string>().size(), 64u);
  // The manifest's digest ignores spacing and key order, not values.
  {
    auto respaced = suite::parseManifest(nlohmann::json::parse(manifest->document.dump(7)), "respaced.json");
    ASSERT_TRUE(respaced);
    EXPECT_EQ(suite::manifestDigest(*respaced), suite::manifestDigest(*manifest));
    nlohmann::json other = manifest->document;
    other["render"]["spp"] = 2;
    auto changed = suite::parseManifest(other, "changed.json");
    ASSERT_TRUE(changed);
    EXPECT_NE(suite::manifestDigest(*changed), suite::manifestDigest(*manifest));
    // A record of that manifest is refused by this one, and the other way round.
    const auto refused = suite::readRecord(good, *changed);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("good.json: /manifest_sha256: a record of another manifest ('smoke'"), std::string::npos)
        << refused.error().message;
  }
  struct Case {
    std::string pointer;
    nlohmann::json value;  // replaces the record's value there (null: removed)
    std::string message;
  };
  const std::vector<Case> cases = {
      {"/dynbench_suite_record", 2, "/dynbench_suite_record: a record of version 2, which this dynbench (record version 1) cannot compare"},
      {"/results_version", 2, "/results_version: numbers of results version 2"},
      {"/numbers_version", 0,
       fmt::format("/numbers_version: numbers of version 0, and this dynbench makes version {}: made by a build whose numbers differ",
                   suite::kNumbersVersion)},
      {"/manifest/description", "edited", "/manifest: not the document its /manifest_sha256 is the digest of"},
      {"/manifest_sha256", std::string(64, '0'), "/manifest_sha256: a record of another manifest"},
      {"/dataset/name", "fps-9-bot", "/dataset/name: 'fps-9-bot' is no dataset of"},
      {"/dataset/sha256/capture", std::string(64, '1'), "/dataset: dataset 'fps-1-flythrough' with other pins or settings than"},
      {"/settings/max_pairs", 1024, "/settings: made with other settings"},
      {"/settings/method_inputs/taa", "still", "/settings: made with other settings"},
      {"/result/measures/frustum", "high", "/result/measures/frustum: expected a number, found \"high\""},
      {"/result/window", nullptr, "/result/window/first: missing"},
      {"/result/name", "fps-2-bot", "/result/name: 'fps-2-bot', not the record's dataset 'fps-1-flythrough'"},
      {"/files/runs~1fps-1-flythrough~1frames~1frame_00030.exr", "abc", "/files/runs/fps-1-flythrough/frames/frame_00030.exr: expected 64 lower-case hex digits"},
      {"/machine", nullptr, "/machine/cpu: missing"},
  };
  for (const Case& c : cases) {
    nlohmann::json bad = record;
    const nlohmann::json::json_pointer at(c.pointer);
    if (c.value.is_null()) bad[at.parent_pointer()].erase(at.back());
    else bad[at] = c.value;
    const fs::path file = dir / "bad.json";
    ASSERT_TRUE(writeFileAtomic(file, bad.dump()));
    const auto refused = suite::readRecord(file, *manifest);
    ASSERT_FALSE(refused) << c.pointer;
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidData) << c.pointer;
    EXPECT_NE(refused.error().message.find(file.string() + ": " + c.message), std::string::npos) << c.pointer << ": " << refused.error().message;
  }
  // Not JSON at all: the JSON reader's error, naming the file; not an object: said so.
  ASSERT_TRUE(writeFileAtomic(dir / "broken.json", "{\"dynbench_suite_record\": 1,"));
  const auto broken = suite::readRecord(dir / "broken.json", *manifest);
  ASSERT_FALSE(broken);
  EXPECT_NE(broken.error().message.find("broken.json"), std::string::npos) << broken.error().message;
  ASSERT_TRUE(writeFileAtomic(dir / "array.json", "[1, 2]"));
  const auto array = suite::readRecord(dir / "array.json", *manifest);
  ASSERT_FALSE(array);
  EXPECT_NE(array.error().message.find("array.json: expected a dynbench suite record"), std::string::npos) << array.error().message;
  // A folder of records: two of one dataset are refused, naming both.
  const fs::path folder = dir / "records";
  fs::create_directories(folder);
  fs::copy_file(good, folder / "a.json");
  fs::copy_file(good, folder / "b.json");
  const auto twice = suite::readRecords(folder, *manifest);
  ASSERT_FALSE(twice);
  EXPECT_NE(twice.error().message.find("b.json: /dataset/name: a second record of dataset 'fps-1-flythrough' (the first: "), std::string::npos)
      << twice.error().message;
  fs::remove(folder / "b.json");
  const auto once = suite::readRecords(folder, *manifest);
  ASSERT_TRUE(once) << once.error().message;
  EXPECT_EQ(once->size(), 1u);
}

// Verifying a record made again (suite verify --record): what counts as the same, checked on a
// record against edited copies of itself. Measures to suite.md's 3 decimals; scores within a tenth
// of the noise floor (0.01 here: 0.001); the ratio to none within what that allows it; frame
// digests only between records of one CPU vendor.
TEST(Suite, ARecordMadeAgainAgreesToTheTablesDigitsAndATenthOfTheFloor) {
  const fs::path dir = test::freshDir("suite_record_compare");
  auto manifest = suite::readManifest(kSmoke);
  ASSERT_TRUE(manifest) << manifest.error().message;
  const nlohmann::json entry = {{"name", "fps-2-bot"},
                                {"dataset", "captures/x/bot.gltf"},
                                {"run", "runs/fps-2-bot"},
                                {"sha256", manifest->document["datasets"][2]["sha256"]},
                                {"window", {{"first", 30}, {"last", 35}}},
                                {"measures", {{"frustum", 1.25}, {"direct_radiance", 0.5}}},
                                {"errors", {{"none", {{"flip", 0.2}}}, {"taa", {{"flip", 0.1}, {"flip_over_none", -0.1}, {"flip_ratio_to_none", 0.5}}}}},
                                {"match", "x"},
                                {"camera", "bot"},
                                {"reference_floor", {{"flip", 0.01}, {"frames", 4}}}};
  const std::map<std::string, std::string> files{{"runs/fps-2-bot/frames/frame_00030.exr", std::string(64, 'a')}};
  const auto make = [&](const std::string& name, const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json record = suite::recordJson(*manifest, 2, entry, files, {}, 1, core::MachineInfo{"A", "AuthenticAMD", "x86-64-v3", 2});
    edit(record);
    EXPECT_TRUE(writeFileAtomic(dir / name, record.dump()));
    auto read = suite::readRecord(dir / name, *manifest);
    EXPECT_TRUE(read) << read.error().message;
    return *read;
  };
  const suite::SuiteRecord recorded = make("recorded.json", [](nlohmann::json&) {});
  const auto differences = [&](const std::function<void(nlohmann::json&)>& edit) {
    return suite::compareRecords(recorded, make("remade.json", edit)).differences;
  };
  const auto same = suite::compareRecords(recorded, recorded);
  EXPECT_TRUE(same.differences.empty());
  EXPECT_EQ(same.files, 1u);
  EXPECT_TRUE(same.filesCompared);
  EXPECT_EQ(same.numbers, 6u + 2u + 1u + 4u);  // exact fields, measures, floor, scores
  // Within what the tables show and a tenth of the floor: the same.
  EXPECT_TRUE(differences([](nlohmann::json& r) {
                r["result"]["measures"]["frustum"] = 1.2504;
                r["result"]["errors"]["taa"]["flip"] = 0.1009;
                r["result"]["errors"]["taa"]["flip_ratio_to_none"] = 0.5074;  // allowed 0.001 (1 + 0.5) / 0.2 = 0.0075
                r["result"]["reference_floor"]["flip"] = 0.0109;
              }).empty());
  // Beyond: named with the record, the pointer and both values.
  const auto moved = differences([](nlohmann::json& r) { r["result"]["measures"]["frustum"] = 1.2506; });
  ASSERT_EQ(moved.size(), 1u);
  EXPECT_EQ(moved[0], (dir / "recorded.json").string() + ": /result/measures/frustum: recorded 1.250, remade 1.251 (as suite.md shows them)");
  const auto score = differences([](nlohmann::json& r) { r["result"]["errors"]["taa"]["flip"] = 0.1011; });
  ASSERT_EQ(score.size(), 1u);
  EXPECT_NE(score[0].find(": /result/errors/taa/flip: recorded 0.1, remade 0.1011 (more than 0.001 apart: a tenth of the noise floor)"), std::string::npos)
      << score[0];
  EXPECT_EQ(differences([](nlohmann::json& r) { r["result"]["errors"]["taa"]["flip_ratio_to_none"] = 0.508; }).size(), 1u);
  EXPECT_EQ(differences([](nlohmann::json& r) { r["result"]["window"]["first"] = 31; }).size(), 1u);
  // Frame digests: compared on one vendor, not across vendors (said so instead), where the record
  // names no fingerprint of its CPU's reciprocal estimates (records made before they carried one).
  const auto otherFrame = [](nlohmann::json& r) { r["files"]["runs/fps-2-bot/frames/frame_00030.exr"] = std::string(64, 'b'); };
  const auto withFingerprint = [](const std::string& estimates) {
    return [estimates](nlohmann::json& r) {
      r["machine"]["family"] = 25;
      r["machine"]["model"] = 17;
      r["machine"]["reciprocal_estimates"] = estimates;
    };
  };
  const auto both = [](auto first, auto second) {
    return [first, second](nlohmann::json& r) {
      first(r);
      second(r);
    };
  };
  const auto oneVendor = suite::compareRecords(recorded, make("remade.json", both(withFingerprint("1234"), otherFrame)));
  ASSERT_EQ(oneVendor.differences.size(), 1u);
  EXPECT_NE(oneVendor.differences[0].find("/files/runs/fps-2-bot/frames/frame_00030.exr: recorded aaaaaaaaaaaa…, remade bbbbbbbbbbbb… (SHA-256)"),
            std::string::npos);
  EXPECT_TRUE(oneVendor.filesCompared);
  // ... and says that the frames may differ because the record cannot tell how its CPU estimated.
  EXPECT_NE(oneVendor.filesNote.find("the record names no fingerprint of its CPU's reciprocal estimates (family and model not recorded; "
                                     "this machine family 25 model 17)"),
            std::string::npos)
      << oneVendor.filesNote;
  const auto oneVendorEqual = suite::compareRecords(recorded, make("remade.json", withFingerprint("1234")));
  EXPECT_TRUE(oneVendorEqual.differences.empty());
  EXPECT_TRUE(oneVendorEqual.filesNote.empty()) << oneVendorEqual.filesNote;
  const auto acrossVendors = suite::compareRecords(recorded, make("remade.json", both(otherFrame, [](nlohmann::json& r) { r["machine"]["vendor"] = "GenuineIntel"; })));
  EXPECT_TRUE(acrossVendors.differences.empty());
  EXPECT_FALSE(acrossVendors.filesCompared);
  EXPECT_NE(acrossVendors.filesNote.find("not compared across CPU vendors"), std::string::npos);
  // Where both name one: compared where the fingerprints are equal, whatever the CPUs' names...
  const suite::SuiteRecord fingerprinted = make("fingerprinted.json", withFingerprint("1234"));
  const auto equalEstimates = suite::compareRecords(fingerprinted, make("remade.json", both(withFingerprint("1234"), otherFrame)));
  EXPECT_EQ(equalEstimates.differences.size(), 1u);
  EXPECT_TRUE(equalEstimates.filesCompared);
  EXPECT_TRUE(equalEstimates.filesNote.empty()) << equalEstimates.filesNote;
  // ... and not where they differ, even on one vendor.
  const auto otherEstimates = suite::compareRecords(fingerprinted, make("remade.json", both(withFingerprint("5678"), otherFrame)));
  EXPECT_TRUE(otherEstimates.differences.empty());
  EXPECT_FALSE(otherEstimates.filesCompared);
  EXPECT_NE(otherEstimates.filesNote.find("whose reciprocal estimates differ from this machine's (A, family 25 model 17: fingerprint 1234 against 5678)"),
            std::string::npos)
      << otherEstimates.filesNote;
}

// --sample's choice: K of the records, the same for a seed on every machine (mt19937_64's sequence
// is fixed by the standard: its 10,000th output is 9981545732273789042), another for another seed.
TEST(Suite, ARecordSampleIsTheSameForASeed) {
  std::mt19937_64 reference;
  reference.discard(9999);
  EXPECT_EQ(reference(), 9981545732273789042ull);
  std::vector<fs::path> records;
  for (int i = 0; i < 15; ++i) records.push_back(fmt::format("records/d{:02d}.json", i));
  const auto a = suite::sampleRecords(records, 3, 7);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
  EXPECT_EQ(std::set<fs::path>(a.begin(), a.end()).size(), 3u);
  EXPECT_EQ(suite::sampleRecords(records, 3, 7), a);
  std::reverse(records.begin(), records.end());
  EXPECT_EQ(suite::sampleRecords(records, 3, 7), a);  // the input's order does not matter
  std::set<std::vector<fs::path>> seen;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) seen.insert(suite::sampleRecords(records, 3, seed));
  EXPECT_GT(seen.size(), 15u);
  EXPECT_EQ(suite::sampleRecords(records, 40, 1).size(), 15u);
}

// The results committed under suites/results/SUITE (`suite publish`): every record parses and
// belongs to suites/SUITE.json as this dynbench makes it (a record of a build whose numbers differ is
// refused: such results are made again, never kept beside newer ones); a complete set's suite.json
// and suite.md are what assembling its records gives, byte for byte; a set still being run
// (`publish --partial`) has no tables.
// Published results of an earlier numbers version (suites/results/v1, made before version 2) still
// assemble, all of one version; a run that would make records beside them refuses them, a set of
// two versions is refused naming the odd record, and `suite verify --record` names the commit that
// can re-make the numbers instead of re-making them with other ones.
TEST(Suite, RecordsOfAnEarlierNumbersVersionAssembleButAreNotMixed) {
  const fs::path published = fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "results" / "v1" / "records";
  auto manifest = suite::readManifest(fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "v1.json");
  ASSERT_TRUE(manifest) << manifest.error().message;
  auto any = suite::readRecords(published, *manifest, suite::NumbersVersions::kAnyOne);
  ASSERT_TRUE(any) << any.error().message;
  ASSERT_FALSE(any->empty());
  const int version = any->begin()->second.numbersVersion;
  if (version == suite::kNumbersVersion) GTEST_SKIP() << "v1's records are of this build's numbers version";
  const auto refused = suite::readRecords(published, *manifest);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find(fmt::format("/numbers_version: numbers of version {}, and this dynbench makes version {}", version,
                                                     suite::kNumbersVersion)),
            std::string::npos)
      << refused.error().message;
  // one record of another version among them
  const fs::path dir = test::freshDir("suite_numbers_versions");
  fs::copy(published, dir / "records");
  const fs::path odd = dir / "records" / "calm-1-bot.json";
  auto doc = nlohmann::json::parse(test::slurp(odd));
  doc["numbers_version"] = version + 100;
  std::ofstream(odd) << doc.dump(2);
  const auto mixed = suite::readRecords(dir / "records", *manifest, suite::NumbersVersions::kAnyOne);
  ASSERT_FALSE(mixed);
  for (const std::string& part : {fmt::format("numbers version {}", version + 100), fmt::format("numbers version {}", version),
                                  std::string("calm-1-bot.json"), std::string("never assembled into one table")})
    EXPECT_NE(mixed.error().message.find(part), std::string::npos) << part << " in " << mixed.error().message;
  // verify names the build that made it and re-makes nothing
  const fs::path v1 = fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "results" / "v1";
  const std::string commit = any->begin()->second.document["tool"]["commit"].get<std::string>();
  const auto r = dynbench(fmt::format("suite verify {} --record {} --work {}", v1.string(), any->begin()->first, (dir / "work").string()), dir);
  EXPECT_EQ(r.status, 6) << r.err;
  EXPECT_NE(r.err.find(fmt::format("made by a build of numbers version {} (git commit {})", version, commit)), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "work" / "captures")) << "nothing is re-made";
}

// cmake/build_commit.cmake, which writes the commit a record names at every build: HEAD of a clean
// tree; HEAD and "-dirty" once a tracked file differs from it (a record made from uncommitted code
// then names no commit whose code it did not run); untracked files do not count; "unknown" outside
// a git checkout.
TEST(Suite, TheBuildCommitIsHeadAndSaysWhenTheTreeDiffers) {
  const fs::path dir = test::freshDir("build_commit");
  const fs::path repo = dir / "repo", out = dir / "build_commit.h";
  fs::create_directories(repo / "src" / "core");
  fs::copy_file(fs::path(DYNBENCH_SOURCE_DIR) / "src" / "core" / "build_commit.h.in", repo / "src" / "core" / "build_commit.h.in");
  auto sh = [&](const std::string& command) { return std::system(fmt::format("cd '{}' && {{ {}; }} >/dev/null 2>&1", repo.string(), command).c_str()); };
  auto written = [&] {
    const std::string script = (fs::path(DYNBENCH_SOURCE_DIR) / "cmake" / "build_commit.cmake").string();
    EXPECT_EQ(sh(fmt::format("cmake -DSOURCE_DIR='{}' -DOUTPUT='{}' -DGIT_EXECUTABLE=git -P '{}'", repo.string(), out.string(), script)), 0);
    const std::string text = test::slurp(out);
    const auto start = text.find("kBuildCommit = \"") + 16;
    return text.substr(start, text.find('"', start) - start);
  };
  EXPECT_EQ(written(), "unknown");
  ASSERT_EQ(sh("git init -q . && git -c user.name=t -c user.email=t@t add -A && git -c user.name=t -c user.email=t@t commit -qm one"), 0);
  const std::string head = [&] {
    const std::string file = (dir / "head").string();
    std::system(fmt::format("cd '{}' && git rev-parse HEAD > '{}'", repo.string(), file).c_str());
    std::string h = test::slurp(file);
    return h.substr(0, h.find('\n'));
  }();
  ASSERT_EQ(head.size(), 40u);
  EXPECT_EQ(written(), head);
  std::ofstream(repo / "untracked.txt") << "not part of the build\n";
  EXPECT_EQ(written(), head) << "untracked files do not make the tree dirty";
  std::ofstream(repo / "src" / "core" / "build_commit.h.in", std::ios::app) << "// edited\n";
  EXPECT_EQ(written(), head + "-dirty");
}

TEST(Suite, PublishedResultsAreTheirRecordsAssembled) {
  const fs::path results = fs::path(DYNBENCH_SOURCE_DIR) / "suites" / "results";
  std::size_t checked = 0;
  std::error_code ec;
  for (const auto& folder : fs::directory_iterator(results, ec)) {
    // A folder is named after its suite, or SUITE@numbers-N for the records of numbers version N
    // being made beside the suite's published set (docs/suite.md, "Publishing").
    const std::string folderName = folder.path().filename().string();
    const std::string name = folderName.substr(0, folderName.find('@'));
    auto manifest = suite::readManifest(fs::path(DYNBENCH_SOURCE_DIR) / "suites" / (name + ".json"));
    ASSERT_TRUE(manifest) << name << ": " << manifest.error().message;
    // published results of an earlier numbers version still assemble (all of one version)
    auto records = suite::readRecords(folder.path() / "records", *manifest, suite::NumbersVersions::kAnyOne);
    ASSERT_TRUE(records) << records.error().message;
    ASSERT_FALSE(records->empty()) << name;
    if (name != folderName) {
      const std::string version = folderName.substr(name.size());
      ASSERT_EQ(version.rfind("@numbers-", 0), 0u) << folderName << ": SUITE@numbers-N";
      for (const auto& [dataset, record] : *records)
        EXPECT_EQ(fmt::format("@numbers-{}", record.numbersVersion), version) << folderName << ": " << dataset;
    }
    ++checked;
    if (records->size() < manifest->datasets.size()) {
      EXPECT_FALSE(fs::exists(folder.path() / "suite.json")) << name << ": tables of a set still being run";
      EXPECT_FALSE(fs::exists(folder.path() / "suite.md")) << name;
      continue;
    }
    const fs::path out = test::freshDir("published_" + name);
    const auto r = dynbench(fmt::format("suite {} -o {} --records {} --assemble", manifest->path.string(), out.string(),
                                        (folder.path() / "records").string()),
                            out);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(test::slurp(out / "suite.json"), test::slurp(folder.path() / "suite.json")) << name;
    EXPECT_EQ(test::slurp(out / "suite.md"), test::slurp(folder.path() / "suite.md")) << name;
  }
  EXPECT_GE(checked, 1u) << "no published results under " << results.string();
}

TEST(Suite, SmokeSuiteRunsResumesAndVerifiesAndAnEditedFrameIsCaught) {
  DYNBENCH_NEEDS(test::missingCube2());
  const fs::path dir = test::freshDir("suite_smoke");
  const fs::path out = dir / "smoke";
  // The one-shot run, shared with Slurm.SuiteAsAChainOfJobsGivesTheLocalSuitesNumbers (shared_run.h),
  // copied here to resume, lock and verify in.
  const auto shared = test::sharedRun("smoke-suite", fmt::format("suite {} -o {{out}}", kSmoke.string()));
  const auto& r = shared.run;
  ASSERT_EQ(r.status, 0) << r.err << r.out;
  test::copyOf(shared, out);
  const auto doc = nlohmann::json::parse(test::slurp(out / "suite.json"));
  EXPECT_EQ(doc["dynbench_suite_results"], 3);
  EXPECT_EQ(doc["manifest"], nlohmann::json::parse(test::slurp(kSmoke)));
  ASSERT_EQ(doc["datasets"].size(), 6u);
  // Each dataset's numbers are those its stages wrote: Table 6.7 from discard.json's mean, the
  // methods' ꟻLIP from evaluate.json, flip_over_none their difference with none's and
  // flip_ratio_to_none their ratio.
  for (const auto& d : doc["datasets"]) {
    const fs::path run = out / d["run"].get<std::string>();
    const auto discard = nlohmann::json::parse(test::slurp(run / "discard.json"));
    EXPECT_NEAR(d["measures"]["direct_radiance"].get<double>(), discard["mean"]["direct_radiance"].get<double>(), 1e-9) << d["name"];
    EXPECT_NEAR(d["measures"]["frustum"].get<double>(), discard["mean"]["frustum"].get<double>(), 1e-9) << d["name"];
    // Each method on its own input (issue 48): TAA on the jittered one (evaluate.json), accumulate
    // and SVGF on the still one (evaluate-still.json), each with that input's `none` as its base.
    EXPECT_EQ(doc["method_inputs"], nlohmann::json({{"none", "jittered"}, {"accumulate", "still"}, {"taa", "jittered"}, {"svgf", "still"}}));
    for (const auto& [file, methods] : {std::pair{"evaluate.json", std::set<std::string>{"none", "taa"}},
                                        std::pair{"evaluate-still.json", std::set<std::string>{"none", "accumulate", "svgf"}}}) {
      const auto evaluation = nlohmann::json::parse(test::slurp(run / file));
      double noneFlip = -1;
      std::set<std::string> names;
      for (const auto& m : evaluation["methods"]) {
        names.insert(m["name"].get<std::string>());
        if (m["name"] == "none") noneFlip = m["mean"]["flip"]["mean"].get<double>();
      }
      EXPECT_EQ(names, methods) << file;
      for (const auto& m : evaluation["methods"]) {
        const std::string name = m["name"] == "none" && std::string(file) == "evaluate-still.json" ? "none-still" : m["name"].get<std::string>();
        EXPECT_NEAR(d["errors"][name]["flip"].get<double>(), m["mean"]["flip"]["mean"].get<double>(), 1e-12);
        EXPECT_NEAR(d["errors"][name]["flip_over_none"].get<double>(), m["mean"]["flip"]["mean"].get<double>() - noneFlip, 1e-12);
        EXPECT_NEAR(d["errors"][name]["flip_ratio_to_none"].get<double>(), m["mean"]["flip"]["mean"].get<double>() / noneFlip, 1e-12);
      }
    }
    // The still input is the jittered one's render without the jitter: the same seed, no jitter.
    const long firstFrame = d["window"]["first"];
    const auto jitteredSidecar = nlohmann::json::parse(test::slurp(run / "input" / fmt::format("frame_{:05d}.json", firstFrame + 1)));
    const auto stillSidecar = nlohmann::json::parse(test::slurp(run / "input-still" / fmt::format("frame_{:05d}.json", firstFrame + 1)));
    EXPECT_EQ(stillSidecar["render"]["seed"], jitteredSidecar["render"]["seed"]);
    EXPECT_NE(jitteredSidecar["camera"]["jitter"], nlohmann::json::array({0.0, 0.0}));
    EXPECT_EQ(stillSidecar["camera"]["jitter"], nlohmann::json::array({0.0, 0.0}));
    // The reference's noise floor: the window's first 4 frames (6 frames, a step of 1) rendered
    // again with seed + 2; its ꟻLIP is what `dynbench compare` gives for each pair, averaged.
    ASSERT_TRUE(d["reference_floor"].is_object()) << d["name"];
    EXPECT_EQ(d["reference_floor"]["frames"], 4);
    double floor = 0;
    for (long f = d["window"]["first"].get<long>(), k = 0; k < 4; ++f, ++k) {
      const fs::path compared = dir / fmt::format("floor_{}.json", f);
      const auto c = dynbench(fmt::format("compare {} {} --json {}", (run / "frames" / fmt::format("frame_{:05d}.exr", f)).string(),
                                          (run / "floor" / fmt::format("frame_{:05d}.exr", f)).string(), compared.string()),
                              dir);
      ASSERT_EQ(c.status, 0) << c.err;
      floor += nlohmann::json::parse(test::slurp(compared))["images"][0]["flip"]["mean"].get<double>() / 4;
      EXPECT_TRUE(doc["files"].contains(fmt::format("{}/floor/frame_{:05d}.exr", d["run"].get<std::string>(), f)));
      const auto sidecar = nlohmann::json::parse(test::slurp(run / "floor" / fmt::format("frame_{:05d}.json", f)));
      EXPECT_EQ(sidecar["render"]["seed"], nlohmann::json::parse(test::slurp(run / "frames" / fmt::format("frame_{:05d}.json", f)))["render"]["seed"].get<int>() + 2);
    }
    EXPECT_NEAR(d["reference_floor"]["flip"].get<double>(), floor, 1e-9) << d["name"];
    EXPECT_GT(floor, 0.0);
    // Every frame of the window is recorded with its checksum.
    EXPECT_TRUE(doc["files"].contains(d["dataset"].get<std::string>()));
    const long window = d["window"]["last"].get<long>() - d["window"]["first"].get<long>() + 1;
    EXPECT_EQ(window, 6);
    EXPECT_TRUE(doc["files"].contains(fmt::format("{}/input/frame_{:05d}.exr", d["run"].get<std::string>(), d["window"]["first"].get<long>())));
  }
  // The smoke manifest's pins (issue 45) held, and suite.json records each dataset's digests.
  const auto manifest = nlohmann::json::parse(test::slurp(kSmoke));
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(doc["datasets"][i]["sha256"], manifest["datasets"][i]["sha256"]) << i;
    EXPECT_EQ(doc["datasets"][i]["sha256"]["dataset"],
              *scene::datasetDigest(out / doc["datasets"][i]["dataset"].get<std::string>()));
  }
  // A pin that does not hold: status 5 naming the dataset, the pointer and the stage, before
  // anything is rendered (the captures are copied, so nothing is captured again).
  for (const auto& [pointer, stage] : {std::pair{"/datasets/3/sha256/capture", "the capture stage"},
                                       std::pair{"/datasets/3/sha256/dataset", "the convert or fly-through stage"}}) {
    nlohmann::json bad = manifest;
    std::string& pin = bad[nlohmann::json::json_pointer(pointer)].get_ref<std::string&>();
    pin[0] = pin[0] == '0' ? '1' : '0';
    ASSERT_TRUE(writeFileAtomic(dir / "pinned.json", bad.dump(2)));
    const fs::path other = dir / "other";
    fs::remove_all(other);
    fs::create_directories(other);
    fs::copy(out / "captures", other / "captures", fs::copy_options::recursive);
    const auto mismatch = dynbench(fmt::format("suite {} -o {}", (dir / "pinned.json").string(), other.string()), dir);
    EXPECT_EQ(mismatch.status, 5) << mismatch.err;
    EXPECT_NE(mismatch.err.find(fmt::format("pinned.json: {}: dataset 'fps-2-flythrough': {}", pointer, stage)), std::string::npos)
        << mismatch.err;
    EXPECT_NE(mismatch.err.find(pin), std::string::npos) << mismatch.err;
    EXPECT_FALSE(fs::exists(other / "runs")) << "rendered before the pins were checked";
    EXPECT_FALSE(fs::exists(other / "suite.json"));
  }

  // The datasets made again as another machine would make them (other_machine.h: Embree's SSE4.2
  // kernels for the fly-through's walls, glibc without AVX2 and FMA): the pins hold.
  {
    const fs::path again = dir / "again";
    fs::create_directories(again);
    fs::copy(out / "captures", again / "captures", fs::copy_options::recursive);
    for (const auto& entry : fs::recursive_directory_iterator(again / "captures"))
      if (entry.path().stem() == "flythrough" || entry.path().stem() == "bot" || entry.path().stem() == "slowed") fs::remove(entry.path());
    test::OtherMachine other;
    const auto remade = dynbench(fmt::format("suite {} -o {} --part datasets", kSmoke.string(), again.string()), dir);
    EXPECT_EQ(remade.status, 0) << remade.err;
    EXPECT_NE(remade.out.find("fly-through: a smooth camera"), std::string::npos) << remade.out;
    EXPECT_NE(remade.out.find("slowed turns: the bot's camera"), std::string::npos) << remade.out;
    for (const auto& d : nlohmann::json::parse(test::slurp(kSmoke))["datasets"])
      EXPECT_NE(remade.out.find("(as pinned), dataset " + d["sha256"]["dataset"].get<std::string>() + " (as pinned)"), std::string::npos)
          << d["name"] << remade.out;
  }

  // The fly-throughs and slowed cameras share their bot's capture: two captures for six datasets.
  EXPECT_EQ(std::distance(fs::directory_iterator(out / "captures"), fs::directory_iterator()), 2);
  // The validity table: a cell per measure, method and error, rho from the recorded numbers.
  ASSERT_FALSE(doc["validity"].empty());
  for (const auto& c : doc["validity"]) {
    if (c["measure"] != "direct_radiance" || c["method"] != "taa" || c["error"] != "flip_over_none") continue;
    std::vector<double> x, y;
    for (const auto& d : doc["datasets"]) x.push_back(d["measures"]["direct_radiance"]), y.push_back(d["errors"]["taa"]["flip_over_none"]);
    EXPECT_NEAR(c["rho"].get<double>(), *metrics::spearman(x, y), 1e-12);
  }
  // Within matches: each match's three cameras in pairs (bot against slowed and against the
  // fly-through, slowed against the fly-through), each cell from the recorded numbers.
  ASSERT_FALSE(doc["within_matches"].empty());
  std::set<std::pair<std::string, std::string>> pairs;
  for (const auto& c : doc["within_matches"]) {
    pairs.emplace(c["camera_a"], c["camera_b"]);
    EXPECT_EQ(c["matches"], 2);
    if (c["camera_a"] != "bot" || c["camera_b"] != "flythrough" || c["measure"] != "frustum" || c["method"] != "taa") continue;
    int higher = 0;
    for (int seed : {1, 2}) {
      const auto pick = [&](const std::string& camera) {
        for (const auto& d : doc["datasets"])
          if (d["name"] == fmt::format("fps-{}-{}", seed, camera)) return d;
        return nlohmann::json();
      };
      higher += pick("bot")["measures"]["frustum"].get<double>() > pick("flythrough")["measures"]["frustum"].get<double>();
    }
    EXPECT_EQ(c["measure_higher"], higher);
  }
  EXPECT_EQ(pairs, (std::set<std::pair<std::string, std::string>>{{"bot", "slowed"}, {"bot", "flythrough"}, {"slowed", "flythrough"}}));
  // The slowed camera keeps the bot's positions and cuts and turns less over the whole match
  // (RUN/stats.json); within a short window it may turn more, a turn's rotation spread over the
  // 2 s around it (docs/suite.md, "Camera policies").
  for (int seed : {1, 2}) {
    const auto pick = [&](const std::string& camera) {
      for (const auto& d : doc["datasets"])
        if (d["name"] == fmt::format("fps-{}-{}", seed, camera)) return d;
      return nlohmann::json();
    };
    const auto motion = [&](const std::string& camera) {
      return nlohmann::json::parse(test::slurp(out / pick(camera)["run"].get<std::string>() / "stats.json"))["datasets"][0]["camera_motion"];
    };
    EXPECT_LT(motion("slowed")["rotation_degrees"]["mean"].get<double>(), motion("bot")["rotation_degrees"]["mean"].get<double>()) << seed;
    EXPECT_EQ(motion("slowed")["cuts"], motion("bot")["cuts"]) << seed;
    EXPECT_DOUBLE_EQ(motion("slowed")["position"]["mean"].get<double>(), motion("bot")["position"]["mean"].get<double>()) << seed;
    EXPECT_DOUBLE_EQ(pick("slowed")["measures"]["camera_position"].get<double>(), pick("bot")["measures"]["camera_position"].get<double>()) << seed;
  }
  const std::string md = test::slurp(out / "suite.md");
  EXPECT_NE(md.find("## Validity"), std::string::npos);
  EXPECT_NE(md.find("### bot (A) against flythrough (B), 2 matches"), std::string::npos);
  EXPECT_NE(md.find("| fps-2-flythrough "), std::string::npos);
  for (const char* method : {"none", "accumulate", "taa", "svgf"}) EXPECT_TRUE(fs::exists(out / "plots" / fmt::format("scatter_{}.png", method)));

  // Each dataset left its record (suite/record.h): suite.json's entry and files for it, the manifest's
  // digest, the machine and the seconds each part took.
  for (std::size_t i = 0; i < 6; ++i) {
    const auto record = nlohmann::json::parse(test::slurp(out / "records" / (doc["datasets"][i]["name"].get<std::string>() + ".json")));
    EXPECT_EQ(record["result"], doc["datasets"][i]) << i;
    EXPECT_EQ(record["dataset"], manifest["datasets"][i]) << i;
    for (const auto& [file, sum] : record["files"].items()) EXPECT_EQ(doc["files"][file], sum) << file;
    EXPECT_TRUE(record["files"].contains(doc["datasets"][i]["dataset"].get<std::string>())) << i;
    EXPECT_GT(record["seconds"]["measure"]["wall"].get<double>(), 0.0) << i;
    EXPECT_GT(record["disk_bytes"].get<double>(), 0.0) << i;
    EXPECT_FALSE(record["machine"]["cpu"].get<std::string>().empty());
  }

  // Resumed: every dataset has its record, so nothing is captured, rendered or measured again, and
  // the same suite.json is assembled.
  const std::string json1 = test::slurp(out / "suite.json"), md1 = test::slurp(out / "suite.md");
  const auto again = dynbench(fmt::format("suite {} -o {}", kSmoke.string(), out.string()), dir);
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(again.out.find("capture:"), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("[6/6] fps-2-slowed: done (record "), std::string::npos) << again.out;
  EXPECT_NE(again.out.find("(0 records made, 6 there before)"), std::string::npos) << again.out;
  EXPECT_EQ(again.out.find("min left"), std::string::npos) << again.out;
  // The first run's progress estimated the time left from what it rendered.
  EXPECT_NE(r.out.find("min left at the"), std::string::npos) << r.out;
  EXPECT_EQ(test::slurp(out / "suite.json"), json1);

  // The same suite as two halves on two folders (another machine's, say), the records brought
  // together and assembled with nothing rendered: suite.json and suite.md byte for byte the
  // one-shot run's. (The captures and frames are copied to spare the game and the renders: each
  // half makes its datasets, measures and records; the kills below render everything again.)
  {
    const fs::path a = dir / "half-a", b = dir / "half-b";
    for (const fs::path& half : {a, b}) {
      fs::create_directories(half);
      fs::copy(out / "captures", half / "captures", fs::copy_options::recursive);
      fs::copy(out / "runs", half / "runs", fs::copy_options::recursive);
    }
    const auto first = dynbench(fmt::format("suite {} -o {} --only fps-1-bot,fps-1-flythrough,fps-1-slowed", kSmoke.string(), a.string()), dir);
    ASSERT_EQ(first.status, 0) << first.err << first.out;
    EXPECT_NE(first.out.find("3 of 6 datasets still without one"), std::string::npos) << first.out;
    EXPECT_NE(first.out.find("rendered 0 frames"), std::string::npos) << "the copied frames are reused: " << first.out;
    EXPECT_FALSE(fs::exists(a / "suite.json"));
    const auto second = dynbench(fmt::format("suite {} -o {} --only fps-2-bot --only fps-2-flythrough,fps-2-slowed", kSmoke.string(), b.string()), dir);
    ASSERT_EQ(second.status, 0) << second.err << second.out;
    // Assembling without every record: an error naming those missing, nothing written.
    const auto partial = dynbench(fmt::format("suite {} -o {} --assemble", kSmoke.string(), b.string()), dir);
    EXPECT_EQ(partial.status, 8) << partial.err;
    EXPECT_NE(partial.err.find("no record of 3 of the 6 datasets (fps-1-bot, fps-1-flythrough, fps-1-slowed)"), std::string::npos) << partial.err;
    const fs::path together = dir / "together";
    const auto assembled = dynbench(fmt::format("suite {} -o {} --records {} --records {} --assemble", kSmoke.string(), together.string(),
                                                (a / "records").string(), (b / "records").string()),
                                    dir);
    ASSERT_EQ(assembled.status, 0) << assembled.err << assembled.out;
    EXPECT_FALSE(fs::exists(together / "runs")) << "rendered";
    EXPECT_EQ(test::slurp(together / "suite.json"), json1);
    EXPECT_EQ(test::slurp(together / "suite.md"), md1);
    EXPECT_EQ(std::distance(fs::directory_iterator(together / "records"), fs::directory_iterator()), 6);
    // A record of another manifest among them: refused, naming the file and the field.
    nlohmann::json foreign = nlohmann::json::parse(test::slurp(a / "records" / "fps-1-bot.json"));
    foreign["manifest_sha256"] = std::string(64, 'f');
    fs::create_directories(dir / "foreign");
    ASSERT_TRUE(writeFileAtomic(dir / "foreign" / "fps-1-bot.json", foreign.dump(1)));
    const auto refused = dynbench(fmt::format("suite {} -o {} --records {} --assemble", kSmoke.string(), (dir / "fresh").string(),
                                              (dir / "foreign").string()),
                                  dir);
    EXPECT_EQ(refused.status, 5) << refused.err;
    EXPECT_NE(refused.err.find("fps-1-bot.json: /manifest_sha256: a record of another manifest"), std::string::npos) << refused.err;
  }

  // One run at a time in a folder: while another process holds its lock, a second run refuses.
  {
    std::string holder;
    ASSERT_EQ(runShell(fmt::format("flock -n {} sleep 20 > /dev/null 2>&1 & sleep 1; echo started", (out / ".suite.lock").string()), holder), 0);
    const auto locked = dynbench(fmt::format("suite {} -o {}", kSmoke.string(), out.string()), dir);
    EXPECT_EQ(locked.status, 3) << locked.err;
    EXPECT_NE(locked.err.find("another `dynbench suite` is running in this folder"), std::string::npos) << locked.err;
    std::string ignored;
    runShell(fmt::format("pkill -f 'flock -n {}'", (out / ".suite.lock").string()), ignored);
  }

  // A record made again from nothing (its own manifest, a fresh folder: capture, convert, renders,
  // discard, evaluate) agrees with it, its frames the same bytes on this machine.
  {
    const auto remade = dynbench(fmt::format("suite verify {} --record fps-1-flythrough --work {}", out.string(), (dir / "remade").string()), dir);
    EXPECT_EQ(remade.status, 0) << remade.err << remade.out;
    EXPECT_NE(remade.out.find("capture:"), std::string::npos) << "not made from nothing: " << remade.out;
    const auto recorded = nlohmann::json::parse(test::slurp(out / "records" / "fps-1-flythrough.json"));
    std::size_t numbers = 6 + recorded["result"]["measures"].size() + 1;  // the exact fields, measures, floor, every score
    for (const auto& [method, errors] : recorded["result"]["errors"].items()) numbers += errors.size();
    EXPECT_NE(remade.out.find(fmt::format("verify fps-1-flythrough: {} numbers and {} file digests, 0 differ", numbers, recorded["files"].size())),
              std::string::npos)
        << remade.out;
  }
  // Killed (SIGKILL) at pseudo-random moments five times, resumed each time: at no point is a
  // half-written record or suite.json there to be taken as finished, and the end is the
  // uninterrupted run's: the same suite.json, each record's result and files. (The captures are
  // copied, the cameras' datasets not: the kills land in the cameras, renders, measuring and
  // record writing, which is where a run spends its time.)
  {
    const fs::path killed = dir / "killed";
    fs::create_directories(killed);
    fs::copy(out / "captures", killed / "captures", fs::copy_options::recursive);
    for (const auto& entry : fs::recursive_directory_iterator(killed / "captures"))
      if (entry.path().stem() == "flythrough" || entry.path().stem() == "slowed") fs::remove(entry.path());
    std::mt19937 random(2026);
    std::uniform_real_distribution<double> seconds(1.0, 12.0);  // a smoke dataset takes about 5-15 s here
    auto smokeManifest = suite::readManifest(kSmoke);
    ASSERT_TRUE(smokeManifest);
    for (int k = 0; k < 5; ++k) {
      const double after = seconds(random);
      SCOPED_TRACE(fmt::format("kill {} after {:.2f} s", k, after));
      std::string log;
      const int status = runShell(fmt::format("timeout -s KILL {:.2f} '{}' suite '{}' -o '{}' 2>&1", after, DYNBENCH_EXE, kSmoke.string(), killed.string()), log);
      EXPECT_TRUE(status == 137 || status == 0) << "kill " << k << " after " << after << " s: " << log;
      // Whatever is in records/ is whole and checks; suite.json is there only once every record is.
      auto records = suite::readRecords(killed / "records", *smokeManifest);
      ASSERT_TRUE(records) << "kill " << k << ": " << records.error().message;
      if (fs::exists(killed / "suite.json")) EXPECT_EQ(records->size(), 6u) << k;
    }
    const auto resumed = dynbench(fmt::format("suite {} -o {}", kSmoke.string(), killed.string()), dir);
    ASSERT_EQ(resumed.status, 0) << resumed.err << resumed.out;
    EXPECT_EQ(test::slurp(killed / "suite.json"), json1);
    for (const auto& entry : fs::directory_iterator(out / "records")) {
      const auto a = nlohmann::json::parse(test::slurp(entry.path())), b = nlohmann::json::parse(test::slurp(killed / "records" / entry.path().filename()));
      EXPECT_EQ(a["result"], b["result"]) << entry.path().filename();
      EXPECT_EQ(a["files"], b["files"]) << entry.path().filename();
    }
  }

  // Published: the records copied and the tables assembled from them alone, the one-shot run's bytes.
  {
    const fs::path published = dir / "published";
    const auto r2 = dynbench(fmt::format("suite publish {} -o {}", out.string(), published.string()), dir);
    ASSERT_EQ(r2.status, 0) << r2.err;
    EXPECT_EQ(test::slurp(published / "suite.json"), json1);
    EXPECT_EQ(test::slurp(published / "suite.md"), md1);
    EXPECT_EQ(std::distance(fs::directory_iterator(published / "records"), fs::directory_iterator()), 6);
    const auto incomplete = dynbench(fmt::format("suite publish {} -o {}", (dir / "half-a").string(), (dir / "published-half").string()), dir);
    EXPECT_EQ(incomplete.status, 8) << incomplete.err;
    EXPECT_NE(incomplete.err.find("no record of 3 of the 6 datasets of suite 'smoke' (fps-2-bot, fps-2-flythrough, fps-2-slowed)"), std::string::npos)
        << incomplete.err;
    // A run still going, published with --partial: its records, no tables (over the complete ones).
    const auto partial = dynbench(fmt::format("suite publish {} -o {} --partial", (dir / "half-a").string(), published.string()), dir);
    ASSERT_EQ(partial.status, 0) << partial.err;
    EXPECT_NE(partial.out.find("3 records, 3 datasets still without one"), std::string::npos) << partial.out;
    EXPECT_EQ(std::distance(fs::directory_iterator(published / "records"), fs::directory_iterator()), 3);
    EXPECT_FALSE(fs::exists(published / "suite.json"));
    EXPECT_FALSE(fs::exists(published / "suite.md"));
  }

  // A clean run verifies.
  const auto clean = dynbench(fmt::format("suite verify {}", out.string()), dir);
  EXPECT_EQ(clean.status, 0) << clean.err << clean.out;
  EXPECT_NE(clean.out.find(", 0 differ"), std::string::npos) << clean.out;

  // A method that is not in the manifest, scored on the finished suite (issue 48): the worked
  // example, examples/python/ema.py --suite, through dynbench.suite_score.
  const fs::path python = fs::path(DYNBENCH_EXE).parent_path() / "python";
  if (fs::exists(python / "dynbench" / "__init__.py")) {
    const std::string env = fmt::format("PYTHONPATH='{}' /usr/bin/python3 ", python.string());
    const std::string example = (fs::path(DYNBENCH_SOURCE_DIR) / "examples" / "python" / "ema.py").string();
    // The records from Python, checked by the same reader: a suite folder's and a folder of records.
    for (const fs::path& folder : {out, dir / "together" / "records"}) {
      std::string listed;
      ASSERT_EQ(runShell(env + fmt::format("-c \"import dynbench; r = dynbench.suite_records('{}'); "
                                           "print(len(r), r['fps-2-bot']['result']['measures']['frustum'], r['fps-2-bot']['manifest']['name'])\" 2>&1",
                                           folder.string()),
                         listed),
                0)
          << listed;
      EXPECT_EQ(listed, fmt::format("6 {} smoke\n", nlohmann::json(doc["datasets"][2]["measures"]["frustum"]).dump())) << folder;
    }
    // Scoring needs frames, and says which datasets have none here: a folder assembled from records.
    {
      std::string refused;
      EXPECT_NE(runShell(env + fmt::format("-c \"import dynbench; dynbench.suite_score('{}', methods=['mine=external:{}'])\" 2>&1",
                                           (dir / "together").string(), (dir / "nowhere").string()),
                         refused),
                0);
      EXPECT_NE(refused.find("the frames of 6 of the 6 datasets are not here (fps-1-bot, fps-1-flythrough, fps-2-bot, fps-2-flythrough, fps-1-slowed, "
                             "fps-2-slowed)"),
                std::string::npos)
          << refused;
      const auto cli = dynbench(fmt::format("suite score {} --method mine=external:{}", (dir / "together").string(), (dir / "nowhere").string()), dir);
      EXPECT_EQ(cli.status, 3) << cli.err;
      EXPECT_NE(cli.err.find("the frames of 6 of the 6 datasets are not here"), std::string::npos) << cli.err;
      EXPECT_EQ(test::slurp(dir / "together" / "suite.json"), json1);
    }
    {
      nlohmann::json edited = nlohmann::json::parse(test::slurp(dir / "together" / "records" / "fps-1-bot.json"));
      edited["settings"]["max_pairs"] = 1;
      ASSERT_TRUE(writeFileAtomic(dir / "edited" / "fps-1-bot.json", edited.dump()));
      std::string refused;
      EXPECT_NE(runShell(env + fmt::format("-c \"import dynbench; dynbench.suite_records('{}')\" 2>&1", (dir / "edited").string()), refused), 0);
      EXPECT_NE(refused.find("fps-1-bot.json: /settings: made with other settings"), std::string::npos) << refused;
    }
    std::string table;
    ASSERT_EQ(runShell(env + fmt::format("'{}' --suite '{}' --check 2>&1", example, out.string()), table), 0) << table;
    EXPECT_NE(table.find("fps-2-flythrough"), std::string::npos) << table;
    EXPECT_NE(table.find(" datasets, 0 differ from evaluate"), std::string::npos) << table;
    // Its column is what `evaluate` gives for the same method on each dataset's stored frames.
    std::string evaluated;
    ASSERT_EQ(runShell(env + fmt::format("-c \"import importlib.util, json, dynbench; spec = importlib.util.spec_from_file_location('ema', '{}'); "
                                         "ema = importlib.util.module_from_spec(spec); spec.loader.exec_module(ema); "
                                         "suite = json.load(open('{}/suite.json')); "
                                         "print(json.dumps({{d['name']: dynbench.evaluate('{}/' + d['run'] + '/input', '{}/' + d['run'] + '/frames', "
                                         "methods=[ema.Ema()])['methods'][0]['mean']['flip']['mean'] for d in suite['datasets']}}))\" 2>&1",
                                         example, out.string(), out.string(), out.string()),
                       evaluated),
              0)
        << evaluated;
    const auto byEvaluate = nlohmann::json::parse(evaluated);
    const auto scored = nlohmann::json::parse(test::slurp(out / "suite.json"));
    ASSERT_EQ(scored["scored_methods"].size(), 1u);
    EXPECT_EQ(scored["scored_methods"][0]["name"], "ema");
    EXPECT_EQ(scored["scored_methods"][0]["spec"], "python:__main__.Ema");
    for (std::size_t i = 0; i < scored["datasets"].size(); ++i) {
      const auto& d = scored["datasets"][i];
      const double flip = d["errors"]["ema"]["flip"], none = d["errors"]["none"]["flip"];
      EXPECT_DOUBLE_EQ(flip, byEvaluate[d["name"].get<std::string>()].get<double>()) << d["name"];
      EXPECT_DOUBLE_EQ(d["errors"]["ema"]["flip_ratio_to_none"].get<double>(), flip / none) << d["name"];
      // the manifest's methods' numbers are untouched
      EXPECT_EQ(d["errors"]["taa"], doc["datasets"][i]["errors"]["taa"]);
      EXPECT_TRUE(scored["files"].contains(fmt::format("scored/{}/ema/frame_{:05d}.exr", d["name"].get<std::string>(), d["window"]["first"].get<long>())));
    }
    EXPECT_NE(test::slurp(out / "suite.md").find("- `ema`: python:__main__.Ema"), std::string::npos);
    EXPECT_NE(test::slurp(out / "suite.md").find("| ema (flip_ratio_to_none) |"), std::string::npos);

    // The same outputs as another program's (the external: layout, {dataset} in the path): the same column.
    const auto external = dynbench(fmt::format("suite score {} --method files=external:{}/scored/{{dataset}}/ema", out.string(), out.string()), dir);
    ASSERT_EQ(external.status, 0) << external.err;
    const auto both = nlohmann::json::parse(test::slurp(out / "suite.json"));
    for (const auto& d : both["datasets"]) EXPECT_EQ(d["errors"]["files"], d["errors"]["ema"]) << d["name"];
    // ... and on the still input: the same ꟻLIP (the same outputs against the same reference), its
    // ratio to `none` on the still input; recorded as such, so verify re-derives it as such.
    const auto still = dynbench(fmt::format("suite score {} --method files-still=external:{}/scored/{{dataset}}/ema --input still", out.string(),
                                            out.string()),
                                dir);
    ASSERT_EQ(still.status, 0) << still.err;
    const auto withStill = nlohmann::json::parse(test::slurp(out / "suite.json"));
    EXPECT_EQ(withStill["scored_methods"].back()["input"], "still");
    EXPECT_EQ(withStill["scored_methods"][0]["input"], "jittered");
    for (const auto& d : withStill["datasets"]) {
      const auto& e = d["errors"]["files-still"];
      EXPECT_DOUBLE_EQ(e["flip"].get<double>(), d["errors"]["ema"]["flip"].get<double>()) << d["name"];
      EXPECT_DOUBLE_EQ(e["flip_ratio_to_none"].get<double>(), e["flip"].get<double>() / d["errors"]["none-still"]["flip"].get<double>()) << d["name"];
      EXPECT_NE(e["flip_ratio_to_none"], d["errors"]["ema"]["flip_ratio_to_none"]) << d["name"];
    }
    // A dataset without the still input: status 3, naming it; nothing changes.
    const std::string withStillText = test::slurp(out / "suite.json");
    const fs::path stillInput = out / withStill["datasets"][1]["run"].get<std::string>() / "input-still";
    fs::rename(stillInput, dir / "input-still-aside");
    const auto noStill = dynbench(fmt::format("suite score {} --method gone-still=external:{}/scored/{{dataset}}/ema --input still", out.string(),
                                              out.string()),
                                  dir);
    fs::rename(dir / "input-still-aside", stillInput);
    EXPECT_EQ(noStill.status, 3) << noStill.err;
    EXPECT_NE(noStill.err.find("no still input"), std::string::npos) << noStill.err;
    EXPECT_EQ(test::slurp(out / "suite.json"), withStillText);
    // verify re-derives the added columns from their stored outputs.
    const auto verified = dynbench(fmt::format("suite verify {}", out.string()), dir);
    EXPECT_EQ(verified.status, 0) << verified.out;
    EXPECT_NE(verified.out.find(", 0 differ"), std::string::npos) << verified.out;

    // Bad requests: a manifest method's name (usage, status 2), a folder without the outputs
    // (status 3, naming the file); suite.json is left as it was and nothing is left pending.
    const std::string before = test::slurp(out / "suite.json");
    const auto taken = dynbench(fmt::format("suite score {} --method taa", out.string()), dir);
    EXPECT_EQ(taken.status, 2) << taken.err;
    EXPECT_NE(taken.err.find("method 'taa' is one of the manifest's"), std::string::npos) << taken.err;
    const auto missing = dynbench(fmt::format("suite score {} --method gone=external:{}", out.string(), (dir / "nowhere").string()), dir);
    EXPECT_EQ(missing.status, 3) << missing.err;
    EXPECT_NE(missing.err.find((dir / "nowhere" / "fps-1-bot").string()), std::string::npos) << missing.err;
    const fs::path half = dir / "half";  // the first dataset's outputs only: fails at the second
    fs::create_directories(half);
    fs::copy(out / "scored" / "fps-1-bot" / "ema", half / "fps-1-bot");
    const auto partial = dynbench(fmt::format("suite score {} --method half=external:{}", out.string(), half.string()), dir);
    EXPECT_EQ(partial.status, 3) << partial.err;
    EXPECT_NE(partial.err.find("dataset 'fps-1-flythrough'"), std::string::npos) << partial.err;
    EXPECT_EQ(test::slurp(out / "suite.json"), before);
    EXPECT_FALSE(fs::exists(out / "scored" / ".pending"));
    EXPECT_FALSE(fs::exists(out / "scored" / "fps-1-bot" / "half"));
  }

  // One input frame edited by hand (its direct radiance doubled): verify names the file and the
  // numbers that changed with it, and fails.
  const std::string run = doc["datasets"][2]["run"];
  const long first = doc["datasets"][2]["window"]["first"];
  const fs::path inputDir = out / run / "input";
  auto frames = frames::listFrames(inputDir);
  ASSERT_TRUE(frames && frames->size() == 6);
  auto frame = frames::readFrame((*frames)[3]);
  ASSERT_TRUE(frame) << frame.error().message;
  for (float& v : frame->direct) v *= 2.0f;
  auto sidecar = frames::readSidecar((*frames)[3].sidecar);
  ASSERT_TRUE(sidecar);
  ASSERT_TRUE(frames::writeFrame(inputDir, *frame, sidecar->render));
  const auto edited = dynbench(fmt::format("suite verify {}", out.string()), dir);
  EXPECT_EQ(edited.status, 5) << edited.out;
  EXPECT_NE(edited.out.find(fmt::format("{}/input/frame_{:05d}.exr: SHA-256 differs", run, first + 3)), std::string::npos) << edited.out;
  EXPECT_NE(edited.out.find(fmt::format("{}: taa flip: recorded", doc["datasets"][2]["name"].get<std::string>())), std::string::npos) << edited.out;
  // The reference frames and the other datasets did not change: their Table 6.7 numbers verify.
  EXPECT_EQ(edited.out.find(": direct: recorded"), std::string::npos) << edited.out;
}

}  // namespace
}  // namespace dynbench
