// Tables 6.1-6.3 counting rules (docs/metrics.md) on a scene built by the test.
#include <fstream>

#include <gtest/gtest.h>

#include "gltf_builder.h"
#include "metrics/properties.h"
#include "scene/queries.h"
#include "scene/load.h"

namespace dynbench::metrics {
namespace {

TEST(Properties, CountsStaticDynamicLightsAndTextures) {
  const auto dir = test::freshDir("properties");
  test::GltfBuilder b;
  // One triangle mesh, instanced by four nodes.
  const int pos = b.accessor({0, 0, 0, 1, 0, 0, 0, 1, 0}, "VEC3");
  b.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"material", 0}}}}}};
  b.doc["images"] = {{{"uri", "albedo.png"}}, {{"uri", "normal%20map.png"}}};
  std::ofstream(dir / "albedo.png") << std::string(1000, 'x');
  std::ofstream(dir / "normal map.png") << std::string(24, 'y');
  b.doc["textures"] = {{{"source", 0}}, {{"source", 1}}};
  b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}, {"normalTexture", {{"index", 1}}}},
                        {{"extensions", {{"KHR_materials_pbrSpecularGlossiness", nlohmann::json::object()}}}}};
  b.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}}, {{"type", "spot"}}, {{"type", "point"}}}}}}};
  b.node({{"name", "static mesh"}, {"mesh", 0}});
  b.node({{"name", "static light"}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  const int mover = b.node({{"name", "mover"}, {"children", {3, 4}}});
  b.doc["nodes"].push_back({{"name", "child mesh (dynamic through parent)"}, {"mesh", 0}});
  b.doc["nodes"].push_back({{"name", "child light"}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  b.node({{"name", "spot"}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  b.node({{"name", "not in the scene"}, {"mesh", 0}});
  b.doc["scenes"][0]["nodes"].erase(b.doc["scenes"][0]["nodes"].size() - 1);
  b.channel(mover, "translation", {0, 1}, {0, 0, 0, 1, 0, 0});
  auto scene = scene::loadScene(b.write(dir, "props"));
  ASSERT_TRUE(scene) << scene.error().message;
  const auto p = measureProperties(*scene, 24.0);
  EXPECT_EQ(p.fileFormat, "glTF");
  EXPECT_EQ(p.fileCount, 4u);  // .gltf, .bin and two images
  EXPECT_EQ(p.textureCount, 2u);
  EXPECT_EQ(p.textureBytes, 1024u);
  EXPECT_EQ(p.materialCount, 2u);
  EXPECT_EQ(p.workflowCounts.at("PBR metallic-roughness"), 1u);
  EXPECT_EQ(p.workflowCounts.at("PBR specular-glossiness"), 1u);
  EXPECT_EQ(p.staticObjects, 1u);
  EXPECT_EQ(p.dynamicRigidObjects, 1u);
  EXPECT_EQ(p.faces, 2u);  // two instances in the scene; the third node is outside it
  EXPECT_EQ(p.uniqueFaces, 1u);
  EXPECT_EQ(p.staticPointLights, 1u);
  EXPECT_EQ(p.dynamicPointLights, 1u);
  EXPECT_EQ(p.spotLights, 1u);
  EXPECT_EQ(p.animationFrames, 25u);
  EXPECT_FALSE(p.animatedCamera);
  EXPECT_FALSE(p.morphTargets);
  std::uint64_t expectedBytes = 1024;
  for (auto f : {"props.gltf", "props.bin"}) expectedBytes += std::filesystem::file_size(dir / f);
  EXPECT_EQ(p.totalBytes, expectedBytes);
}

TEST(Properties, SeparateClipsOnOneNodeAreFlaggedAndSelectable) {
  const auto dir = test::freshDir("clips");
  test::GltfBuilder b;
  const int n = b.node({{"name", "cam"}, {"camera", b.perspectiveCamera()}});
  b.channel(n, "translation", {0, 1}, {0, 0, 0, 24, 0, 0});  // "walk": 1 unit per frame at 24 fps
  b.doc["animations"][0]["name"] = "walk";
  // A second clip, "run", on the same property: 3 units per frame over 2 s.
  const int in = b.accessor({0, 2}, "SCALAR"), out = b.accessor({0, 0, 0, 144, 0, 0}, "VEC3");
  b.doc["animations"].push_back({{"name", "run"},
                                 {"samplers", {{{"input", in}, {"output", out}}}},
                                 {"channels", {{{"sampler", 0}, {"target", {{"node", n}, {"path", "translation"}}}}}}});
  auto scene = scene::loadScene(b.write(dir, "clips"));
  ASSERT_TRUE(scene) << scene.error().message;
  const auto both = measureProperties(*scene, 24.0);
  ASSERT_EQ(both.warnings.size(), 1u);
  EXPECT_NE(both.warnings[0].find("more than one animation"), std::string::npos);
  EXPECT_EQ(both.animationFrames, 49u);  // the clock spans both clips
  auto walk = *scene;
  ASSERT_TRUE(scene::keepOnlyAnimation(walk, "walk"));
  EXPECT_EQ(measureProperties(walk, 24.0).animationFrames, 25u);
  EXPECT_TRUE(measureProperties(walk, 24.0).warnings.empty());
  auto run = *scene;
  ASSERT_TRUE(scene::keepOnlyAnimation(run, "1"));
  EXPECT_EQ(run.animations[0].name, "run");
  EXPECT_FALSE(scene::keepOnlyAnimation(run, "jump"));
}

TEST(Properties, FrameCount) {
  EXPECT_EQ(scene::frameCount({0.0, 2.0}, true, 24.0), 49u);
  EXPECT_EQ(scene::frameCount({1.25, 2.5}, true, 24.0), 31u);
  EXPECT_EQ(scene::frameCount({0.0, 0.0}, true, 24.0), 1u);
  EXPECT_EQ(scene::frameCount({0.0, 5.0}, false, 24.0), 0u);
}

}  // namespace
}  // namespace dynbench::metrics
