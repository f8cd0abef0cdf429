// The glTF reader on the Khronos sample models (counts read independently from the JSON) and on
// broken files (each error names the file and the JSON pointer, and says what was expected).
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "gltf_builder.h"
#include "metrics/properties.h"
#include "scene/pose.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

namespace fs = std::filesystem;
const fs::path kTestData = DYNBENCH_TESTDATA_DIR;

// Counts taken straight from the JSON, without dynbench's reader.
struct JsonCounts {
  std::size_t nodes = 0, skins = 0, joints = 0, animations = 0, channels = 0, cameras = 0, triangles = 0, morphTargets = 0;
};

JsonCounts countFromJson(const fs::path& file) {
  std::ifstream in(file);
  const auto j = nlohmann::json::parse(in);
  JsonCounts c;
  c.nodes = j.value("nodes", nlohmann::json::array()).size();
  c.cameras = j.value("cameras", nlohmann::json::array()).size();
  for (const auto& s : j.value("skins", nlohmann::json::array())) {
    ++c.skins;
    c.joints += s["joints"].size();
  }
  for (const auto& a : j.value("animations", nlohmann::json::array())) {
    ++c.animations;
    c.channels += a["channels"].size();
  }
  for (const auto& m : j.value("meshes", nlohmann::json::array()))
    for (const auto& p : m["primitives"]) {
      if (p.value("mode", 4) != 4) continue;
      const auto& counted = p.contains("indices") ? j["accessors"][p["indices"].get<int>()]
                                                  : j["accessors"][p["attributes"]["POSITION"].get<int>()];
      c.triangles += counted["count"].get<std::size_t>() / 3;
      c.morphTargets = std::max(c.morphTargets, p.value("targets", nlohmann::json::array()).size());
    }
  return c;
}

class KhronosSample : public ::testing::TestWithParam<std::string> {};

TEST_P(KhronosSample, CountsMatchTheJson) {
  const fs::path file = kTestData / GetParam() / (GetParam() + ".gltf");
  auto scene = loadScene(file);
  ASSERT_TRUE(scene) << scene.error().message;
  const JsonCounts expected = countFromJson(file);
  EXPECT_EQ(scene->nodes.size(), expected.nodes);
  EXPECT_EQ(scene->skins.size(), expected.skins);
  std::size_t joints = 0, channels = 0, triangles = 0, targets = 0;
  for (const auto& s : scene->skins) joints += s.joints.size();
  for (const auto& a : scene->animations) channels += a.channels.size();
  for (const auto& m : scene->meshes) {
    triangles += m.triangleCount();
    targets = std::max(targets, m.morphTargetCount());
  }
  EXPECT_EQ(joints, expected.joints);
  EXPECT_EQ(scene->animations.size(), expected.animations);
  EXPECT_EQ(channels, expected.channels);
  EXPECT_EQ(scene->cameras.size(), expected.cameras);
  EXPECT_EQ(triangles, expected.triangles);
  EXPECT_EQ(targets, expected.morphTargets);
  EXPECT_EQ(scene->source.files.size(), 1u);  // embedded buffers only
  EXPECT_EQ(scene->source.totalBytes(), fs::file_size(file));
}

INSTANTIATE_TEST_SUITE_P(Samples, KhronosSample,
                         ::testing::Values("AnimatedTriangle", "BoxAnimated", "RiggedFigure", "RiggedSimple", "SimpleMorph",
                                           "SimpleSkin"));

TEST(KhronosSamples, KnownFacts) {
  // Facts from shared/testdata/README.md, which was written from the files by other means.
  auto box = loadScene(kTestData / "BoxAnimated/BoxAnimated.gltf");
  ASSERT_TRUE(box);
  const auto range = box->timeRange();
  EXPECT_NEAR(range.start, 0.0, 1e-6);
  EXPECT_NEAR(range.end, 3.708, 1e-3);  // the longer channel sets the clock
  EXPECT_EQ(box->nodes[2].parent, 1);
  EXPECT_EQ(box->nodes[1].parent, 0);

  auto triangle = loadScene(kTestData / "AnimatedTriangle/AnimatedTriangle.gltf");
  ASSERT_TRUE(triangle);
  // 0, 90, 180, 270, 360 degrees about Z over 0-1 s: at 0.5 s the node is turned 180 degrees.
  const Evaluator e(*triangle);
  const glm::dmat4 m = e.worldMatrix(0, 0.5);
  EXPECT_NEAR(m[0].x, -1.0, 1e-6);
  EXPECT_NEAR(m[1].y, -1.0, 1e-6);

  auto morph = loadScene(kTestData / "SimpleMorph/SimpleMorph.gltf");
  ASSERT_TRUE(morph);
  EXPECT_EQ(morph->meshes[0].defaultWeights, (std::vector<float>{0.5f, 0.5f}));
  const auto p = metrics::measureProperties(*morph, 24.0);
  EXPECT_TRUE(p.morphTargets);
  EXPECT_EQ(p.morphAnimatedObjects, 1u);
  EXPECT_EQ(p.animationFrames, 97u);  // 0-4 s at 24 fps

  auto rigged = loadScene(kTestData / "RiggedFigure/RiggedFigure.gltf");
  ASSERT_TRUE(rigged);
  EXPECT_EQ(rigged->skins[0].joints.size(), 19u);
  EXPECT_EQ(metrics::measureProperties(*rigged, 24.0).armatures, 1u);
}

