// `dynbench convert` round trip: a capture written through the SDK, converted, checked by the
// Khronos validator, reloaded with dynbench's own loader and evaluated at the captured times.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "capture/check.h"
#include "capture/reader.h"
#include "capture_fixture.h"
#include "convert/convert.h"
#include "convert/sky.h"
#include "core/files.h"
#include "core/image_io.h"
#include "frames/frame_io.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "run_cli.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "scene/queries.h"

namespace dynbench::convert {
namespace {

namespace fs = std::filesystem;
using namespace dynbench::test;

glm::dmat4 matrix(const dbc_dual_quat& q) {
  return matrixOf(DualQuaternion{glm::dquat(q.rw, q.rx, q.ry, q.rz), glm::dquat(q.dw, q.dx, q.dy, q.dz)});
}

TEST(Convert, RoundTripMatchesTheCapture) {
  const Converted c = convertFixture("convert_roundtrip");
  int status = -1;
  const std::string validation = test::validateGltf(c.dataset, status);
  EXPECT_EQ(status, 0) << validation;
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;

  auto loaded = scene::loadScene(c.dataset);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const scene::Scene& s = *loaded;
  const scene::Evaluator e(s);
  // Thesis §5.1 layout.
  EXPECT_EQ(s.nodes[0].name, "WorldOrigo");
  EXPECT_EQ(s.nodes[static_cast<std::size_t>(s.nodes[0].children.at(0))].name, "StaticObjects");
  EXPECT_EQ(s.nodes[static_cast<std::size_t>(s.nodes[0].children.at(1))].name, "DynamicObjects");
  EXPECT_EQ(s.images.size(), 2u);  // arm.png and its mask, copied beside the dataset
  EXPECT_TRUE(fs::exists(c.dataset.parent_path() / "dataset_textures/chars/arm.png"));
  EXPECT_EQ(c.report.textures, 2u);

  const int camera = nodeNamed(s, "camera_1");
  const int arm = nodeNamed(s, "model_2_chars/arm");
  const int crate = nodeNamed(s, "model_3_mapmodel/crate:1");
  const int skinned = nodeNamed(s, "skinned_2");
  const int flash = nodeNamed(s, "light_6");
  ASSERT_TRUE(camera >= 0 && arm >= 0 && crate >= 0 && skinned >= 0 && flash >= 0);
  EXPECT_EQ(s.meshes.size(), 2u);  // defined once, shared by the static tree and the crate
  EXPECT_EQ(s.nodes[static_cast<std::size_t>(crate)].mesh, s.nodes[static_cast<std::size_t>(nodeNamed(s, "static_4_mapmodel/crate:1"))].mesh);

  for (int f = 0; f < 10; ++f) {
    const double t = static_cast<float>(f / 60.0);
    const std::string at = fmt::format("frame {}", f);
    // Camera: position and game-camera angles as captured.
    const RigidPose pose = decomposeRigid(e.worldMatrix(camera, t));
    expectClose(pose.position, {0, 1.7f, f}, at + " camera position");
    const auto euler = eulerYawPitchRoll(pose.rotation);
    EXPECT_NEAR(degrees(euler.yaw), 3.0 * f, 1e-4) << at;
    EXPECT_NEAR(degrees(euler.pitch), -5.0, 1e-4) << at;
    // The crate: absent in frames 4-6, otherwise where it was captured.
    const bool crateThere = f < 4 || f > 6;
    EXPECT_EQ(e.visible(crate, t), crateThere) << at;
    if (crateThere) {
      const glm::dmat4 expected = matrix(crateModelPose(f));
      const glm::dmat4 got = e.worldMatrix(crate, t);
      for (int col = 0; col < 4; ++col) expectClose(glm::dvec3(got[col]), glm::dvec3(expected[col]), at + " crate column");
    }
    // The flash: recorded in frames 2-3, kept 3 frames longer by the default light rules.
    EXPECT_EQ(e.ownVisibility(flash, t), f >= 2 && f <= 6) << at;
    // ... at its captured position (0.5, 1.5, f) while recorded, then held.
    if (f >= 2) expectClose(glm::dvec3(e.worldMatrix(flash, t)[3]), {0.5, 1.5, std::min(f, 3)}, at + " flash position");
    // ... with its captured brightness: 4 x 100 cd at full orange in frame 2, half in frame 3, then
    // held (KHR_animation_pointer on the light's colour and intensity).
    if (f >= 2) {
      const scene::Light light = e.light(s.nodes[static_cast<std::size_t>(flash)].light, t);
      EXPECT_NEAR(light.intensity, f == 2 ? 400.0 : 200.0, 1e-3) << at;
      expectClose(glm::dvec3(light.color), {1.0, 0.5, 0.0}, at + " flash colour");
    }
    // The camera cut at frame 7 (a respawn): between the keys of frames 6 and 7 only.
    if (f > 0) {
      const double previous = static_cast<float>((f - 1) / 60.0);
      EXPECT_EQ(scene::cameraCutBetween(s.nodes[static_cast<std::size_t>(camera)], previous, t), f == 7) << at;
    }
    // Skinned vertices: world = model transform x sum_k w_k J_k IBM_k v, from the capture's values.
    const auto world = e.worldPositions(skinned, 0, t);
    ASSERT_EQ(world.size(), 4u);
    const glm::dmat4 model = matrix(armModelPose(f));
    const glm::dmat4 ibm[2] = {matrix(rigid(0, {0, 0, 0})), matrix(rigid(0, {0, -1, 0}))};
    for (int v = 0; v < 4; ++v) {
      glm::dvec3 expected(0.0);
      const glm::dvec4 p(kArmPositions[3 * v], kArmPositions[3 * v + 1], kArmPositions[3 * v + 2], 1.0);
      for (int k = 0; k < 4; ++k) {
        const double w = kArmWeights[4 * v + k];
        if (w == 0) continue;
        const int joint = kArmJoints[4 * v + k];
        expected += w * glm::dvec3(model * matrix(armJointPose(f, joint)) * ibm[joint] * p);
      }
      expectClose(world[static_cast<std::size_t>(v)], expected, fmt::format("{} arm vertex {}", at, v));
    }
  }
  const auto& cuts = s.nodes[static_cast<std::size_t>(camera)].cuts;
  ASSERT_EQ(cuts.size(), 1u);
  EXPECT_EQ(cuts[0].reason, "respawn");
  EXPECT_DOUBLE_EQ(cuts[0].from, static_cast<float>(6 / 60.0));
  EXPECT_DOUBLE_EQ(cuts[0].time, static_cast<float>(7 / 60.0));
  // At 24 fps (frames at 0, 1/24, 2/24, ...) the jump from 0.1 s to 0.1167 s lies inside the pair
  // (2/24, 3/24]: that frame is the cut.
  EXPECT_TRUE(scene::cameraCutBetween(s.nodes[static_cast<std::size_t>(camera)], 2 / 24.0, 3 / 24.0));
  EXPECT_FALSE(scene::cameraCutBetween(s.nodes[static_cast<std::size_t>(camera)], 1 / 24.0, 2 / 24.0));
  // Between frames 4 and 7 the crate's scale-0 fallback hides it too.
  EXPECT_TRUE(scene::hasZeroScale(e.worldMatrix(crate, static_cast<float>(5 / 60.0))));
}

nlohmann::json readJson(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

TEST(Convert, EnvironmentSkyOrUserImage) {
  const Converted c = convertFixture("convert_env");
  const auto j = readJson(c.dataset);
  const auto& env = j["extensions"]["DYNBENCH_environment"];
  EXPECT_EQ(env["projection"], "equirectangular");
  EXPECT_EQ(env["units"], "cd/m2");
  const fs::path sky = c.dataset.parent_path() / env["uri"].get<std::string>();
  ASSERT_TRUE(fs::exists(sky));
  auto header = readImageHeader(sky);
  ASSERT_TRUE(header) << header.error().message;
  EXPECT_EQ(header->width, 2 * header->height);
  EXPECT_GT(env["sky"]["sun_illuminance_lux"].get<double>(), 10000.0);

  // The user's own environment is checked and copied beside the dataset.
  const fs::path mine = freshDir("convert_env_user") / "studio.hdr";
  ASSERT_TRUE(writeImage(mine, FloatImage{8, 4, 3, std::vector<float>(96, 2.0f)}));
  ConvertOptions options;
  options.environment = mine;
  const auto k = readJson(convertFixture("convert_env_user2", options).dataset);
  EXPECT_EQ(k["extensions"]["DYNBENCH_environment"]["uri"], "dataset_environment.hdr");
  EXPECT_EQ(k["extensions"]["DYNBENCH_environment"]["source"], "studio.hdr");
  // Not an image: a clear error, no dataset.
  std::ofstream(mine, std::ios::trunc) << "not an image";
  options.capture = writeCapture("convert_env_bad");
  options.output = freshDir("convert_env_bad_out") / "bad.gltf";
  auto bad = convertCapture(options);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("studio.hdr"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(fs::exists(options.output));
}

TEST(Convert, MaskMapBecomesMetallicRoughness) {
  const fs::path capture = writeCapture("convert_mask");
  const fs::path root = freshDir("convert_mask_data");
  fs::create_directories(root / "chars");
  std::ofstream(root / "chars/arm.png", std::ios::binary).write(reinterpret_cast<const char*>(kPng), sizeof kPng);
  // Two mask texels: full specular, half chrome; no specular, full chrome.
  ASSERT_TRUE(writeImage(root / "chars/arm_mask.png", FloatImage{2, 1, 3, {1.0f, 0.0f, 0.5f, 0.0f, 0.0f, 1.0f}}));
  ConvertOptions options;
  options.capture = capture;
  options.dataRoot = root;
  options.output = freshDir("convert_mask_out") / "masked.gltf";
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  const auto j = readJson(options.output);
  const auto& pbr = j["materials"][0]["pbrMetallicRoughness"];
  ASSERT_TRUE(pbr.contains("metallicRoughnessTexture"));
  EXPECT_EQ(pbr["roughnessFactor"], 1.0);
  const int texture = pbr["metallicRoughnessTexture"]["index"];
  const std::string uri = j["images"][j["textures"][texture]["source"].get<int>()]["uri"];
  auto mr = readImage(options.output.parent_path() / uri);
  ASSERT_TRUE(mr) << mr.error().message;
  ASSERT_EQ(mr->width, 2);
  // roughness (G) = 1 - 0.8 x specular; metallic (B) = chrome; 8-bit, so within 1/255.
  EXPECT_NEAR(mr->pixels[1], 0.2f, 1.0f / 255);
  EXPECT_NEAR(mr->pixels[2], 0.5f, 1.0f / 255);
  EXPECT_NEAR(mr->pixels[4], 1.0f, 1.0f / 255);
  EXPECT_NEAR(mr->pixels[5], 1.0f, 1.0f / 255);
  int status = -1;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_EQ(status, 0) << validation;
}

// A two-frame capture of a static map made of `meshes` (textures under dir/data), seen from above.
void captureStaticMeshes(const fs::path& dir, std::initializer_list<const dbc_mesh*> meshes) {
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open((dir / "capture").c_str(), "test", &s), DBC_OK);
  ASSERT_EQ(dbc_set_data_root(s, (dir / "data").c_str()), DBC_OK);
  ASSERT_EQ(dbc_model_begin(s, "map"), DBC_OK);
  for (const dbc_mesh* m : meshes) ASSERT_EQ(dbc_model_mesh(s, m), DBC_OK) << dbc_last_error();
  ASSERT_EQ(dbc_model_end(s), DBC_OK);
  const uint64_t camera = dbc_new_id(s), map = dbc_new_id(s);
  const float eye[] = {0.5f, 2, 0.5f};
  const dbc_dual_quat identity{0, 0, 0, 1, 0, 0, 0, 0};
  for (int f = 0; f < 2; ++f) {
    ASSERT_EQ(dbc_frame_begin(s, static_cast<uint64_t>(f), f / 60.0), DBC_OK);
    ASSERT_EQ(dbc_camera(s, camera, eye, -90, 0, 0), DBC_OK);
    if (f == 0) ASSERT_EQ(dbc_static_model(s, map, "map", identity), DBC_OK) << dbc_last_error();
    ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  }
  ASSERT_EQ(dbc_close(s), DBC_OK);
}

// A mesh's material beyond its maps (Cube 2's lava and water): base colour factor, metallic and
// roughness, emission in cd/m2 (E_u e / pi, docs/dataset.md) and vertex colours as COLOR_0 with
// alpha blending; the Khronos validator accepts it and dynbench's loader reads it back.
TEST(Convert, MaterialFactorsEmissionAndVertexColours) {
  const fs::path dir = freshDir("convert_materials");
  fs::create_directories(dir / "data");
  std::ofstream(dir / "data/lava.png", std::ios::binary).write(reinterpret_cast<const char*>(kPng), sizeof kPng);
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1}, uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
  const float normals[] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  const float colors[] = {1, 1, 1, 1, 0.5f, 0.5f, 0.5f, 0.25f, 1, 1, 1, 1, 1, 1, 1, 1};
  const float water[] = {0.1f, 0.2f, 0.3f, 1}, smooth[] = {0, 0.05f}, emission[] = {1.5f, 0.75f, 0};
  const uint32_t quad[] = {0, 1, 2, 0, 2, 3};
  dbc_mesh lava{};
  lava.name = "lava";
  lava.texture = lava.emission_texture = "lava.png";
  lava.vertex_count = 4;
  lava.positions = positions;
  lava.normals = normals;
  lava.uvs = uvs;
  lava.triangle_count = 2;
  lava.indices = quad;
  lava.emission = emission;
  dbc_mesh pool = lava;
  pool.mesh_id = 1;
  pool.name = "water";
  pool.texture = pool.emission_texture = nullptr;
  pool.emission = nullptr;
  pool.base_color = water;
  pool.metallic_roughness = smooth;
  dbc_mesh layer = pool;
  layer.mesh_id = 2;
  layer.name = "layer";
  layer.base_color = nullptr;
  layer.metallic_roughness = nullptr;
  layer.colors = colors;
  captureStaticMeshes(dir, {&lava, &pool, &layer});
  if (HasFatalFailure()) return;
  ConvertOptions options;
  options.capture = dir / "capture";
  options.output = dir / "out" / "materials.gltf";
  options.lightRules.luxPerUnit = 20000.0;
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  const auto j = readJson(options.output);
  ASSERT_EQ(j["materials"].size(), 3u);
  const auto& lavaMaterial = j["materials"][0];
  EXPECT_EQ(lavaMaterial["emissiveFactor"], nlohmann::json({1.0, 0.5, 0.0}));
  // Radiance E_u e / pi: strength E_u max(e) / pi.
  EXPECT_NEAR(lavaMaterial["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>(), 20000.0 * 1.5 / kPi, 1e-6);
  EXPECT_TRUE(lavaMaterial.contains("emissiveTexture"));
  EXPECT_FALSE(lavaMaterial.contains("alphaMode"));
  const auto& waterMaterial = j["materials"][1]["pbrMetallicRoughness"];
  EXPECT_NEAR(waterMaterial["baseColorFactor"][2].get<double>(), 0.3, 1e-6);
  EXPECT_NEAR(waterMaterial["roughnessFactor"].get<double>(), 0.05, 1e-6);
  EXPECT_EQ(waterMaterial["metallicFactor"].get<double>(), 0.0);
  EXPECT_EQ(j["materials"][2]["alphaMode"], "BLEND");  // a vertex alpha below 1
  const auto& used = j["extensionsUsed"];
  EXPECT_NE(std::find(used.begin(), used.end(), "KHR_materials_emissive_strength"), used.end());
  int status = -1;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_EQ(status, 0) << validation;
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;

  auto loaded = scene::loadScene(options.output);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const scene::Material& lavaLoaded = loaded->materials[0];
  EXPECT_NEAR(lavaLoaded.emissiveFactor.r, 20000.0 * 1.5 / kPi, 1e-2);  // factor x strength
  EXPECT_NEAR(lavaLoaded.emissiveFactor.g, 20000.0 * 0.75 / kPi, 1e-2);
  bool sawColours = false;
  for (const auto& mesh : loaded->meshes)
    for (const auto& prim : mesh.primitives)
      if (!prim.colors.empty()) {
        sawColours = true;
        ASSERT_EQ(prim.colors.size(), 4u);
        EXPECT_EQ(prim.colors[1], glm::vec4(0.5f, 0.5f, 0.5f, 0.25f));
        EXPECT_EQ(loaded->materials[static_cast<std::size_t>(prim.material)].alphaMode, scene::AlphaMode::kBlend);
      }
  EXPECT_TRUE(sawColours);
}

// OpenArena's light-emitting shaders (record m): the capture's emission is the surface's mean, in
// the light's colour, and the texture only shapes its level: the converter writes the texture's
// linear luminance as a grey emission map and divides the emission by that map's mean. A texture
// of a yellow and a black texel (sRGB (1, 1, 0) and 0: level Y = 0.9278 and 0, mean 0.4639) scales
// the emission by 1 / 0.4639 in every channel, blue included, so its hue is the light's; the old
// division channel by channel gave (3, 1.5, 0): no blue, another hue. The same mesh with record E
// keeps its emission and the texture itself.
TEST(Convert, AnEmissionMapThatOnlyShapesTheEmissionKeepsItsMean) {
  const fs::path dir = freshDir("convert_emission_mean");
  fs::create_directories(dir / "data");
  ASSERT_TRUE(writeImage(dir / "data/glow.png", FloatImage{2, 1, 3, {1, 1, 0, 0, 0, 0}, {}, {}, {}}));  // yellow, black
  const float positions[] = {0, 0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 1}, uvs[] = {0, 0, 1, 0, 1, 1, 0, 1};
  const float normals[] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, emission[] = {1.5f, 0.75f, 0.5f};
  const uint32_t quad[] = {0, 1, 2, 0, 2, 3};
  dbc_mesh shaped{};
  shaped.name = "shaped";
  shaped.texture = shaped.emission_texture = "glow.png";
  shaped.emission_texture_mean_one = 1;
  shaped.vertex_count = 4;
  shaped.positions = positions;
  shaped.normals = normals;
  shaped.uvs = uvs;
  shaped.triangle_count = 2;
  shaped.indices = quad;
  shaped.emission = emission;
  dbc_mesh multiplied = shaped;
  multiplied.mesh_id = 1;
  multiplied.name = "multiplied";
  multiplied.emission_texture_mean_one = 0;
  captureStaticMeshes(dir, {&shaped, &multiplied});
  if (HasFatalFailure()) return;
  std::string records;
  for (const auto& e : fs::recursive_directory_iterator(dir / "capture" / "models")) records += test::slurp(e.path());
  EXPECT_NE(records.find("m:0:glow.png"), std::string::npos) << records;
  EXPECT_NE(records.find("E:1:glow.png"), std::string::npos) << records;
  ConvertOptions options;
  options.capture = dir / "capture";
  options.output = dir / "out" / "emission.gltf";
  options.lightRules.luxPerUnit = 20000.0;
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  const auto j = readJson(options.output);
  ASSERT_EQ(j["materials"].size(), 2u);
  const auto& a = j["materials"][0];
  EXPECT_EQ(a["name"], "glow");
  ASSERT_TRUE(a.contains("emissiveTexture"));
  const auto uriOf = [&](const nlohmann::json& material) {
    return j["images"][j["textures"][material["emissiveTexture"]["index"].get<int>()]["source"].get<int>()]["uri"].get<std::string>();
  };
  // The level map: grey, the texels' luminance sRGB-encoded (Y 0.9278 -> 0.9688 -> byte 247; 0).
  const std::string levelUri = uriOf(a);
  EXPECT_TRUE(levelUri.ends_with("glow_emission_level.png")) << levelUri;
  auto level = readImage(options.output.parent_path() / levelUri);
  ASSERT_TRUE(level) << level.error().message;
  ASSERT_EQ(level->width, 2);
  const auto texel = [&](int x, int c) { return level->pixels[static_cast<std::size_t>(x * level->channels + c)]; };
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(texel(0, c), 247.0f / 255.0f, 1e-6) << c;
    EXPECT_EQ(texel(1, c), 0.0f) << c;
  }
  // mean level: byte 247 decoded over two texels; the emission keeps its hue (1.5, 0.75, 0.5)
  const double meanLevel = srgbToLinear(247.0 / 255.0) / 2.0;
  ASSERT_EQ(a["emissiveFactor"].size(), 3u);
  EXPECT_NEAR(a["emissiveFactor"][0].get<double>(), 1.0, 1e-6);
  EXPECT_NEAR(a["emissiveFactor"][1].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(a["emissiveFactor"][2].get<double>(), 0.5 / 1.5, 1e-6);
  EXPECT_NEAR(a["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>(), 20000.0 * 1.5 / meanLevel / kPi, 1e-2);
  const auto& b = j["materials"][1];
  EXPECT_EQ(uriOf(b), "emission_textures/glow.png");
  EXPECT_NEAR(b["emissiveFactor"][2].get<double>(), 0.5 / 1.5, 1e-6);
  EXPECT_NEAR(b["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>(), 20000.0 * 1.5 / kPi, 1e-3);
  int status = -1;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;
}

// Blender's own glTF importer reads the dataset (the thesis rendered its datasets with Blender).

TEST(Convert, BlenderImportsTheDataset) {
  DYNBENCH_NEEDS(test::missingBlender());
  const Converted c = convertFixture("convert_blender");
  const nlohmann::json summary = test::blenderImport(c.dataset);
  ASSERT_FALSE(summary.is_null());
  EXPECT_EQ(summary["result"], "FINISHED");
  EXPECT_EQ(summary["armatures"], 1);  // the arm
  EXPECT_EQ(summary["cameras"], 1);
  EXPECT_EQ(summary["lights"], 2);     // the lamp and the flash
  EXPECT_EQ(summary["meshes"], 3);     // static tree, crate, skinned arm
  EXPECT_GE(summary["actions"], 1);
}

TEST(Convert, GlbHoldsTheSameDataset) {
  ConvertOptions options;
  options.glb = true;
  const Converted c = convertFixture("convert_glb", options);
  int status = -1;
  const std::string validation = test::validateGltf(c.dataset, status);
  EXPECT_EQ(status, 0) << validation;
  auto loaded = scene::loadScene(c.dataset);
  ASSERT_TRUE(loaded) << loaded.error().message;
  EXPECT_EQ(loaded->source.format, "GLB");
  EXPECT_FALSE(fs::exists(c.dataset.parent_path() / "dataset.bin"));
  const scene::Evaluator e(*loaded);
  const RigidPose pose = decomposeRigid(e.worldMatrix(nodeNamed(*loaded, "camera_1"), static_cast<float>(7 / 60.0)));
  expectClose(pose.position, {0, 1.7f, 7}, "camera at frame 7");
}

TEST(Convert, VisibilityModes) {
  ConvertOptions node;
  node.visibility = VisibilityMode::kNode;
  const auto j = readJson(convertFixture("convert_vis_node", node).dataset);
  for (const auto& ch : j["animations"][0]["channels"]) EXPECT_NE(ch["target"]["path"], "scale");
  ConvertOptions scale;
  scale.visibility = VisibilityMode::kScale;
  const auto k = readJson(convertFixture("convert_vis_scale", scale).dataset);
  for (const auto& used : k["extensionsUsed"]) EXPECT_NE(used, "KHR_node_visibility");
  int scales = 0;
  for (const auto& ch : k["animations"][0]["channels"]) scales += ch["target"]["path"] == "scale";
  EXPECT_EQ(scales, 1);  // only the crate appears and disappears; lights never get a scale channel
}

TEST(Convert, LightRules) {
  const Converted c = convertFixture("convert_lights");
  const auto j = readJson(c.dataset);
  const auto& lights = j["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 2u);
  // Lamp: white (1, 1, 1) with a range of 40 units and a linear falloff: the flux of the engine's
  // light, I = E_u x 40^2 x 5/48, with E_u (lux of the engine's full light) the sky dome's
  // horizontal illuminance, as the fixture's capture has no map lighting. Flash: orange (1, 0.5, 0)
  // without a range, 100 cd per unit, amplified x4.
  const auto& calibration = j["extensions"]["DYNBENCH_environment"]["light_calibration"];
  EXPECT_EQ(calibration["source"], "sky dome = full light");
  const double lux = calibration["lux_per_unit"].get<double>();
  EXPECT_GT(lux, 5000.0);  // a clear sky's dome gives a horizontal surface some 10 klux
  EXPECT_LT(lux, 50000.0);
  EXPECT_NEAR(lights[0]["intensity"].get<double>(), lux * 1600.0 * 5.0 / 48.0, 1e-9 * lux * 1600.0);
  EXPECT_EQ(lights[0]["range"], 40.0);
  EXPECT_FALSE(lights[1].contains("range"));
  EXPECT_DOUBLE_EQ(lights[1]["intensity"].get<double>(), 400.0);
  EXPECT_EQ(lights[1]["color"], nlohmann::json({1.0, 0.5, 0.0}));

  const fs::path rules = freshDir("convert_rules") / "rules.json";
  std::ofstream(rules) << R"({"candela_per_unit": 10, "types": {"flash": {"ring_lights": 6, "ring_radius_m": 2}}})";
  auto parsed = readLightRules(rules);
  ASSERT_TRUE(parsed) << parsed.error().message;
  Expected<LightRules> bad = parsed;
  ConvertOptions options;
  options.lightRules = *parsed;
  const auto k = readJson(convertFixture("convert_lights_ring", options).dataset);
  const auto& ring = k["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(ring.size(), 2u);
  EXPECT_NEAR(ring[1]["intensity"].get<double>(), 10.0 / 6, 1e-12);  // six lights share the flash
  int ringNodes = 0;
  for (const auto& n : k["nodes"])
    if (n.value("name", "") == "light_6_ring") {
      ++ringNodes;
      EXPECT_NEAR(glm::length(glm::dvec3(n["translation"][0], n["translation"][1], n["translation"][2])), 2.0, 1e-6);
    }
  EXPECT_EQ(ringNodes, 6);

  // lux_per_unit set by hand: the lamp's candela follow from it alone.
  std::ofstream(rules, std::ios::trunc) << R"({"lux_per_unit": 3})";
  parsed = readLightRules(rules);
  ASSERT_TRUE(parsed) << parsed.error().message;
  options.lightRules = *parsed;
  const auto byHand = readJson(convertFixture("convert_lights_lux", options).dataset);
  EXPECT_NEAR(byHand["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"].get<double>(), 500.0, 1e-9);
  std::ofstream(rules, std::ios::trunc) << R"({"lux_per_unit": 0})";
  bad = readLightRules(rules);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("/lux_per_unit"), std::string::npos) << bad.error().message;

  std::ofstream(rules, std::ios::trunc) << R"({"types": {"flash": {"extra_frames": -1}}})";
  bad = readLightRules(rules);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("/types/flash/extra_frames"), std::string::npos) << bad.error().message;
  std::ofstream(rules, std::ios::trunc) << R"({"typo": 1})";
  bad = readLightRules(rules);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("/typo"), std::string::npos) << bad.error().message;
}

TEST(Convert, NegativeLightColoursBecomeZero) {
  // Cube 2's darkening lights have negative channels; KHR_lights_punctual colours are in [0, 1].
  const fs::path dir = freshDir("convert_negative_light");
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open((dir / "capture").c_str(), "test", &s), DBC_OK);
  const uint64_t camera = dbc_new_id(s), lamp = dbc_new_id(s);
  const float origin[3] = {0, 0, 0}, rgb[3] = {-0.2f, 0.5f, 1.0f};
  for (int f = 0; f < 2; ++f) {
    ASSERT_EQ(dbc_frame_begin(s, static_cast<uint64_t>(f), f / 60.0), DBC_OK);
    ASSERT_EQ(dbc_camera(s, camera, origin, 0, 0, 0), DBC_OK);
    ASSERT_EQ(dbc_light(s, lamp, origin, rgb, 0.0f, DBC_FALLOFF_LINEAR, DBC_LIGHT_POINT, 1, "explosion"), DBC_OK);
    ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  }
  ASSERT_EQ(dbc_close(s), DBC_OK);
  ConvertOptions options;
  options.capture = dir / "capture";
  options.output = dir / "out" / "neg.gltf";
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  const auto j = readJson(dir / "out" / "neg.gltf");
  const auto& light = j["extensions"]["KHR_lights_punctual"]["lights"][0];
  EXPECT_EQ(light["color"], nlohmann::json({0.0, 0.5, 1.0}));
  EXPECT_DOUBLE_EQ(light["intensity"].get<double>(), 100.0);
  int status = 0;
  const std::string validation = test::validateGltf(dir / "out" / "neg.gltf", status);
  EXPECT_EQ(status, 0) << validation;
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;
}

// A one-frame capture of a map's lighting (a sun from elevation 30 degrees, azimuth 0, of colour
// `sun`; the ambient floor; the sky light) and one static point light at the origin, converted:
// the dataset's path, or empty after a test failure.
struct OneLight {
  glm::vec3 sun{0.0f}, ambient{0.0f}, sky{0.0f}, colour{1.0f};
  float range = 20.0f;
  dbc_light_falloff falloff = DBC_FALLOFF_QUADRATIC;
  const char* type = "none";
};
fs::path convertOneLight(const fs::path& dir, const OneLight& l) {
  dbc_session* s = nullptr;
  const fs::path failed;
  if (dbc_open((dir / "capture").c_str(), "test", &s) != DBC_OK) return ADD_FAILURE() << dbc_last_error(), failed;
  const float towardsSun[3] = {0.0f, 0.5f, -static_cast<float>(std::sqrt(3.0) / 2)};
  const uint64_t camera = dbc_new_id(s), lamp = dbc_new_id(s);
  const float origin[3] = {0, 0, 0};
  const bool ok = dbc_set_lighting(s, towardsSun, &l.sun.x, &l.ambient.x, &l.sky.x) == DBC_OK && dbc_frame_begin(s, 0, 0.0) == DBC_OK &&
                  dbc_camera(s, camera, origin, 0, 0, 0) == DBC_OK &&
                  dbc_light(s, lamp, origin, &l.colour.x, l.range, l.falloff, DBC_LIGHT_POINT, 0, l.type) == DBC_OK &&
                  dbc_frame_end(s) == DBC_OK && dbc_close(s) == DBC_OK;
  if (!ok) return ADD_FAILURE() << dbc_last_error(), failed;
  ConvertOptions options;
  options.capture = dir / "capture";
  options.output = dir / "out" / "map.gltf";
  auto report = convertCapture(options);
  if (!report) return ADD_FAILURE() << report.error().message, failed;
  return options.output;
}

TEST(Convert, TheMapsSunPlacesTheSkysSunAndCalibratesTheLights) {
  // A map lit by a sun of engine colour 0.5 from elevation 30 degrees: the generated sky's sun
  // stands there, and a light of colour 1 and radius R gets I = (E_sun / 0.5) x R^2 x k, k = 1/6
  // for a quadratic falloff. A map without a sun gets a sky without a sun disc.
  for (const bool sun : {true, false}) {
    OneLight l;
    if (sun) l.sun = {0.5f, 0.5f, 0.4f};
    l.ambient = glm::vec3(0.1f);
    l.sky = glm::vec3(0.4f);
    const fs::path dataset = convertOneLight(freshDir(sun ? "convert_map_sun" : "convert_map_no_sun"), l);
    ASSERT_FALSE(dataset.empty());
    const auto j = readJson(dataset);
    const auto& env = j["extensions"]["DYNBENCH_environment"];
    const double intensity = j["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"].get<double>();
    if (sun) {
      EXPECT_NEAR(env["sky"]["sun_elevation_degrees"].get<double>(), 30.0, 1e-4);
      EXPECT_NEAR(env["sky"]["sun_azimuth_degrees"].get<double>(), 0.0, 1e-4);
      const double sunLux = env["sky"]["sun_illuminance_lux"].get<double>();
      EXPECT_GT(sunLux, 50000.0);
      EXPECT_EQ(env["light_calibration"]["source"], "map sun");
      EXPECT_NEAR(intensity, sunLux / 0.5 * 400.0 / 6.0, 1e-3 * intensity);
    } else {
      EXPECT_EQ(env["sky"]["sun_disc"], false);
      EXPECT_EQ(env["sky"]["sun_illuminance_lux"], 0.0);
      EXPECT_EQ(env["light_calibration"]["source"], "map sky light");
      const double dome = env["light_calibration"]["sky_dome_lux"].get<double>();
      EXPECT_NEAR(intensity, dome / 0.4 * 400.0 / 6.0, 1e-3 * intensity);
    }
    int status = 0;
    const std::string validation = test::validateGltf(dataset, status);
    EXPECT_EQ(status, 0) << validation;
    EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;
  }
}

// A map light of colour (2, 1, 0.5) and `falloff`, `range`, in a map lit by a sun of engine colour
// 0.5, converted (the capture's record checked for `token`, the dataset by the glTF validator):
// the dataset's light and the sky's sun illuminance.
std::pair<nlohmann::json, double> convertMapLight(dbc_light_falloff falloff, float range, const std::string& token, const std::string& name) {
  OneLight l;
  l.sun = glm::vec3(0.5f);
  l.colour = {2.0f, 1.0f, 0.5f};
  l.range = range;
  l.falloff = falloff;
  l.type = "maplight";
  const fs::path dir = freshDir(name);
  const fs::path dataset = convertOneLight(dir, l);
  EXPECT_FALSE(dataset.empty());
  if (dataset.empty()) return {nlohmann::json::object(), 0.0};
  EXPECT_NE(test::slurp(dir / "capture" / "Capture.txt").find(token), std::string::npos);
  const auto j = readJson(dataset);
  int status = 0;
  const std::string validation = test::validateGltf(dataset, status);
  EXPECT_EQ(status, 0) << validation;
  return {j["extensions"]["KHR_lights_punctual"]["lights"][0], j["extensions"]["DYNBENCH_environment"]["sky"]["sun_illuminance_lux"].get<double>()};
}

TEST(Convert, AnInverseSquareLightGivesItsColourAtItsRange) {
  // id Tech 3's map lights (maplight): colour c x (R / d)^2, no end. In a map lit by a sun of
  // engine colour 0.5, E_u = E_sun / 0.5 and the light is a point light without a range of
  // I = E_u x peak(c) x R^2 cd: at d = R it gives E_u x c, the engine's light of colour c.
  const auto [light, sunLux] = convertMapLight(DBC_FALLOFF_INVERSE_SQUARE, 30.0f, ":30:inverse_square:point:0:maplight", "convert_inverse_square");
  EXPECT_FALSE(light.contains("range"));
  EXPECT_EQ(light["color"], nlohmann::json({1.0, 0.5, 0.25}));
  EXPECT_NEAR(light["intensity"].get<double>(), sunLux / 0.5 * 2.0 * 900.0, 1e-3 * light["intensity"].get<double>());
}

// A windowed inverse-square light (id Tech 3's map lights ended at q3map2's envelope) is KHR's point
// light with that range: I = E_u max(c) R^2 as for the inverse square (its light at d < R is then
// E_u c (R/d)^2 before the window, the capture's), and the range kept.
TEST(Convert, AWindowedInverseSquareLightKeepsItsRange) {
  const auto [light, sunLux] = convertMapLight(DBC_FALLOFF_WINDOWED_INVERSE_SQUARE, 240.0f, ":240:windowed_inverse_square:point:0:maplight",
                                               "convert_windowed_inverse_square");
  EXPECT_EQ(light["range"].get<double>(), 240.0);
  EXPECT_EQ(light["color"], nlohmann::json({1.0, 0.5, 0.25}));
  EXPECT_NEAR(light["intensity"].get<double>(), sunLux / 0.5 * 2.0 * 240.0 * 240.0, 1e-3 * light["intensity"].get<double>());
}

// An engine that records its lighting with neither a sky light nor an ambient floor (id Tech 3 with
// dynbench's map lights) says its sky gives no light but its sun: the dataset's sky is black but
// the sun disc (all of the sky's light on a horizontal surface comes from the disc, as much as
// before), and black without a sun, the lights calibrated as before (E_u = E_dome).
TEST(Convert, ASkyThatGivesNoLightButItsSunHasNoDome) {
  for (const bool sun : {true, false}) {
    OneLight l;
    if (sun) l.sun = glm::vec3(0.5f);
    l.range = 30.0f;
    l.falloff = DBC_FALLOFF_INVERSE_SQUARE;
    l.type = "maplight";
    const fs::path dataset = convertOneLight(freshDir(sun ? "convert_dark_sky_sun" : "convert_dark_sky"), l);
    ASSERT_FALSE(dataset.empty());
    const auto j = readJson(dataset);
    const auto& env = j["extensions"]["DYNBENCH_environment"];
    EXPECT_EQ(env["light_calibration"]["source"], sun ? "map sun" : "sky dome = full light") << env;
    EXPECT_TRUE(env["light_calibration"].contains("sky_dome")) << env;
    auto image = readImage(dataset.parent_path() / env["uri"].get<std::string>());
    ASSERT_TRUE(image) << image.error().message;
    std::vector<float> rgb(static_cast<std::size_t>(image->width) * image->height * 3);
    for (std::size_t i = 0; i < rgb.size() / 3; ++i)
      for (int c = 0; c < 3; ++c) rgb[3 * i + c] = image->pixels[i * static_cast<std::size_t>(image->channels) + c];
    // the dome gives nothing: a horizontal surface gets light only from within 2 degrees of the sun
    const double towards = horizontalIlluminance(rgb, image->width, image->height);
    const glm::dvec3 sunDirection(0.0, 0.5, -std::sqrt(3.0) / 2);
    EXPECT_EQ(horizontalIlluminance(rgb, image->width, image->height, sunDirection, radians(2.0)), 0.0);
    const double lux = env["light_calibration"]["lux_per_unit"].get<double>();
    const double intensity = j["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"].get<double>();
    EXPECT_NEAR(intensity, lux * 900.0, 1e-6 * intensity);
    if (sun) {
      const double sunLux = env["sky"]["sun_illuminance_lux"].get<double>();
      EXPECT_EQ(env["sky"]["model"], "ESRA sun disc alone, no sky dome");
      EXPECT_NEAR(lux, sunLux / 0.5, 1e-6 * lux);
      EXPECT_NEAR(towards, sunLux * 0.5, 0.02 * sunLux);  // the disc at 30 degrees' elevation: E_sun sin 30
    } else {
      EXPECT_EQ(env["sky"]["model"], "black: no sky dome, no sun");
      EXPECT_EQ(towards, 0.0);
      EXPECT_GT(lux, 5000.0);  // the daylight dome's illuminance still calibrates the lights
    }
  }
}

TEST(Convert, AStaticLightTheEngineDoesNotAttenuateGetsItsIrradianceAtTheMapsCentre) {
  // Cube 2 lights a surface with a light of radius 0 at its full colour however far away it is
  // (colos's "sun"). A map of two triangles spanning x, z in [-10, 10] at y = 0 (offset by the map
  // offset), a static light of colour 0.5 without a range 50 units from the map's centre: a point
  // light (its shadows fall as the engine's) of E_u x 0.5 x 50^2 cd, so that the centre gets the
  // engine's irradiance. The map has no sun and no sky light, only an ambient floor of 0.25: the
  // sky dome stands for it, E_u = E_dome / 0.25. A dynamic light without a range keeps the candela
  // rule.
  const fs::path dir = freshDir("convert_constant_light");
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open((dir / "capture").c_str(), "test", &s), DBC_OK);
  const float offset[3] = {5, 0, -5};
  ASSERT_EQ(dbc_set_map(s, "flat", offset), DBC_OK);
  const float towardsSun[3] = {0, 1, 0}, none[3] = {0, 0, 0}, ambient[3] = {0.25f, 0.2f, 0.2f};
  ASSERT_EQ(dbc_set_lighting(s, towardsSun, none, ambient, none), DBC_OK) << dbc_last_error();
  const float positions[] = {-10, 0, -10, 10, 0, -10, 10, 0, 10, -10, 0, 10};
  const uint32_t quad[] = {0, 2, 1, 0, 3, 2};
  ASSERT_EQ(dbc_model_begin(s, "flat"), DBC_OK);
  const dbc_mesh floor{0, nullptr, nullptr, nullptr, 4, positions, nullptr, nullptr, nullptr, nullptr, 2, quad};
  ASSERT_EQ(dbc_model_mesh(s, &floor), DBC_OK) << dbc_last_error();
  ASSERT_EQ(dbc_model_end(s), DBC_OK);
  const uint64_t camera = dbc_new_id(s), sun = dbc_new_id(s), flash = dbc_new_id(s);
  const float origin[3] = {0, 2, 0}, sunAt[3] = {5, 30, 35}, grey[3] = {0.5f, 0.5f, 0.5f};
  ASSERT_EQ(dbc_frame_begin(s, 0, 0.0), DBC_OK);
  ASSERT_EQ(dbc_camera(s, camera, origin, 0, 0, 0), DBC_OK);
  ASSERT_EQ(dbc_light(s, sun, sunAt, grey, 0.0f, DBC_FALLOFF_LINEAR, DBC_LIGHT_POINT, 0, "none"), DBC_OK);
  ASSERT_EQ(dbc_light(s, flash, origin, grey, 0.0f, DBC_FALLOFF_LINEAR, DBC_LIGHT_POINT, 1, "none"), DBC_OK);
  ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  ASSERT_EQ(dbc_close(s), DBC_OK);
  ConvertOptions options;
  options.capture = dir / "capture";
  options.output = dir / "out" / "flat.gltf";
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  const auto j = readJson(options.output);
  const auto& calibration = j["extensions"]["DYNBENCH_environment"]["light_calibration"];
  EXPECT_EQ(calibration["source"], "map ambient");
  const double dome = calibration["sky_dome_lux"].get<double>();
  const double lux = calibration["lux_per_unit"].get<double>();
  EXPECT_NEAR(lux, dome / 0.25, 1e-6 * lux);
  const auto& lights = j["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 2u);
  EXPECT_EQ(lights[0]["type"], "point");
  EXPECT_NEAR(lights[0]["intensity"].get<double>(), lux * 0.5 * 2500.0, 1e-6 * lux * 2500.0);
  EXPECT_FALSE(lights[0].contains("range"));
  EXPECT_EQ(lights[1]["type"], "point");
  EXPECT_DOUBLE_EQ(lights[1]["intensity"].get<double>(), 50.0);
  int status = 0;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_EQ(status, 0) << validation;
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;
}

TEST(Convert, TruncatedCaptureKeepsCompleteFrames) {
  const fs::path capture = writeCapture("convert_truncated");
  // Cut Capture.txt inside frame 109 (the last): keep everything before its end record.
  std::ifstream in(capture / "Capture.txt");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  text = text.substr(0, text.rfind("e:109")) ;
  std::ofstream(capture / "Capture.txt", std::ios::trunc) << text;
  ConvertOptions options;
  options.capture = capture;
  options.output = freshDir("convert_truncated_out") / "cut.gltf";
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->frames, 9u);
  bool warned = false;
  for (const auto& w : report->warnings) warned |= w.find("frame 109 has no end record") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(ConvertCli, WritesDatasetAndRejectsBadArguments) {
  const fs::path capture = writeCapture("convert_cli");
  const fs::path out = freshDir("convert_cli_out");
  auto r = dynbench(fmt::format("convert {} -o {}", capture.string(), (out / "d.gltf").string()), out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("10 frames"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out / "d.gltf") && fs::exists(out / "d.bin") && fs::exists(out / "d.README.md"));
  std::ifstream readme(out / "d.README.md");
  const std::string text((std::istreambuf_iterator<char>(readme)), {});
  EXPECT_NE(text.find("dynbench tests"), std::string::npos);  // the capture's source
  EXPECT_NE(text.find("Licences"), std::string::npos);
  r = dynbench(fmt::format("convert {} -o {}", capture.string(), (out / "d.obj").string()), out);
  EXPECT_EQ(r.status, 2);
  r = dynbench(fmt::format("convert {} -o {} --visibility sometimes", capture.string(), (out / "e.gltf").string()), out);
  EXPECT_NE(r.status, 0);
  EXPECT_FALSE(fs::exists(out / "e.gltf"));
  std::ofstream(capture / "Capture.txt", std::ios::app) << "garbage\n";
  r = dynbench(fmt::format("convert {} -o {}", capture.string(), (out / "f.gltf").string()), out);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("Capture.txt:"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "f.gltf"));
  EXPECT_FALSE(fs::exists(out / "f.bin"));
}

// A vertex-animated model through the SDK (dbc_model_mesh_frames, dbc_vertex_frames): a "flag" of
// two meshes, a quad with 3 key frames (key frame k: the base raised by k units in y) and a
// triangle without key frames, seen over 9 frames at 24 fps stepping a quarter key frame a frame.
fs::path writeVertexAnimatedCapture(const std::string& name, uint64_t& flagId) {
  const fs::path dir = freshDir(name);
  dbc_session* s = nullptr;
  EXPECT_EQ(dbc_open(dir.c_str(), "vertex animation test", &s), DBC_OK) << dbc_last_error();
  EXPECT_EQ(dbc_set_camera_settings(s, 16.0f / 9, 60, 0.1f, 100), DBC_OK);
  EXPECT_EQ(dbc_model_begin(s, "models/flag"), DBC_OK);
  const float quad[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, normals[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const uint32_t quadIndices[6] = {0, 1, 2, 0, 2, 3};
  dbc_mesh mesh{0, "cloth", nullptr, nullptr, 4, quad, normals, nullptr, nullptr, nullptr, 2, quadIndices};
  EXPECT_EQ(dbc_model_mesh(s, &mesh), DBC_OK) << dbc_last_error();
  float keys[3 * 12], keyNormals[3 * 12];
  for (int k = 0; k < 3; ++k)
    for (int v = 0; v < 4; ++v)
      for (int c = 0; c < 3; ++c) {
        keys[(k * 4 + v) * 3 + c] = quad[v * 3 + c] + (c == 1 ? static_cast<float>(k) : 0.0f);
        keyNormals[(k * 4 + v) * 3 + c] = normals[v * 3 + c];
      }
  EXPECT_EQ(dbc_model_mesh_frames(s, 0, 3, keys, keyNormals), DBC_OK) << dbc_last_error();
  const float tri[9] = {0, 0, 1, 1, 0, 1, 0, 1, 1};
  const uint32_t triIndices[3] = {0, 1, 2};
  dbc_mesh pole{1, "pole", nullptr, nullptr, 3, tri, nullptr, nullptr, nullptr, nullptr, 1, triIndices};
  EXPECT_EQ(dbc_model_mesh(s, &pole), DBC_OK) << dbc_last_error();
  EXPECT_EQ(dbc_model_end(s), DBC_OK) << dbc_last_error();
  const uint64_t camera = dbc_new_id(s);
  flagId = dbc_new_id(s);
  for (int f = 0; f < 9; ++f) {
    EXPECT_EQ(dbc_frame_begin(s, static_cast<uint64_t>(f), f / 24.0), DBC_OK);
    const float eye[3] = {0.5f, 1.0f, 6.0f};
    EXPECT_EQ(dbc_camera(s, camera, eye, 0, 0, 0), DBC_OK);
    EXPECT_EQ(dbc_model(s, flagId, "models/flag", toC(DualQuaternion{})), DBC_OK);
    const uint32_t from = static_cast<uint32_t>(f / 4), to = std::min<uint32_t>(from + 1, 2);
    EXPECT_EQ(dbc_vertex_frames(s, flagId, "models/flag", from, to, static_cast<float>(f % 4) / 4), DBC_OK) << dbc_last_error();
    EXPECT_EQ(dbc_frame_end(s), DBC_OK);
  }
  EXPECT_EQ(dbc_close(s), DBC_OK);
  return dir;
}

// The highest world-space y the renderer's P buffer hits in frame `frame` of `dataset` at 64x36,
// and how many pixels hit.
struct RenderedTop {
  double y = -1e9;
  std::size_t hits = 0;
};
RenderedTop renderedTop(const fs::path& dataset, const std::string& engine, long frame) {
  const fs::path frames = freshDir(fmt::format("{}_{}_{}", dataset.stem().string(), engine, frame));
  std::string out;
  if (runShell(fmt::format("{} render '{}' -o '{}' --res 64x36 --spp 1 --frames {} --engine {} 2>&1", DYNBENCH_EXE, dataset.string(),
                           frames.string(), frame, engine), out) != 0) {
    ADD_FAILURE() << out;
    return {};
  }
  auto read = frames::readFrame({frame, frames::frameImagePath(frames, frame), frames::frameSidecarPath(frames, frame)});
  if (!read) {
    ADD_FAILURE() << read.error().message;
    return {};
  }
  RenderedTop top;
  for (std::size_t i = 0; i < read->pixelCount(); ++i)
    if (read->hit.empty() ? glm::length(glm::vec3(read->position[3 * i], read->position[3 * i + 1], read->position[3 * i + 2])) > 0 : read->hit[i] > 0)
      top.y = std::max(top.y, static_cast<double>(read->position[3 * i + 1])), ++top.hits;
  return top;
}

TEST(Convert, VertexAnimationBecomesMorphTargetsWithAnimatedWeights) {
  uint64_t flag = 0;
  const fs::path capture = writeVertexAnimatedCapture("vertex_animation_capture", flag);
  auto summary = capture::checkCapture(capture);
  ASSERT_TRUE(summary) << summary.error().message;
  EXPECT_EQ(summary->vertexAnimatedModels, 1u);
  EXPECT_EQ(summary->rigidModels, 0u);
  EXPECT_EQ(summary->vertexAnimatedModelFiles, 1u);
  EXPECT_EQ(summary->keyFrames, 3u);
  EXPECT_EQ(summary->vertexFrameRecords, 9u);
  ConvertOptions options;
  options.capture = capture;
  options.output = freshDir("vertex_animation_out") / "flag.gltf";
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->morphTargets, 3u);
  int status = -1;
  const std::string validation = test::validateGltf(options.output, status);
  EXPECT_EQ(status, 0) << validation;
  auto loaded = scene::loadScene(options.output);
  ASSERT_TRUE(loaded) << loaded.error().message;
  const scene::Evaluator e(*loaded);
  const int node = nodeNamed(*loaded, fmt::format("model_{}_models/flag", flag));
  ASSERT_GE(node, 0);
  // Frame f is key frame f / 4 (a quarter a frame): every quad vertex raised by f / 4; the pole
  // (zero targets) stays.
  for (int f = 0; f < 9; ++f) {
    const std::vector<glm::dvec3> quad = e.worldPositions(node, 0, f / 24.0), pole = e.worldPositions(node, 1, f / 24.0);
    ASSERT_EQ(quad.size(), 4u);
    expectClose(quad[2], {1, 1 + f / 4.0, 0}, fmt::format("quad vertex 2 at frame {}", f));
    expectClose(quad[0], {0, f / 4.0, 0}, fmt::format("quad vertex 0 at frame {}", f));
    expectClose(pole[2], {0, 1, 1}, fmt::format("pole vertex 2 at frame {}", f));
  }
  // Between frames the weights interpolate linearly: halfway between frames 5 and 6, 1.375.
  expectClose(e.worldPositions(node, 0, 5.5 / 24.0)[0], {0, 1.375, 0}, "halfway between frames 5 and 6");
  // The renderer draws the morphed quad: at frame 8 (key frame 2, raised by 2) the highest point
  // it hits is above y = 2, where at frame 0 nothing is above y = 1.
  for (const auto& [frame, low, high] : {std::tuple{0L, 0.5, 1.0}, std::tuple{8L, 2.5, 3.0}}) {
    const RenderedTop top = renderedTop(options.output, "embree", frame);
    EXPECT_GT(top.y, low) << "frame " << frame;
    EXPECT_LE(top.y, high + 1e-4) << "frame " << frame;
  }
}

TEST(Convert, BlenderImportsTheMorphTargetsAsShapeKeys) {
  DYNBENCH_NEEDS(test::missingBlender());
  uint64_t flag = 0;
  ConvertOptions options;
  options.capture = writeVertexAnimatedCapture("vertex_animation_blender_capture", flag);
  options.output = freshDir("vertex_animation_blender_out") / "flag.gltf";
  auto report = convertCapture(options);
  ASSERT_TRUE(report) << report.error().message;
  const nlohmann::json summary = test::blenderImport(options.output);
  ASSERT_FALSE(summary.is_null());
  EXPECT_EQ(summary["result"], "FINISHED");
  EXPECT_EQ(summary["meshes"], 1);      // the flag (its two primitives in one mesh)
  EXPECT_EQ(summary["shape_keys"], 3);  // one per key frame, as convert reports
  EXPECT_EQ(summary["shape_keys"], report->morphTargets);
  // Cycles (through that import) draws the morphed quad where dynbench's renderer does.
  const RenderedTop embree = renderedTop(options.output, "embree", 8), cycles = renderedTop(options.output, "cycles", 8);
  EXPECT_GT(cycles.y, 2.5);
  EXPECT_NEAR(cycles.y, embree.y, 1e-3);
  EXPECT_EQ(cycles.hits, embree.hits);
}

TEST(Capture, VertexAnimationIsCheckedBySdkAndReader) {
  const fs::path dir = freshDir("vertex_animation_bad");
  dbc_session* s = nullptr;
  ASSERT_EQ(dbc_open(dir.c_str(), "bad", &s), DBC_OK);
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, keys[18] = {};
  const uint32_t idx[3] = {0, 1, 2};
  dbc_mesh mesh{0, "m", nullptr, nullptr, 3, p, nullptr, nullptr, nullptr, nullptr, 1, idx};
  EXPECT_EQ(dbc_model_mesh_frames(s, 0, 2, keys, nullptr), DBC_ERROR_ORDER);  // outside a model
  ASSERT_EQ(dbc_model_begin(s, "models/m"), DBC_OK);
  ASSERT_EQ(dbc_model_mesh(s, &mesh), DBC_OK);
  EXPECT_EQ(dbc_model_mesh_frames(s, 1, 2, keys, nullptr), DBC_ERROR_ORDER);  // not the last mesh
  EXPECT_EQ(dbc_model_mesh_frames(s, 0, 0, keys, nullptr), DBC_ERROR_ARGUMENT);
  ASSERT_EQ(dbc_model_mesh_frames(s, 0, 2, keys, nullptr), DBC_OK) << dbc_last_error();
  EXPECT_EQ(dbc_model_mesh_frames(s, 0, 2, keys, nullptr), DBC_ERROR_ORDER);  // twice
  EXPECT_EQ(dbc_model_joint(s, 0, "j", -1, toC(DualQuaternion{}), toC(DualQuaternion{})), DBC_ERROR_ARGUMENT);  // joints and key frames
  ASSERT_EQ(dbc_model_end(s), DBC_OK);
  const uint64_t id = dbc_new_id(s);
  ASSERT_EQ(dbc_frame_begin(s, 0, 0.0), DBC_OK);
  EXPECT_EQ(dbc_vertex_frames(s, id, "models/m", 0, 1, 0.5f), DBC_ERROR_ORDER);  // before its dbc_model
  ASSERT_EQ(dbc_model(s, id, "models/m", toC(DualQuaternion{})), DBC_OK);
  EXPECT_EQ(dbc_vertex_frames(s, id, "models/m", 0, 2, 0.5f), DBC_ERROR_ARGUMENT);  // key frame 2 of 2
  EXPECT_EQ(dbc_vertex_frames(s, id, "models/m", 0, 1, 1.5f), DBC_ERROR_ARGUMENT);
  EXPECT_NE(std::string(dbc_last_error()).find("fraction"), std::string::npos);
  EXPECT_EQ(dbc_vertex_frames(s, id, "models/m", 1, 0, 0.25f), DBC_OK) << dbc_last_error();
  ASSERT_EQ(dbc_frame_end(s), DBC_OK);
  ASSERT_EQ(dbc_close(s), DBC_OK);
  auto reader = capture::CaptureReader::open(dir);
  ASSERT_TRUE(reader) << reader.error().message;
  ASSERT_EQ((*reader)->models().size(), 1u);
  EXPECT_EQ((*reader)->models()[0].keyFrames, 2u);
  capture::CaptureFrame frame;
  ASSERT_TRUE((*reader)->next(frame).value_or(false));
  ASSERT_EQ(frame.vertexFrames.size(), 1u);
  EXPECT_EQ(frame.vertexFrames[0].from, 1u);
  EXPECT_DOUBLE_EQ(frame.vertexFrames[0].fraction, 0.25);
  // The reader refuses what the SDK would not write, naming file:line.
  auto capture = readWholeFile(dir / "Capture.txt");
  ASSERT_TRUE(capture);
  const std::string good = *capture;
  for (const auto& [from, to, expected] : {std::tuple{":1:0:0.25:", ":1:0:1.25:", "Capture.txt:5: fraction 1.25 is not in [0, 1]"},
                                           std::tuple{":1:0:0.25:", ":1:7:0.25:", "Capture.txt:5: key frames 1 and 7 of model 'models/m', which has 2"}}) {
    std::string text = good;
    text.replace(text.find(from), std::string(from).size(), to);
    ASSERT_TRUE(writeFileAtomic(dir / "Capture.txt", text));
    auto bad = capture::CaptureReader::open(dir);
    ASSERT_TRUE(bad);
    capture::CaptureFrame f;
    auto next = (*bad)->next(f);
    ASSERT_FALSE(next) << to;
    EXPECT_NE(next.error().message.find(expected), std::string::npos) << next.error().message;
  }
}

}  // namespace
}  // namespace dynbench::convert
