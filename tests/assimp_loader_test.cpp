// FBX and COLLADA through assimp, on Debian's assimp-testmodels. The expected counts are read from
// the files by this test's own minimal readers (a binary-FBX record walker, text search in DAE),
// not by assimp.
#include <fstream>
#include <regex>
#include <sstream>

#include <gtest/gtest.h>
#include <zlib.h>

#include "core/files.h"
#include "metrics/camera_motion.h"
#include "scene/queries.h"
#include "metrics/properties.h"
#include "scene/load.h"

namespace dynbench::scene {
namespace {

namespace fs = std::filesystem;
const fs::path kModels = DYNBENCH_ASSIMP_MODELS_DIR;

// ---- a minimal binary FBX reader: record names and string properties only ----------------------
struct FbxRecord {
  std::string name;
  std::vector<std::string> strings;
  std::vector<std::int32_t> ints;  // the first int32 array property, inflated
  std::vector<FbxRecord> children;
};

class FbxWalker {
 public:
  explicit FbxWalker(std::string data) : d_(std::move(data)) {}
  FbxRecord root() {
    std::uint32_t version = 0;
    std::memcpy(&version, d_.data() + 23, 4);
    wide_ = version >= 7500;
    FbxRecord top;
    std::size_t off = 27;
    FbxRecord child;
    while (off < d_.size() && read(off, child)) top.children.push_back(std::move(child));
    return top;
  }

 private:
  template <typename T>
  T get(std::size_t off) const {
    T v;
    std::memcpy(&v, d_.data() + off, sizeof(T));
    return v;
  }
  std::uint64_t field(std::size_t& off) {
    const std::uint64_t v = wide_ ? get<std::uint64_t>(off) : get<std::uint32_t>(off);
    off += wide_ ? 8 : 4;
    return v;
  }
  bool read(std::size_t& off, FbxRecord& out) {
    out = {};
    const std::uint64_t end = field(off);
    const std::uint64_t props = field(off);
    const std::uint64_t propBytes = field(off);
    const std::uint8_t nameLength = get<std::uint8_t>(off);
    off += 1;
    if (end == 0) return false;  // the null record closing a list
    out.name = d_.substr(off, nameLength);
    off += nameLength;
    const std::size_t propStart = off;
    for (std::uint64_t p = 0; p < props; ++p) {
      const char type = d_[off++];
      switch (type) {
        case 'Y': off += 2; break;
        case 'C': off += 1; break;
        case 'I': case 'F': off += 4; break;
        case 'D': case 'L': off += 8; break;
        case 'S': case 'R': {
          const auto n = get<std::uint32_t>(off);
          if (type == 'S') out.strings.push_back(d_.substr(off + 4, n));
          off += 4 + n;
          break;
        }
        case 'i': {  // int32 array: length, encoding (0 raw, 1 zlib), byte count, bytes
          const auto length = get<std::uint32_t>(off), encoding = get<std::uint32_t>(off + 4), bytes = get<std::uint32_t>(off + 8);
          if (out.ints.empty()) {
            out.ints.resize(length);
            uLongf size = length * 4;
            if (encoding == 0) std::memcpy(out.ints.data(), d_.data() + off + 12, size);
            else EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(out.ints.data()), &size,
                                      reinterpret_cast<const Bytef*>(d_.data() + off + 12), bytes), Z_OK);
          }
          off += 12 + bytes;
          break;
        }
        default: off += 12 + get<std::uint32_t>(off + 8); break;  // other arrays: length, encoding, bytes
      }
    }
    off = propStart + propBytes;
    FbxRecord child;
    while (off < end && read(off, child)) out.children.push_back(std::move(child));
    off = end;
    return true;
  }
  std::string d_;
  bool wide_ = false;
};

struct FbxCounts {
  int meshModels = 0, cameras = 0, lights = 0, clusters = 0, skins = 0, stacks = 0;
  std::size_t triangles = 0;           // polygons of n corners count n - 2
  std::vector<std::string> modelNames;  // every Model, "Name\0\1Model" cut at the separator
};

