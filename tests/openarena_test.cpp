// `dynbench capture openarena` end to end on Debian's OpenArena (ioquake3 with the game modules
// rebuilt with dynbench's capture hooks): seeded matches on two maps are byte-identical twice, the
// second time as another machine would run them (other_machine.h); a match converts to a dataset
// the Khronos validator accepts, that Blender imports with the counts
// `stats` reports, whose players are MD3 key frames as morph targets posed where the game put them,
// and whose map faces the way the game's does.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>
#include <vector>

#include "capture/openarena.h"
#include "core/files.h"
#include "frames/feature_frame.h"
#include "frames/frame_io.h"
#include "scene/pose.h"
#include "scene/load.h"
#include "suite/manifest.h"
#include "gltf_builder.h"
#include "external_tools.h"
#include "other_machine.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;

// Every file under a folder, by relative path, with its bytes.
std::map<std::string, std::string> filesUnder(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file()) files[fs::relative(entry.path(), root).generic_string()] = test::slurp(entry.path());
  return files;
}

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ':');) fields.push_back(f);
  return fields;
}

// The map faces the way the game's does: id Tech 3 winds planar faces clockwise in front, glTF
// counter-clockwise, and the adapter turns them round (patches it tessellates the right way
// itself), so at most `against` of the corners face against their BSP vertex normal; floors face
// up (+Y).
void expectFacesAlongNormals(const scene::Scene& dataset, const std::string& map, double against) {
  const auto mapNode = std::find_if(dataset.nodes.begin(), dataset.nodes.end(), [&](const auto& n) { return n.name == "static_2_maps/" + map; });
  ASSERT_NE(mapNode, dataset.nodes.end());
  std::size_t corners = 0, alongFace = 0, againstFace = 0, upward = 0;
  for (const auto& prim : dataset.meshes[static_cast<std::size_t>(mapNode->mesh)].primitives) {
    ASSERT_EQ(prim.normals.size(), prim.positions.size());
    for (std::size_t t = 0; t < prim.triangleCount(); ++t) {
      const std::uint32_t* idx = &prim.indices[3 * t];
      const glm::dvec3 a(prim.positions[idx[0]]), b(prim.positions[idx[1]]), c(prim.positions[idx[2]]);
      const glm::dvec3 cross = glm::cross(b - a, c - a);
      if (glm::length(cross) < 1e-9) continue;
      const glm::dvec3 face = glm::normalize(cross);
      upward += face.y > 0.99 ? 1 : 0;
      for (int k = 0; k < 3; ++k, ++corners) {
        const double along = glm::dot(glm::dvec3(prim.normals[idx[k]]), face);
        alongFace += along > 0.9 ? 1 : 0;
        againstFace += along < 0 ? 1 : 0;
      }
    }
  }
  std::printf("%s: of %zu corners, %zu within 25 degrees of their face normal, %zu facing against it; %zu up-facing triangles\n",
              map.c_str(), corners, alongFace, againstFace, upward);
  EXPECT_LT(static_cast<double>(againstFace), against * static_cast<double>(corners)) << map;
  EXPECT_GT(static_cast<double>(alongFace), 0.6 * static_cast<double>(corners)) << map;
  EXPECT_GT(upward, 200u) << map;
}

