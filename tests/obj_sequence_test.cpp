// A Utah-style OBJ key-frame sequence: frames written by the test, morph evaluation checked.
#include <fstream>

#include <gtest/gtest.h>

#include "gltf_builder.h"
#include "metrics/properties.h"
#include "scene/pose.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

namespace fs = std::filesystem;

// One triangle whose first vertex sits at x = offset.
void writeFrame(const fs::path& file, double offset) {
  std::ofstream(file) << "v " << offset << " 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
}

TEST(ObjSequence, FolderPlaysAsMorphAnimation) {
  const auto dir = test::freshDir("objseq");
  // Names sort naturally: 2 before 10.
  const std::vector<std::pair<std::string, double>> frames = {{"f1.obj", 0.0}, {"f2.obj", 2.0}, {"f10.obj", 6.0}};
  for (const auto& [name, x] : frames) writeFrame(dir / name, x);
  auto scene = loadScene(dir, LoadOptions{.sequenceRate = 2.0});
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->source.format, "OBJ sequence");
  EXPECT_EQ(scene->source.files.size(), 3u);
  int meshNode = -1;
  for (std::size_t i = 0; i < scene->nodes.size(); ++i)
    if (scene->nodes[i].mesh >= 0) meshNode = static_cast<int>(i);
  ASSERT_GE(meshNode, 0);
  const Evaluator e(*scene);
  auto x = [&](double t) {
    const auto w = e.morphWeights(meshNode, t);
    const Primitive& p = scene->meshes[0].primitives[0];
    for (std::size_t v = 0; v < p.positions.size(); ++v)
      if (p.positions[v].y == 0.0f && p.positions[v].x == 0.0f) {
        double value = 0.0;
        for (std::size_t k = 0; k < w.size(); ++k) value += w[k] * p.targets[k].positionDeltas[v].x;
        return value;
      }
    return -1.0;
  };
  EXPECT_DOUBLE_EQ(x(0.0), 0.0);   // f1
  EXPECT_DOUBLE_EQ(x(0.5), 2.0);   // f2 at 1/rate
  EXPECT_DOUBLE_EQ(x(1.0), 6.0);   // f10 at 2/rate
  EXPECT_DOUBLE_EQ(x(0.75), 4.0);  // halfway between f2 and f10
  const auto p = metrics::measureProperties(*scene, 24.0);
  EXPECT_TRUE(p.morphTargets);
  EXPECT_EQ(p.animationFrames, 25u);  // 1 s at 24 fps
  EXPECT_EQ(p.faces, 1u);
}

TEST(ObjSequence, GlobSelectsFiles) {
  const auto dir = test::freshDir("objglob");
  writeFrame(dir / "a_0.obj", 0.0);
  writeFrame(dir / "a_1.obj", 1.0);
  writeFrame(dir / "b_0.obj", 5.0);
  auto files = expandObjSequence(dir / "a_*.obj");
  ASSERT_TRUE(files);
  ASSERT_EQ(files->size(), 2u);
  EXPECT_EQ((*files)[1].filename(), "a_1.obj");
}

TEST(ObjSequence, ChangingTopologyIsAnError) {
  const auto dir = test::freshDir("objbad");
  writeFrame(dir / "f0.obj", 0.0);
  std::ofstream(dir / "f1.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  auto scene = loadScene(dir);
  ASSERT_FALSE(scene);
  EXPECT_EQ(scene.error().code, ErrorCode::kInvalidData);
  EXPECT_NE(scene.error().message.find("f1.obj"), std::string::npos) << scene.error().message;
  EXPECT_NE(scene.error().message.find("topology"), std::string::npos);
  auto empty = loadScene(test::freshDir("objnone") / "*.obj");
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().message.find("no file matches"), std::string::npos);
}

}  // namespace
}  // namespace dynbench::scene