FbxCounts countFbx(const fs::path& file) {
  auto data = readWholeFile(file);
  EXPECT_TRUE(data);
  FbxCounts c;
  for (const auto& section : FbxWalker(*data).root().children) {
    if (section.name != "Objects") continue;
    for (const auto& o : section.children) {
      const std::string kind = o.strings.size() > 1 ? o.strings[1] : "";
      if (o.name == "Model" && kind == "Mesh") ++c.meshModels;
      if (o.name == "Model" && kind == "Camera") ++c.cameras;
      if (o.name == "Model" && kind == "Light") ++c.lights;
      if (o.name == "Deformer" && kind == "Cluster") ++c.clusters;
      if (o.name == "Deformer" && kind == "Skin") ++c.skins;
      if (o.name == "Model" && !o.strings.empty()) c.modelNames.push_back(o.strings[0].substr(0, o.strings[0].find('\0')));
      if (o.name == "Geometry" && kind == "Mesh")
        for (const auto& field : o.children)
          if (field.name == "PolygonVertexIndex") {
            int corners = 0;
            for (std::int32_t index : field.ints) {
              ++corners;
              if (index < 0) {  // a negative index (bitwise not) closes the polygon
                c.triangles += static_cast<std::size_t>(corners - 2);
                corners = 0;
              }
            }
          }
      if (o.name == "AnimationStack") ++c.stacks;
    }
  }
  return c;
}

class FbxModel : public ::testing::TestWithParam<std::string> {};

TEST_P(FbxModel, CountsMatchTheFbxRecords) {
  const fs::path file = kModels / "FBX" / GetParam();
  const FbxCounts expected = countFbx(file);
  auto scene = loadScene(file);
  ASSERT_TRUE(scene) << scene.error().message;
  EXPECT_EQ(scene->source.format, "FBX");
  std::size_t meshNodes = 0, cameraNodes = 0, lightNodes = 0, joints = 0;
  for (const auto& n : scene->nodes) {
    meshNodes += n.mesh >= 0;
    cameraNodes += n.camera >= 0;
    lightNodes += n.light >= 0;
  }
  for (const auto& s : scene->skins) joints += s.joints.size();
  EXPECT_EQ(meshNodes, static_cast<std::size_t>(expected.meshModels));
  EXPECT_EQ(scene->cameras.size(), static_cast<std::size_t>(expected.cameras));
  EXPECT_EQ(cameraNodes, static_cast<std::size_t>(expected.cameras));
  EXPECT_EQ(scene->lights.size(), static_cast<std::size_t>(expected.lights));
  EXPECT_EQ(lightNodes, static_cast<std::size_t>(expected.lights));
  EXPECT_EQ(joints, static_cast<std::size_t>(expected.clusters));
  EXPECT_EQ(scene->skins.size(), static_cast<std::size_t>(expected.skins));
  std::size_t triangles = 0;
  for (const auto& n : scene->nodes)
    if (n.mesh >= 0) triangles += scene->meshes[static_cast<std::size_t>(n.mesh)].triangleCount();
  EXPECT_EQ(triangles, expected.triangles);
  for (const auto& name : expected.modelNames)
    EXPECT_TRUE(std::any_of(scene->nodes.begin(), scene->nodes.end(), [&](const Node& n) { return n.name == name; }))
        << "FBX Model '" << name << "' has no node";
  EXPECT_EQ(scene->animations.size(), static_cast<std::size_t>(expected.stacks));
}

INSTANTIATE_TEST_SUITE_P(AssimpTestModels, FbxModel,
                         ::testing::Values("animation_with_skeleton.fbx", "huesitos.fbx", "spider.fbx", "phong_cube.fbx"));

TEST(Fbx, SkeletonAnimationIsMeasured) {
  auto scene = loadScene(kModels / "FBX/animation_with_skeleton.fbx");
  ASSERT_TRUE(scene);
  const auto p = metrics::measureProperties(*scene, 24.0);
  EXPECT_EQ(p.armatures, 1u);
  EXPECT_GT(p.animationFrames, 1u);
  EXPECT_GT(p.channels, 0u);
  EXPECT_EQ(p.materialWorkflow, "Phong/other");
}

TEST(Fbx, MaterialWorkflowFrom3dsMaxPbrMaterials) {
  auto mr = loadScene(kModels / "FBX/maxPbrMaterial_metalRough.fbx");
  auto sg = loadScene(kModels / "FBX/maxPbrMaterial_specGloss.fbx");
  auto phong = loadScene(kModels / "FBX/phong_cube.fbx");
  ASSERT_TRUE(mr && sg && phong);
  EXPECT_EQ(mr->materials.at(0).workflow, MaterialWorkflow::kMetallicRoughness);
  EXPECT_EQ(sg->materials.at(0).workflow, MaterialWorkflow::kSpecularGlossiness);
  EXPECT_EQ(phong->materials.at(0).workflow, MaterialWorkflow::kPhongOrOther);
}

