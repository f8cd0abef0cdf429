// `dynbench capture cube2` end to end on Debian's Cube 2 data: a seeded 5-second bot match on
// colos, twice, must give the same Capture.txt byte for byte, the second time as on another
// machine (a working audio device, llvmpipe without AVX-512 on one thread, glibc without its AVX2
// and FMA code: issue 45); it converts to a dataset the Khronos
// validator accepts, whose stats show the followed bot's camera, the map, the players' skinned
// models, projectiles and debris and the game's lights; the dataset's skinned players match the
// engine's own skinning of the same frame vertex by vertex.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "capture/cube2.h"
#include "core/files.h"
#include "core/image_io.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "other_machine.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

TEST(Cube2, SeededMatchIsDeterministicAndConverts) {
  DYNBENCH_NEEDS(test::missingCube2());
  const auto dir = test::freshDir("cube2");
  // The adapter also writes the engine's own skinned vertices of frame 120 (2 s).
  ::setenv("DYNBENCH_CAPTURE_VERIFY_FRAME", "120", 1);
  // Run b as another machine would: SDL's dummy audio driver is a working audio device (with one,
  // the game's sounds drew from its random numbers before the adapter turned the volume to 0).
  for (const char* run : {"a", "b"}) {
    std::optional<test::OtherMachine> other;
    if (std::string(run) == "b") other.emplace();
    const auto r = dynbench(fmt::format("capture cube2 -o {} --map colos --bots 4 --seconds 5 --seed 3", (dir / run).string()), dir);
    other.reset();
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("300 frames"), std::string::npos) << r.out;
  }
  const auto a = readWholeFile(dir / "a" / "Capture.txt"), b = readWholeFile(dir / "b" / "Capture.txt");
  ASSERT_TRUE(a && b);
  EXPECT_GT(a->size(), 10000u);
  EXPECT_TRUE(*a == *b) << "the same seed gave different captures (run b as on another machine)";
  ::unsetenv("DYNBENCH_CAPTURE_VERIFY_FRAME");

  auto r = dynbench(fmt::format("convert {} -o {}", (dir / "a").string(), (dir / "ds" / "colos.gltf").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  int status = -1;
  const std::string validation = test::validateGltf(dir / "ds" / "colos.gltf", status);
  EXPECT_EQ(status, 0) << validation;
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;

  // The dataset README lists the licences of the Cube 2 assets (cube2-data's copyright file).
  const std::string readme = test::slurp(dir / "ds" / "colos.README.md");
  EXPECT_NE(readme.find("cube2-data"), std::string::npos);
  EXPECT_NE(readme.find("License: CC-BY-3.0"), std::string::npos);
  EXPECT_NE(readme.find("zlib"), std::string::npos);

  r = dynbench(fmt::format("stats {} --fps 60 --json {}", (dir / "ds" / "colos.gltf").string(), (dir / "stats.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(test::slurp(dir / "stats.json"))["datasets"][0];
  EXPECT_TRUE(j["properties"]["animated_camera"].get<bool>());
  EXPECT_GE(j["properties"]["static_objects"].get<int>(), 1);        // the map
  EXPECT_GT(j["properties"]["faces"].get<int>(), 5000);              // colos has ~7,800 triangles
  EXPECT_GT(j["properties"]["dynamic_point_lights"].get<int>(), 0);  // muzzle flashes, explosions
  EXPECT_GT(j["properties"]["static_point_lights"].get<int>(), 0);   // the map's lights
  EXPECT_GE(j["properties"]["armatures"].get<int>(), 4);              // players (snoutx10k), grenades, flags
  EXPECT_GT(j["properties"]["dynamic_rigid_objects"].get<int>(), 0);  // weapons in hand, debris
  std::printf("armatures %d, dynamic rigid objects %d, dynamic point lights %d\n", j["properties"]["armatures"].get<int>(),
              j["properties"]["dynamic_rigid_objects"].get<int>(), j["properties"]["dynamic_point_lights"].get<int>());

  // Skinning: the engine blends dual quaternions in its vertex shader; the dataset stores joint
  // transforms and glTF blends matrices. Vertices bound to one bone must agree to float precision,
  // blended ones within the difference of the two blends (a few centimetres at most).
  std::ifstream reference(dir / "a" / "skinning_frame_120.txt");
  ASSERT_TRUE(reference) << "the adapter wrote no skinning reference";
  std::map<std::pair<std::string, int>, std::vector<glm::dvec3>> engineVertices;
  std::string id;
  int mesh = 0, vertex = 0;
  glm::dvec3 p;
  while (reference >> id >> mesh >> vertex >> p.x >> p.y >> p.z) engineVertices[{id, mesh}].push_back(p);
  auto dataset = scene::loadScene(dir / "ds" / "colos.gltf");
  ASSERT_TRUE(dataset) << dataset.error().message;
  const scene::Evaluator evaluator(*dataset);
  std::vector<double> errors;
  std::set<std::string> parts;
  for (const auto& [key, points] : engineVertices) {
    const auto node = std::find_if(dataset->nodes.begin(), dataset->nodes.end(), [&](const auto& n) { return n.name == "skinned_" + key.first; });
    ASSERT_NE(node, dataset->nodes.end()) << "no skinned node for capturable " << key.first;
    std::vector<glm::dvec3> positions, normals;
    evaluator.worldGeometry(static_cast<int>(node - dataset->nodes.begin()), static_cast<std::size_t>(key.second), 2.0, positions, normals);
    ASSERT_EQ(positions.size(), points.size());
    for (std::size_t v = 0; v < points.size(); ++v) errors.push_back(glm::distance(positions[v], points[v]));
    parts.insert(key.first);
  }
  ASSERT_GE(parts.size(), 3u) << "fewer than 3 skinned models drawn at frame 120";
  std::sort(errors.begin(), errors.end());
  const double median = errors[errors.size() / 2], p99 = errors[errors.size() * 99 / 100], worst = errors.back();
  std::printf("skinning vs the engine: %zu vertices of %zu models, median %.2g, 99th percentile %.3f, max %.3f units (8 per metre)\n",
              errors.size(), parts.size(), median, p99, worst);
  EXPECT_LT(median, 1e-3);
  EXPECT_LT(p99, 0.15);
  EXPECT_LT(worst, 0.5);
  // The map's vertex normals are its surfaces' normals: the engine stores them as signed bytes and
  // gives lightmapped faces a placeholder (0, 0, 1); both once made floors lean 45 degrees. The
  // engine smooths normals across faces that meet at small angles, so a corner's normal may lean
  // from its triangle's face normal (front side, counter-clockwise as glTF winds), but by less than
  // 25 degrees nearly everywhere; and floors face up.
  const auto mapNode = std::find_if(dataset->nodes.begin(), dataset->nodes.end(), [](const auto& n) { return n.name == "map colos"; });
  ASSERT_NE(mapNode, dataset->nodes.end());
  std::size_t corners = 0, alongFace = 0, upward = 0;
  for (const auto& prim : dataset->meshes[static_cast<std::size_t>(mapNode->mesh)].primitives) {
    ASSERT_EQ(prim.normals.size(), prim.positions.size());
    for (std::size_t t = 0; t < prim.triangleCount(); ++t) {
      const std::uint32_t* idx = &prim.indices[3 * t];
      const glm::dvec3 a(prim.positions[idx[0]]), b(prim.positions[idx[1]]), c(prim.positions[idx[2]]);
      const glm::dvec3 cross = glm::cross(b - a, c - a);
      if (glm::length(cross) < 1e-9) continue;
      const glm::dvec3 face = glm::normalize(cross);
      upward += face.y > 0.99 ? 1 : 0;
      for (int k = 0; k < 3; ++k, ++corners) alongFace += glm::dot(glm::dvec3(prim.normals[idx[k]]), face) > 0.9 ? 1 : 0;
    }
  }
  std::printf("map normals: %zu of %zu corners within 25 degrees of their face normal; %zu upward triangles\n", alongFace, corners, upward);
  EXPECT_GT(static_cast<double>(alongFace), 0.99 * static_cast<double>(corners));
  EXPECT_GT(upward, 500u);
  // Light identity: a light is one capturable over the frames it lives (a rocket's, a flash's), not
  // a new one per frame: far fewer lights than light records.
  r = dynbench(fmt::format("capture-check {} --json {}", (dir / "a").string(), (dir / "check.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto check = nlohmann::json::parse(test::slurp(dir / "check.json"));
  const int dynamicLights = check["capturables"]["dynamic_lights"].get<int>(), lightRecords = check["records"]["light"].get<int>();
  EXPECT_GT(dynamicLights, 0);
  EXPECT_LE(5 * dynamicLights, lightRecords) << dynamicLights << " dynamic lights, " << lightRecords << " light records";
  // Camera cuts: in this match the followed bot dies at 2.65 s and the camera switches to the next
  // one; stats leave the cut frames out, and the jump is larger than any motion left.
  ASSERT_TRUE(check["camera_cuts"].contains("switch")) << check["camera_cuts"];
  EXPECT_GE(check["camera_cuts"]["switch"].get<int>(), 1);
  EXPECT_GE(j["camera_motion"]["cuts"].get<int>(), 1);
  EXPECT_GT(j["camera_motion"]["with_cuts"]["rotation_degrees"]["max"].get<double>(),
            3 * j["camera_motion"]["rotation_degrees"]["max"].get<double>());
  // Animated map models (colos's two waving flags, md5anim "mapmodel") are recorded every frame,
  // not frozen in their first pose: their joints move.
  int flags = 0;
  for (std::size_t n = 0; n < dataset->nodes.size(); ++n) {
    const auto& node = dataset->nodes[n];
    EXPECT_FALSE(node.name.starts_with("static_") && node.name.ends_with("ffflag")) << node.name;
    if (!(node.name.starts_with("model_") && node.name.ends_with("_ffflag"))) continue;
    ++flags;
    ASSERT_FALSE(node.children.empty()) << node.name;
    // Some joint under the flag moves between 1 s and 2 s.
    double moved = 0;
    std::vector<int> stack{static_cast<int>(n)};
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      moved = std::max(moved, glm::distance(glm::dvec3(evaluator.worldMatrix(k, 1.0)[3]), glm::dvec3(evaluator.worldMatrix(k, 2.0)[3])));
      for (int c : dataset->nodes[static_cast<std::size_t>(k)].children) stack.push_back(c);
    }
    EXPECT_GT(moved, 0.01) << node.name << " does not move";
  }
  EXPECT_EQ(flags, 2);
  // A bot's first-person view turns far faster than a slow fly-through: over 15 degrees per second
  // on average (0.25 per frame at 60 fps), three times a slow 5 degrees-per-second pan.
  EXPECT_GT(j["camera_motion"]["rotation_degrees"]["mean"].get<double>() * 60.0, 15.0);
  std::printf("camera rotation %.3f deg/frame (mean), %.3f (max); position %.3f units/frame\n",
              j["camera_motion"]["rotation_degrees"]["mean"].get<double>(), j["camera_motion"]["rotation_degrees"]["max"].get<double>(),
              j["camera_motion"]["position"]["mean"].get<double>());
}

// A second map, another mode and the default --follow auto: cyber1, a 3-second team match.
// A second map, zoom, with lava and water (material volumes the engine draws over the world, not
// world geometry): the dataset holds both as surfaces with their material (lava glowing with its
// texture, water smooth and of its colour), validates, and at game frame 150, where a lava pool
// fills the lower left of the view, the render agrees with the game's depth (0.906 when the lava
// was not recorded and the render saw the floor beneath it: docs/fidelity.md).
TEST(Cube2, SecondMapsLavaAndWaterConvertValidateAndAgreeWithTheGame) {
  DYNBENCH_NEEDS(test::missingCube2());
  const auto dir = test::freshDir("cube2_zoom");
  auto r = dynbench(fmt::format("capture cube2 -o {} --map zoom --bots 4 --seconds 3 --seed 1 --width 320 --height 180 --game-frames 150",
                                (dir / "cap").string()),
                    dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const fs::path gltf = dir / "ds" / "zoom.gltf";
  r = dynbench(fmt::format("convert {} -o {}", (dir / "cap").string(), gltf.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  int status = -1;
  const std::string validation = test::validateGltf(gltf, status);
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;
  const auto doc = nlohmann::json::parse(test::slurp(gltf));
  int lava = 0, water = 0;
  for (const auto& m : doc["materials"]) {
    if (m.contains("extensions") && m["extensions"].contains("KHR_materials_emissive_strength")) {
      ++lava;
      EXPECT_TRUE(m.contains("emissiveTexture")) << m;
      EXPECT_GT(m["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>(), 0.0) << m;
    }
    const auto& pbr = m["pbrMetallicRoughness"];
    if (pbr.contains("baseColorFactor") && pbr["roughnessFactor"].get<double>() < 0.1) ++water;
  }
  EXPECT_EQ(lava, 1);
  EXPECT_EQ(water, 1);
  r = dynbench(fmt::format("fidelity {} {} -o {}", (dir / "cap").string(), gltf.string(), (dir / "fid").string()), dir);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  const auto report = nlohmann::json::parse(test::slurp(dir / "fid" / "fidelity.json"));
  ASSERT_EQ(report["frames"].size(), 1u);
  EXPECT_GE(report["frames"][0]["depth_agreement"].get<double>(), 0.99) << report["frames"][0];
  EXPECT_GE(report["frames"][0]["correlation"].get<double>(), 0.8) << report["frames"][0];
  r = dynbench(fmt::format("stats {} --fps 60 --json {}", gltf.string(), (dir / "stats.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(test::slurp(dir / "stats.json"))["datasets"][0];
  EXPECT_TRUE(j["properties"]["animated_camera"].get<bool>());
  EXPECT_GT(j["properties"]["faces"].get<int>(), 5000);
  EXPECT_GE(j["properties"]["armatures"].get<int>(), 3);  // the followed bot's opponents
  std::printf("zoom: %d faces, %d armatures, %d dynamic rigid objects, camera rotation %.3f deg/frame (mean)\n",
              j["properties"]["faces"].get<int>(), j["properties"]["armatures"].get<int>(), j["properties"]["dynamic_rigid_objects"].get<int>(),
              j["camera_motion"]["rotation_degrees"]["mean"].get<double>());
}

// The game as oracle (docs/fidelity.md): two_towers, which has water, so that the engine also
// draws the world reflected, in third person, with the followed player's own body in it. The
// game's own frames and the dataset's renders of them agree in depth and lighting, and the
// dataset holds no player model where the followed player stands (the camera's own body, which
// the first-person view leaves out, once recorded from the reflection and seen looking down).
TEST(Cube2, TheGamesOwnFramesAgreeWithTheDatasetsRenderOfThem) {
  DYNBENCH_NEEDS(test::missingCube2());
  const auto dir = test::freshDir("cube2_fidelity");
  auto r = dynbench(fmt::format("capture cube2 -o {} --map two_towers --bots 3 --seconds 2 --seed 1 --width 320 --height 180 --game-frames 40,100",
                                (dir / "cap").string()),
                    dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* file : {"game/frame_00040.ppm", "game/frame_00040_depth.pfm", "game/frame_00100.ppm", "game/frame_00100_depth.pfm"})
    EXPECT_TRUE(fs::exists(dir / "cap" / file)) << file;
  r = dynbench(fmt::format("convert {} -o {}", (dir / "cap").string(), (dir / "ds" / "two_towers.gltf").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = dynbench(fmt::format("fidelity {} {} -o {}", (dir / "cap").string(), (dir / "ds" / "two_towers.gltf").string(), (dir / "fid").string()), dir);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  const auto report = nlohmann::json::parse(test::slurp(dir / "fid" / "fidelity.json"));
  ASSERT_EQ(report["frames"].size(), 2u);
  for (const auto& f : report["frames"]) {
    EXPECT_GE(f["depth_agreement"].get<double>(), 0.95) << f;
    EXPECT_GE(f["correlation"].get<double>(), 0.4) << f;
    EXPECT_LE(f["unlit_share"].get<double>(), 0.15) << f;
    // The side-by-side's fourth panel shows the same light reach: white where a light reaches the
    // render's surface, black where none does, dark blue on its sky.
    auto side = readImage(dir / "fid" / fmt::format("fidelity_{:05d}.png", f["frame"].get<int>()));
    ASSERT_TRUE(side) << side.error().message;
    ASSERT_EQ(side->width, 4 * 320);
    std::size_t reached = 0, unreached = 0, sky = 0;
    for (int y = 0; y < side->height; ++y)
      for (int x = 3 * 320; x < 4 * 320; ++x) {
        const float* p = &side->pixels[(static_cast<std::size_t>(y) * side->width + x) * side->channels];
        if (p[0] > 0.5f && p[1] > 0.5f && p[2] > 0.5f) ++reached;
        else if (p[0] < 0.01f && p[1] < 0.01f && p[2] > 0.1f) ++sky;
        else if (p[0] < 0.01f && p[1] < 0.01f && p[2] < 0.01f) ++unreached;
      }
    EXPECT_EQ(reached + unreached + sky, 320u * static_cast<std::size_t>(side->height)) << "every pixel one of the three colours";
    EXPECT_GT(reached, unreached);
    EXPECT_NEAR(static_cast<double>(unreached) / static_cast<double>(reached + unreached), f["unlit_share"].get<double>(), 1e-12) << f;
  }

  auto dataset = scene::loadScene(dir / "ds" / "two_towers.gltf");
  ASSERT_TRUE(dataset) << dataset.error().message;
  const scene::Evaluator evaluator(*dataset);
  int cameraNode = -1;
  std::vector<int> players;
  for (std::size_t n = 0; n < dataset->nodes.size(); ++n) {
    if (dataset->nodes[n].camera >= 0) cameraNode = static_cast<int>(n);
    if (dataset->nodes[n].name.starts_with("model_") && dataset->nodes[n].name.ends_with("snoutx10k")) players.push_back(static_cast<int>(n));
  }
  ASSERT_GE(cameraNode, 0);
  ASSERT_FALSE(players.empty());
  // Two players' bodies cannot overlap (Cube 2's player radius is 4.1 units), so a body whose
  // origin (its feet) is within 2 units of straight below the camera is the camera's own.
  for (int frame = 0; frame < 120; frame += 5) {
    const double t = frame / 60.0;
    const glm::dvec3 eye(evaluator.worldMatrix(cameraNode, t)[3]);
    for (const int p : players) {
      if (!evaluator.visible(p, t)) continue;
      const glm::dvec3 feet(evaluator.worldMatrix(p, t)[3]);
      const double below = eye.y - feet.y, aside = glm::length(glm::dvec2(eye.x - feet.x, eye.z - feet.z));
      EXPECT_FALSE(aside < 2.0 && below > 0.0 && below < 20.0)
          << dataset->nodes[static_cast<std::size_t>(p)].name << " stands where the camera is at frame " << frame;
    }
  }
}

TEST(Cube2, PresetsSetGameSettingsAndExplicitOptionsWin) {
  capture::Cube2Options o;
  ASSERT_TRUE(capture::applyCube2Preset("hard", o));
  EXPECT_EQ(o.mode, "instagib");
  EXPECT_LE(o.skill, 100);  // above 100 the game's bots aim instantly
  capture::Cube2Options kept;
  kept.bots = 3;
  kept.follow = "one";
  ASSERT_TRUE(capture::applyCube2Preset("calm", kept, {"bots", "follow"}));
  EXPECT_EQ(kept.map, "two_towers");
  EXPECT_EQ(kept.bots, 3);
  EXPECT_EQ(kept.follow, "one");
  const auto bad = capture::applyCube2Preset("insane", o);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kUsage);
  EXPECT_NE(bad.error().message.find("calm, fps, hard"), std::string::npos) << bad.error().message;
  for (const auto& p : capture::cube2Presets()) {  // every preset makes a valid match script
    capture::Cube2Options each;
    ASSERT_TRUE(capture::applyCube2Preset(p.name, each));
    EXPECT_TRUE(capture::cube2Script(each)) << p.name;
  }
}

TEST(Cube2, BadOptionsFailClearly) {
  const auto dir = test::freshDir("cube2_bad");
  EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --mode deathmatch", (dir / "x").string()), dir, 2,
                            "--mode: deathmatch not in {ffa,teamplay,instagib,efficiency,tactics}"));
  EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --bots 0", (dir / "x").string()), dir, 2, "--bots: must be from 1 to 32 (got 0)"));
  EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --warmup 0.2", (dir / "x").string()), dir, 2, "--warmup: must be from 1.5 to 3600 (got 0.2)"));
  EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --skill 102", (dir / "x").string()), dir, 2, "--skill: must be from 1 to 101 (got 102)"));
  EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --preset insane", (dir / "x").string()), dir, 2, "--preset: insane not in {calm,fps,hard}"));
  EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --client {}", (dir / "x").string(), (dir / "nothing").string()), dir, 7, "nothing"));
  if (test::missingCube2().empty()) {
    EXPECT_TRUE(test::refuses(fmt::format("capture cube2 -o {} --map nosuchmap", (dir / "x").string()), dir, 3, "map 'nosuchmap' not found"));
  }
  EXPECT_FALSE(fs::exists(dir / "x" / "Capture.txt"));
}

}  // namespace
}  // namespace dynbench