// ---- bad input -------------------------------------------------------------------------------

test::GltfBuilder animatedCamera() {
  test::GltfBuilder b;
  const int n = b.node({{"name", "cam"}, {"camera", b.perspectiveCamera()}});
  b.channel(n, "translation", {0, 1, 2}, {0, 0, 0, 1, 0, 0, 2, 0, 0});
  return b;
}

void expectError(const Expected<Scene>& result, ErrorCode code, std::vector<std::string> fragments) {
  ASSERT_FALSE(result) << "expected an error";
  EXPECT_EQ(result.error().code, code) << result.error().message;
  for (const auto& f : fragments)
    EXPECT_NE(result.error().message.find(f), std::string::npos) << "missing '" << f << "' in: " << result.error().message;
}

TEST(BadGltf, TruncatedGlb) {
  const auto dir = test::freshDir("bad_glb");
  auto b = animatedCamera();
  const auto glb = b.writeGlb(dir, "ok");
  ASSERT_TRUE(loadScene(glb)) << "the untruncated GLB must load";
  const auto size = fs::file_size(glb);
  fs::resize_file(glb, size / 2);
  expectError(loadScene(glb), ErrorCode::kParse, {glb.string(), "truncated GLB", std::to_string(size)});
  fs::resize_file(glb, 7);
  expectError(loadScene(glb), ErrorCode::kParse, {"truncated GLB", "12"});
}

TEST(BadGltf, MissingBin) {
  const auto dir = test::freshDir("bad_bin");
  auto b = animatedCamera();
  const auto path = b.write(dir, "scene");
  fs::remove(dir / "scene.bin");
  expectError(loadScene(path), ErrorCode::kIo, {path.string(), "/buffers/0/uri", "scene.bin"});
}

TEST(BadGltf, AccessorOutOfRange) {
  const auto dir = test::freshDir("bad_accessor");
  auto b = animatedCamera();
  b.doc["accessors"][1]["count"] = 5;  // translation output: 5 VEC3 (60 bytes) in a 36-byte view
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData, {"/accessors/1", "needs 60 bytes", "bufferView 1", "36 bytes"});
}

TEST(BadGltf, NanKeyframe) {
  const auto dir = test::freshDir("bad_nan");
  test::GltfBuilder b;
  const int n = b.node({{"name", "cam"}});
  b.channel(n, "translation", {0, 1}, {0, 0, 0, std::nanf(""), 0, 0});
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData,
              {"/animations/0/samplers/0/output", "NaN", "key 1"});
}

TEST(BadGltf, NonIncreasingTimes) {
  const auto dir = test::freshDir("bad_times");
  test::GltfBuilder b;
  const int n = b.node({{"name", "cam"}});
  b.channel(n, "translation", {0, 1, 1}, {0, 0, 0, 1, 0, 0, 2, 0, 0});
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData,
              {"/animations/0/samplers/0/input", "key time 2", "strictly increasing"});
}

TEST(BadGltf, UnknownRequiredExtension) {
  const auto dir = test::freshDir("bad_ext");
  auto b = animatedCamera();
  b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kUnsupported,
              {"/extensionsRequired/0", "KHR_draco_mesh_compression"});
  // The same extension merely used, not required, loads.
  b.doc.erase("extensionsRequired");
  EXPECT_TRUE(loadScene(b.write(dir, "scene")));
}

TEST(BadGltf, UriLeavingTheFolderIsRefusedUnread) {
  const auto dir = test::freshDir("bad_escape");
  fs::create_directories(dir / "dataset");
  auto b = animatedCamera();
  b.write(dir, "outside");  // a real buffer file next to the dataset folder, which must not be read
  nlohmann::json doc = b.doc;
  doc["buffers"] = {{{"byteLength", b.bin.size()}, {"uri", "../outside.bin"}}};
  std::ofstream(dir / "dataset/scene.gltf") << doc.dump();
  expectError(loadScene(dir / "dataset/scene.gltf"), ErrorCode::kInvalidData,
              {"/buffers/0/uri", "../outside.bin", "leaves the dataset's folder"});
  // Hidden behind a folder name and percent-encoding too.
  doc["buffers"][0]["uri"] = "sub/%2E%2E/%2E%2E/outside.bin";
  std::ofstream(dir / "dataset/scene.gltf") << doc.dump();
  expectError(loadScene(dir / "dataset/scene.gltf"), ErrorCode::kInvalidData, {"leaves the dataset's folder"});
  // Images as well.
  doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + test::base64(b.bin);
  doc["images"] = {{{"uri", "../outside.bin"}}};
  std::ofstream(dir / "dataset/scene.gltf") << doc.dump();
  expectError(loadScene(dir / "dataset/scene.gltf"), ErrorCode::kInvalidData, {"/images/0/uri", "leaves the dataset's folder"});
}