std::string text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::size_t countMatches(const std::string& s, const std::string& pattern) {
  const std::regex re(pattern);
  return static_cast<std::size_t>(std::distance(std::sregex_iterator(s.begin(), s.end(), re), std::sregex_iterator()));
}

TEST(Collada, LightsAndCamerasMatchTheXml) {
  const std::string lights = text(kModels / "Collada/lights.dae");
  auto lightScene = loadScene(kModels / "Collada/lights.dae");
  ASSERT_TRUE(lightScene);
  EXPECT_EQ(lightScene->source.format, "COLLADA");
  EXPECT_EQ(lightScene->lights.size(), countMatches(lights, "<light "));
  std::size_t lightNodes = 0;
  for (const auto& n : lightScene->nodes) lightNodes += n.light >= 0;
  EXPECT_EQ(lightNodes, countMatches(lights, "<instance_light"));

  // Every named <node> of the XML is a node of the scene.
  const std::regex nodeName("<node [^>]*name=\"([^\"]+)\"");
  std::size_t named = 0;
  for (auto it = std::sregex_iterator(lights.begin(), lights.end(), nodeName); it != std::sregex_iterator(); ++it, ++named) {
    const std::string name = (*it)[1].str();
    EXPECT_TRUE(std::any_of(lightScene->nodes.begin(), lightScene->nodes.end(), [&](const Node& n) { return n.name == name; }))
        << name;
  }
  EXPECT_GE(named, countMatches(lights, "<instance_light"));  // at least the light nodes were checked

  const std::string cameras = text(kModels / "Collada/cameras.dae");
  auto cameraScene = loadScene(kModels / "Collada/cameras.dae");
  ASSERT_TRUE(cameraScene);
  EXPECT_EQ(cameraScene->cameras.size(), countMatches(cameras, "<camera "));
  // --camera picks any of them by name; the DAE node names are Camera, Camera_002, Camera_003.
  for (const char* name : {"Camera", "Camera_002", "Camera_003"})
    EXPECT_TRUE(scene::selectCameraNode(*cameraScene, std::string(name))) << name;
}

TEST(Collada, TrianglesMatchThePolylistCounts) {
  // duck.dae: one <polylist> whose <vcount> lists each polygon's corner count; a polygon with n
  // corners is n - 2 triangles.
  const std::string duck = text(kModels / "Collada/duck.dae");
  const std::regex vcount("<vcount>([^<]*)</vcount>");
  std::size_t triangles = 0;
  for (auto it = std::sregex_iterator(duck.begin(), duck.end(), vcount); it != std::sregex_iterator(); ++it) {
    std::istringstream numbers((*it)[1].str());
    for (int n; numbers >> n;) triangles += static_cast<std::size_t>(n - 2);
  }
  ASSERT_GT(triangles, 0u);
  auto scene = loadScene(kModels / "Collada/duck.dae");
  ASSERT_TRUE(scene);
  const auto p = metrics::measureProperties(*scene, 24.0);
  EXPECT_EQ(p.uniqueFaces, triangles);
  // Its one texture (duckCM.tga) is found beside the file and counted by its size on disk.
  EXPECT_EQ(p.textureCount, 1u);
  EXPECT_EQ(p.textureBytes, fs::file_size(kModels / "Collada/duckCM.tga"));
  EXPECT_EQ(p.totalBytes, fs::file_size(kModels / "Collada/duck.dae") + fs::file_size(kModels / "Collada/duckCM.tga"));
}

TEST(Collada, NodeAnimationsAreRead) {
  const std::string xml = text(kModels / "Collada/box_nested_animation.dae");
  auto scene = loadScene(kModels / "Collada/box_nested_animation.dae");
  ASSERT_TRUE(scene);
  std::size_t channels = 0;
  for (const auto& a : scene->animations) channels += a.channels.size();
  EXPECT_GT(channels, 0u);
  EXPECT_GT(metrics::measureProperties(*scene, 24.0).animationFrames, 1u);
  EXPECT_EQ(countMatches(xml, "<animation "), 2u);  // the file animates two targets
}

TEST(Assimp, UnreadableFileIsAClearError) {
  const fs::path dir = fs::temp_directory_path() / "dynbench_assimp_bad";
  fs::create_directories(dir);
  std::ofstream(dir / "broken.fbx") << "Kaydara FBX Binary  \x00 not really";
  auto scene = loadScene(dir / "broken.fbx");
  ASSERT_FALSE(scene);
  EXPECT_NE(scene.error().message.find("broken.fbx"), std::string::npos);
  auto missing = loadScene(dir / "missing.dae");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, ErrorCode::kIo);
}

}  // namespace
}  // namespace dynbench::scene