TEST(OpenArena, SeededMatchesOnTwoMapsAreByteIdentical) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  const auto dir = test::freshDir("openarena_identical");
  // oa_dm1 with its fitted lights (fitted once, then read from the cache by run b); oa_dm3 with the
  // adapter's own approximation: its fit takes 38 s, and the fit's own determinism, across machines
  // too, is OpenArena.AFitIsTheSameBytesOnAnotherMachineAndUnjudged's.
  for (const auto& [map, seed, lights] : {std::tuple<std::string, int, std::string>{"oa_dm1", 3, "fit"}, {"oa_dm3", 5, "none"}}) {
    for (const char* run : {"a", "b"}) {
      std::optional<test::OtherMachine> other;  // run b as another machine would (other_machine.h)
      if (std::string(run) == "b") other.emplace();
      const auto r = dynbench(fmt::format("capture openarena -o {} --map {} --bots 4 --seconds 3 --seed {} --map-lights {} --game-cpu host", (dir / (map + run)).string(),
                                          map, seed, lights),
                              dir);
      other.reset();
      ASSERT_EQ(r.status, 0) << r.err;
      EXPECT_NE(r.out.find("150 frames"), std::string::npos) << r.out;
    }
    const auto a = filesUnder(dir / (map + "a")), b = filesUnder(dir / (map + "b"));
    ASSERT_GT(a.at("Capture.txt").size(), 10000u);
    EXPECT_GT(a.size(), 20u) << "models and textures";
    EXPECT_TRUE(a == b) << map << ": the same seed gave different captures";
    // No run folder (private base and home) is left behind.
    for (const auto& [name, bytes] : a) EXPECT_FALSE(name.starts_with(".openarena-")) << name;
  }
  // oa_dm3's curved patches, tessellated by the adapter, face along their normals too.
  auto r3 = dynbench(fmt::format("convert {} -o {}", (dir / "oa_dm3a").string(), (dir / "ds" / "dm3.gltf").string()), dir);
  ASSERT_EQ(r3.status, 0) << r3.err;
  auto dm3 = scene::loadScene(dir / "ds" / "dm3.gltf");
  ASSERT_TRUE(dm3) << dm3.error().message;
  expectFacesAlongNormals(*dm3, "oa_dm3", 0.001);
  // Another seed is another match.
  const auto r = dynbench(fmt::format("capture openarena -o {} --map oa_dm1 --bots 4 --seconds 3 --seed 4 --game-cpu host", (dir / "other").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(test::slurp(dir / "other" / "Capture.txt"), test::slurp(dir / "oa_dm1a" / "Capture.txt"));
}

// The default, --game-cpu emulated: the engine and the game modules run under qemu-x86_64 as a
// Nehalem, so the match is a property of the seed, not of the host's CPU. The pin below was made on
// an Intel Xeon with AVX-512 (2026-11-28); every x86-64 host must give the same digest, under the
// emulated other machine too (its glibc tunables reach the guest's C library, which qemu's fixed
// CPU model already decides). On the host's own CPU the same seed plays another match: Debian's
// engine computes 1/sqrt(x) in the bots' library from RSQRTSS's estimate, qemu exactly.
TEST(OpenArena, AnEmulatedMatchIsTheSameOnEveryHost) {
  DYNBENCH_NEEDS(test::missingEmulatedOpenArena());
  const auto dir = test::freshDir("openarena_emulated");
  // A small window: it records nothing but its aspect, and emulated, drawing is most of the time.
  const std::string match = "--map oa_dm1 --bots 3 --seconds 0.4 --warmup 2 --seed 7 --map-lights none --width 128 --height 72";
  {
    test::OtherMachine other;
    const auto r = dynbench(fmt::format("capture openarena -o {} {}", (dir / "emulated").string(), match), dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("20 frames"), std::string::npos) << r.out;
  }
  const auto digest = suite::captureDigest(dir / "emulated");
  ASSERT_TRUE(digest) << digest.error().message;
  EXPECT_EQ(*digest, "a7eb598958084d6431aeb943cfac1d5c0eb50dc29be66372bc74bbd3f6e47314") << "the emulated match differs from the one pinned on an Intel Xeon: after a change to the adapter, the "
         "modules' build or Debian's engine or data, pin the new digest; otherwise the match depends on the host";
  const auto r = dynbench(fmt::format("capture openarena -o {} {} --game-cpu host", (dir / "host").string(), match), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(test::slurp(dir / "host" / "Capture.txt"), test::slurp(dir / "emulated" / "Capture.txt"))
      << "the host's RSQRTSS estimates and qemu's exact 1/sqrt(x) played the same match: is the engine still Debian's?";
}

TEST(OpenArena, MatchConvertsWithMorphTargetsWhereTheGamePutThem) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  DYNBENCH_NEEDS(test::missingGltfValidator());
  const auto dir = test::freshDir("openarena_dataset");
  // A window other than the default, whose size the game's frames must have.
  constexpr unsigned kWidth = 480, kHeight = 270;
  auto r = dynbench(fmt::format("capture openarena -o {} --map oa_dm1 --bots 4 --seconds 6 --seed 3 --game-frames 100,250 --width {} --height {} --game-cpu host",
                                (dir / "cap").string(), kWidth, kHeight),
                    dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // The game's own image of frames 100 and 250: the window's size, and a lit room, not a black
  // buffer; and its depth buffer, read before the swap from the classic renderer (read after it
  // from Debian's default renderer, these two frames' depth read back as zeros on every run).
  for (const char* frame : {"00100", "00250"}) {
    const std::string ppm = test::slurp(dir / "cap" / "game" / fmt::format("frame_{}.ppm", frame));
    const std::string header = fmt::format("P6\n{} {}\n255\n", kWidth, kHeight);
    ASSERT_EQ(ppm.substr(0, header.size()), header);
    ASSERT_EQ(ppm.size(), header.size() + kWidth * kHeight * 3u);
    double mean = 0;
    for (std::size_t i = header.size(); i < ppm.size(); ++i) mean += static_cast<unsigned char>(ppm[i]);
    mean /= kWidth * kHeight * 3.0 * 255.0;
    EXPECT_GT(mean, 0.05) << "the game's frame " << frame << " is black";
    const fs::path depthPath = dir / "cap" / "game" / fmt::format("frame_{}_window_depth.pfm", frame);
    ASSERT_TRUE(fs::exists(depthPath)) << "frame " << frame << " kept no depth";
    const std::string pfm = test::slurp(depthPath);
    const std::string pfmHeader = fmt::format("Pf\n{} {}\n-1.0\n", kWidth, kHeight);
    ASSERT_EQ(pfm.substr(0, pfmHeader.size()), pfmHeader);
    ASSERT_EQ(pfm.size(), pfmHeader.size() + kWidth * kHeight * sizeof(float));
    std::vector<float> depth(kWidth * kHeight);
    std::memcpy(depth.data(), pfm.data() + pfmHeader.size(), depth.size() * sizeof(float));
    // window depth: in [0, 1], 1 on the sky; a room in view covers most of the frame nearer than that
    const auto [lowest, highest] = std::minmax_element(depth.begin(), depth.end());
    EXPECT_GE(*lowest, 0.0f);
    EXPECT_LE(*highest, 1.0f);
    const auto geometry = std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0.0f && d < 1.0f; });
    EXPECT_GT(static_cast<double>(geometry) / static_cast<double>(depth.size()), 0.5) << "frame " << frame;
    EXPECT_LT(*lowest, *highest) << "frame " << frame << ": a uniform depth buffer";
  }
  r = dynbench(fmt::format("convert {} -o {}", (dir / "cap").string(), (dir / "ds" / "dm1.gltf").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("is neither PNG nor JPEG"), std::string::npos) << r.err;  // TGA textures become PNG
  int status = -1;
  const std::string validation = test::validateGltf(dir / "ds" / "dm1.gltf", status);
  EXPECT_EQ(status, 0) << validation;
  EXPECT_NE(validation.find("errors=0"), std::string::npos) << validation;
  const std::string readme = test::slurp(dir / "ds" / "dm1.README.md");
  EXPECT_NE(readme.find("openarena-data"), std::string::npos);

  r = dynbench(fmt::format("stats {} --fps 50 --json {}", (dir / "ds" / "dm1.gltf").string(), (dir / "stats.json").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(test::slurp(dir / "stats.json"))["datasets"][0];
  const auto& p = j["properties"];
  EXPECT_TRUE(p["animated_camera"].get<bool>());
  EXPECT_TRUE(p["morph_targets"].get<bool>());
  EXPECT_GE(p["morph_animated_objects"].get<int>(), 4);  // players' legs and torsos
  EXPECT_EQ(p["static_objects"].get<int>(), 1);          // the map
  EXPECT_GT(p["faces"].get<int>(), 10000);
  EXPECT_GT(p["static_point_lights"].get<int>(), 10);    // the map's light-emitting surfaces
  EXPECT_GT(p["dynamic_point_lights"].get<int>(), 0);    // muzzle flashes, rockets, explosions
  EXPECT_GT(p["dynamic_rigid_objects"].get<int>(), 10);  // player parts, weapons, items, projectiles
  // A bot's view: faster than a slow fly-through (5 degrees a second).
  EXPECT_GT(j["camera_motion"]["rotation_degrees"]["mean"].get<double>() * 50.0, 15.0);
  std::printf("oa_dm1 6 s: %d faces, %d dynamic objects (%d morph-animated), %d + %d point lights, camera %.3f deg/frame\n",
              p["faces"].get<int>(), p["dynamic_rigid_objects"].get<int>(), p["morph_animated_objects"].get<int>(),
              p["static_point_lights"].get<int>(), p["dynamic_point_lights"].get<int>(),
              j["camera_motion"]["rotation_degrees"]["mean"].get<double>());

  // Blender's importer makes what stats counts: a mesh object per static or dynamic object, a light
  // per light, the camera, and the morph targets as shape keys.
  if (test::missingBlender().empty()) {
    const auto summary = test::blenderImport(dir / "ds" / "dm1.gltf");
    ASSERT_FALSE(summary.is_null());
    EXPECT_EQ(summary["meshes"].get<int>(), p["static_objects"].get<int>() + p["dynamic_rigid_objects"].get<int>());
    EXPECT_EQ(summary["lights"].get<int>(), p["static_point_lights"].get<int>() + p["dynamic_point_lights"].get<int>());
    EXPECT_EQ(summary["cameras"].get<int>(), 1);
    EXPECT_EQ(summary["objects"].get<int>(), p["nodes"].get<int>());
    EXPECT_GT(summary["shape_keys"].get<int>(), 0);
  }

  // Morph targets, against the capture itself: a vertex-animated capturable's vertices in the
  // dataset at a recorded frame are its ModelMesh key frames interpolated as the engine does,
  // (1 - fraction) P[from] + fraction P[to], moved by its recorded pose.
  auto dataset = scene::loadScene(dir / "ds" / "dm1.gltf");
  ASSERT_TRUE(dataset) << dataset.error().message;
  const scene::Evaluator evaluator(*dataset);
  std::ifstream capture(dir / "cap" / "Capture.txt");
  std::string line;
  double time = 0;
  int checked = 0;
  std::map<std::string, std::string> modelFiles;  // model path -> ModelMesh file
  for (const auto& entry : fs::directory_iterator(dir / "cap" / "models")) {
    std::ifstream in(entry.path());
    std::string version, origin;
    std::getline(in, version);
    std::getline(in, origin);
    modelFiles[origin.substr(2)] = entry.path().string();
  }
  std::vector<std::string> pose;
  double worst = 0;
  while (std::getline(capture, line) && checked < 12) {
    const auto f = splitFields(line);
    if (f[0] == "f") time = std::stod(f[2]);
    if (f[0] == "m") pose = f;
    if (f[0] != "v" || pose.size() < 11 || pose[1] != f[1]) continue;
    const int frame = static_cast<int>(std::lround(time * 50));
    if (frame % 37 != 5) continue;  // a spread of frames
    const std::string& model = f[5];
    const unsigned from = std::stoul(f[2]), to = std::stoul(f[3]);
    const double fraction = std::stod(f[4]);
    // mesh 0's key-frame positions
    std::ifstream mesh(modelFiles.at(model));
    std::vector<glm::dvec3> at_from, at_to;
    std::string record;
    while (std::getline(mesh, record)) {
      const auto r = splitFields(record);
      if (r[0] != "P" || r[1] != "0") continue;
      const unsigned k = std::stoul(r[2]);
      const glm::dvec3 v(std::stod(r[3]), std::stod(r[4]), std::stod(r[5]));
      if (k == from) at_from.push_back(v);
      if (k == to) at_to.push_back(v);
    }
    ASSERT_FALSE(at_from.empty());
    ASSERT_EQ(at_from.size(), at_to.size());
    const glm::dquat r(std::stod(pose[5]), std::stod(pose[2]), std::stod(pose[3]), std::stod(pose[4]));
    const glm::dquat d(std::stod(pose[9]), std::stod(pose[6]), std::stod(pose[7]), std::stod(pose[8]));
    const glm::dquat tq = 2.0 * d * glm::conjugate(r);
    const glm::dvec3 translation(tq.x, tq.y, tq.z);
    const auto node = std::find_if(dataset->nodes.begin(), dataset->nodes.end(),
                                   [&](const auto& n) { return n.name == "model_" + f[1] + "_" + model; });
    ASSERT_NE(node, dataset->nodes.end()) << model;
    std::vector<glm::dvec3> positions, normals;
    evaluator.worldGeometry(static_cast<int>(node - dataset->nodes.begin()), 0, time, positions, normals);
    ASSERT_EQ(positions.size(), at_from.size());
    for (std::size_t v = 0; v < positions.size(); ++v) {
      const glm::dvec3 expected = r * ((1 - fraction) * at_from[v] + fraction * at_to[v]) + translation;
      worst = std::max(worst, glm::distance(expected, positions[v]));
    }
    ++checked;
  }
  EXPECT_GE(checked, 4);
  std::printf("morph targets vs the capture's key frames: %d poses, worst vertex %.2g units\n", checked, worst);
  EXPECT_LT(worst, 0.01);  // float rounding of 1-unit-scale positions (32 units a metre)

  // oa_dm1's own misc_model soups wind 480 of their 9,240 corners against their smoothed normals.
  expectFacesAlongNormals(*dataset, "oa_dm1", 0.03);

  // Cycles, through Blender's glTF import, draws the frame where dynbench's renderer does, players'
  // morphed MD3 parts included: the recorded frame with the most vertex-animated parts drawn,
  // rendered by both, P buffers compared pixel by pixel (Embree's object ids tell the map from the
  // rest).
  if (test::missingBlender().empty()) {
    std::map<long, int> animatedParts;
    std::ifstream again(dir / "cap" / "Capture.txt");
    long frame = -1;
    while (std::getline(again, line)) {
      if (line.starts_with("f:")) frame = std::stol(splitFields(line)[1]);
      if (line.starts_with("v:")) ++animatedParts[frame];
    }
    const auto busiest = std::max_element(animatedParts.begin(), animatedParts.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    ASSERT_NE(busiest, animatedParts.end());
    std::map<std::string, frames::FeatureFrame> rendered;
    for (const char* engine : {"embree", "cycles"}) {
      const fs::path out = dir / (std::string("render_") + engine);
      std::string log;
      ASSERT_EQ(runShell(fmt::format("{} render '{}' -o '{}' --res 160x90 --spp 1 --bounces 0 --fps 50 --frames {} --engine {} 2>&1", DYNBENCH_EXE,
                                     (dir / "ds" / "dm1.gltf").string(), out.string(), busiest->first, engine),
                         log),
                0)
          << log;
      auto read = frames::readFrame({busiest->first, frames::frameImagePath(out, busiest->first), frames::frameSidecarPath(out, busiest->first)});
      ASSERT_TRUE(read) << read.error().message;
      rendered.emplace(engine, std::move(*read));
    }
    const auto& embree = rendered.at("embree");
    const auto& cycles = rendered.at("cycles");
    std::map<float, std::size_t> idPixels;
    for (float id : embree.id) ++idPixels[id];
    const float mapId = std::max_element(idPixels.begin(), idPixels.end(), [](const auto& a, const auto& b) { return a.second < b.second; })->first;
    std::size_t objectPixels = 0, far = 0;
    double objectWorst = 0;
    for (std::size_t i = 0; i < embree.pixelCount(); ++i) {
      if (!(embree.hit[i] > 0) || !(cycles.hit[i] > 0)) continue;
      const double d = glm::distance(glm::dvec3(embree.position[3 * i], embree.position[3 * i + 1], embree.position[3 * i + 2]),
                                     glm::dvec3(cycles.position[3 * i], cycles.position[3 * i + 1], cycles.position[3 * i + 2]));
      far += d > 1.0 ? 1 : 0;
      if (embree.id[i] != mapId) ++objectPixels, objectWorst = std::max(objectWorst, d);
    }
    std::printf("Cycles vs dynbench's renderer, frame %ld (%d animated parts): %zu of %zu pixels more than 1 unit apart; %zu pixels of "
                "models, at most %.3g units apart\n",
                busiest->first, busiest->second, far, embree.pixelCount(), objectPixels, objectWorst);
    EXPECT_LT(static_cast<double>(far), 0.005 * static_cast<double>(embree.pixelCount()));  // silhouette pixels only
    EXPECT_GT(objectPixels, 10u);
    EXPECT_LT(objectWorst, 0.1);  // a tenth of a unit, 3 mm: float rounding, not a different pose
  }
}

// The demo's datasets part with --engine openarena: the match captured and converted, the
// fly-through made over it, the capture's options recorded so that a second run reuses all of it.
TEST(OpenArena, DemoMakesItsDatasetsFromAnOpenArenaMatch) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  const auto dir = test::freshDir("openarena_demo");
  const std::string command = fmt::format("demo --engine openarena -o {} --bots 3 --seconds 2 --seed 2 --part datasets --game-cpu host", (dir / "demo").string());
  auto r = dynbench(command, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* name : {"oa_dm1_bot.gltf", "oa_dm1_flythrough.gltf"}) {
    auto dataset = scene::loadScene(dir / "demo" / "datasets" / name);
    ASSERT_TRUE(dataset) << name << ": " << dataset.error().message;
    EXPECT_GE(dataset->animations.size(), 1u) << name;
  }
  const std::string record = test::slurp(dir / "demo" / "capture" / "dynbench-demo-capture.json");
  EXPECT_NE(record.find("\"engine\": \"openarena\""), std::string::npos) << record;
  EXPECT_NE(record.find("\"bots\": 3"), std::string::npos) << record;
  r = dynbench(command, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE((r.out + r.err).find("exists, reused"), std::string::npos) << r.out << r.err;
}

// A map-lights file's colours are the game's (lightmap tints, shown through 8-bit sRGB): the
// capture records them as linear colours of the same peak, each channel over the peak decoded as
// sRGB (IEC 61966-2-1), the level unchanged. A light with its end (8 numbers: D and E) is recorded
// as the windowed inverse square of the same light: colour x (D/E)^2 at range E.
TEST(OpenArena, MapLightColoursAreRecordedLinear) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  const auto dir = test::freshDir("openarena_light_colours");
  std::ofstream(dir / "lights.txt") << "# known answers\n"
                                       "point 0 0 64 1 0.5 0.5 100\n"
                                       "point 0 64 64 0.2 0.2 0.1 50\n"
                                       "point 64 0 64 0.02 0.02 0.02 30\n"
                                       "point 64 64 64 1 1 1 40 320\n"
                                       "sun 0 0 1 0.5 0.25 0\n";
  auto r = dynbench(fmt::format("capture openarena -o {} --seconds 1 --bots 1 --map-lights {} --game-cpu host", (dir / "cap").string(),
                                (dir / "lights.txt").string()),
                    dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // decode(0.5) = ((0.5 + 0.055) / 1.055)^2.4 = 0.2140411; decode(0.1 / 0.2) the same
  const std::vector<std::array<double, 4>> expected = {
      {1.0, 0.2140411, 0.2140411, 100.0}, {0.2, 0.2, 0.2 * 0.2140411, 50.0}, {0.02, 0.02, 0.02, 30.0}, {0.015625, 0.015625, 0.015625, 320.0}};
  const std::vector<std::string> falloffs = {"inverse_square", "inverse_square", "inverse_square", "windowed_inverse_square"};
  std::vector<std::array<double, 4>> recorded;
  std::vector<std::string> recordedFalloffs;
  std::vector<double> sun;
  std::ifstream capture(dir / "cap" / "Capture.txt");
  for (std::string line; std::getline(capture, line);) {
    const auto f = splitFields(line);
    if (f[0] == "l" && f.size() >= 13 && f[12] == "maplight") {
      recorded.push_back({std::stod(f[5]), std::stod(f[6]), std::stod(f[7]), std::stod(f[8])});
      recordedFalloffs.push_back(f[9]);
    }
    if (f[0] == "L" && f.size() >= 7) sun = {std::stod(f[4]), std::stod(f[5]), std::stod(f[6])};
  }
  ASSERT_EQ(recorded.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(recorded[i][k], expected[i][k], 1e-6) << "light " << i << " value " << k;
  EXPECT_EQ(recordedFalloffs, falloffs);
  ASSERT_EQ(sun.size(), 3u);
  EXPECT_NEAR(sun[0], 0.5, 1e-6);
  EXPECT_NEAR(sun[1], 0.5 * 0.2140411, 1e-6);
  EXPECT_NEAR(sun[2], 0.0, 1e-9);
}

TEST(OpenArena, BadOptionsFailClearly) {
  const auto dir = test::freshDir("openarena_bad");
  EXPECT_TRUE(test::refuses(fmt::format("capture openarena -o {} --fps 30", (dir / "a").string()), dir, 2, "divisor of 1000"));
  EXPECT_FALSE(fs::exists(dir / "a")) << "nothing is made for a match that cannot be played";
  EXPECT_TRUE(test::refuses(fmt::format("capture openarena -o {} --map 'oa dm1'", (dir / "b").string()), dir, 2, "expected a map name"));
  EXPECT_TRUE(test::refuses(fmt::format("capture openarena -o {} --follow someone", (dir / "c").string()), dir, 2, "--follow 'someone'"));
  EXPECT_TRUE(test::refuses(fmt::format("capture openarena -o {} --seconds 1 --game-frames 49", (dir / "g").string()), dir, 2, "--game-frames: frame 49"));
  EXPECT_TRUE(test::refuses(fmt::format("capture openarena -o {} --game-cpu arm", (dir / "i").string()), dir, 2, "--game-cpu 'arm': expected emulated or host"));
  EXPECT_FALSE(fs::exists(dir / "i"));
  auto r = dynbench(fmt::format("capture openarena -o {} --bots 17", (dir / "d").string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  r = dynbench(fmt::format("capture openarena -o {} --modules {}", (dir / "e").string(), dir.string()), dir);
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("cgamex86_64.so"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "e" / "Capture.txt"));
  if (test::missingOpenArena().empty()) {
    // A map the game does not have: the game quits, and the error says so with the game's words.
    r = dynbench(fmt::format("capture openarena -o {} --map no_such_map --seconds 1 --game-cpu host", (dir / "f").string()), dir);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("OpenArena stopped after 0 of 50 frames"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("Can't find map maps/no_such_map.bsp"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "f" / "Capture.txt")) << "no capture that looks complete";
    // A lights file with a line the adapter cannot read: the game quits before writing anything.
    std::ofstream(dir / "lights.txt") << "point 0 0 64 1 1 1 100\nspot 0 0 0\n";
    r = dynbench(fmt::format("capture openarena -o {} --seconds 1 --map-lights {} --game-cpu host", (dir / "h").string(), (dir / "lights.txt").string()), dir);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("lights.txt:2: expected 'point X Y Z R G B D E'"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "h" / "Capture.txt"));
    // The default, emulated, on a machine without qemu-user: told what to install, before anything
    // is made (PATH holding Xvfb alone).
    fs::create_directories(dir / "path");
    fs::create_symlink(findOnPath("Xvfb"), dir / "path" / "Xvfb");
    const std::string path = std::getenv("PATH");
    ::setenv("PATH", (dir / "path").c_str(), 1);
    r = dynbench(fmt::format("capture openarena -o {} --seconds 1 --map-lights none", (dir / "j").string()), dir);
    ::setenv("PATH", path.c_str(), 1);
    EXPECT_EQ(r.status, 7) << r.err;
    EXPECT_NE(r.err.find("qemu-x86_64 is missing: install Debian's qemu-user"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "j" / "Capture.txt"));
  }
}

}  // namespace
}  // namespace dynbench