TEST(BadGltf, AbsolutePathAndUrl) {
  const auto dir = test::freshDir("bad_absolute");
  auto b = animatedCamera();
  b.write(dir, "real");
  nlohmann::json doc = b.doc;
  doc["buffers"] = {{{"byteLength", b.bin.size()}, {"uri", (dir / "real.bin").string()}}};
  std::ofstream(dir / "scene.gltf") << doc.dump();
  expectError(loadScene(dir / "scene.gltf"), ErrorCode::kInvalidData, {"/buffers/0/uri", "absolute path"});
  doc["buffers"][0]["uri"] = "file:///etc/passwd";
  std::ofstream(dir / "scene.gltf") << doc.dump();
  expectError(loadScene(dir / "scene.gltf"), ErrorCode::kInvalidData, {"/buffers/0/uri", "URL"});
}

TEST(BadGltf, JsonSyntaxErrorNamesLineAndColumn) {
  const auto dir = test::freshDir("bad_json");
  std::ofstream(dir / "scene.gltf") << "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [ {,} ]\n}\n";
  expectError(loadScene(dir / "scene.gltf"), ErrorCode::kParse, {"scene.gltf", "line 3, column"});
}

TEST(BadGltf, IndexOutOfRangeAndWrongTypes) {
  const auto dir = test::freshDir("bad_index");
  auto b = animatedCamera();
  b.doc["nodes"][0]["mesh"] = 4;
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData, {"/nodes/0/mesh", "mesh index 4 is out of range"});
  b = animatedCamera();
  b.doc["nodes"][0]["translation"] = {1, "two", 3};
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData, {"/nodes/0/translation/1", "expected a number"});
  b = animatedCamera();
  b.doc["nodes"][0]["children"] = {0};
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData, {"/nodes/0/children/0"});
  b = animatedCamera();
  b.doc["accessors"][0]["componentType"] = 5124;
  expectError(loadScene(b.write(dir, "scene")), ErrorCode::kInvalidData, {"/accessors/0/componentType"});
}

// Every truncation and a few thousand single-byte corruptions of a valid GLB: each load either
// succeeds or returns an error; none crashes (run under ASan/UBSan with the debug preset).
TEST(BadGltf, CorruptedGlbNeverCrashes) {
  const auto dir = test::freshDir("corrupt");
  auto b = animatedCamera();
  const auto glb = b.writeGlb(dir, "ok");
  std::string bytes;
  {
    std::ifstream in(glb, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path target = dir / "corrupt.glb";
  auto attempt = [&](const std::string& data) {
    std::ofstream(target, std::ios::binary | std::ios::trunc) << data;
    auto scene = loadScene(target);
    if (!scene) EXPECT_NE(scene.error().message.find("corrupt.glb"), std::string::npos) << scene.error().message;
  };
  for (std::size_t n = 0; n < bytes.size(); n += 3) attempt(bytes.substr(0, n));
  std::uint32_t state = 12345;  // fixed-seed LCG: the same corruptions every run
  for (int i = 0; i < 3000; ++i) {
    state = state * 1664525u + 1013904223u;
    std::string data = bytes;
    data[(state >> 8) % data.size()] = static_cast<char>(state >> 24);
    attempt(data);
  }
}

TEST(Gltf, EmbeddedExternalAndGlbAgree) {
  const auto dir = test::freshDir("three_ways");
  auto b = animatedCamera();
  auto external = loadScene(b.write(dir, "external", true));
  auto embedded = loadScene(b.write(dir, "embedded", false));
  auto glb = loadScene(b.writeGlb(dir, "binary"));
  ASSERT_TRUE(external && embedded && glb);
  EXPECT_EQ(external->source.format, "glTF");
  EXPECT_EQ(glb->source.format, "GLB");
  EXPECT_EQ(external->source.files.size(), 2u);
  EXPECT_EQ(embedded->source.files.size(), 1u);
  for (const Scene* s : {&*external, &*embedded, &*glb})
    EXPECT_EQ(s->animations[0].samplers[0].values, (std::vector<float>{0, 0, 0, 1, 0, 0, 2, 0, 0}));
}

}  // namespace
}  // namespace dynbench::scene
