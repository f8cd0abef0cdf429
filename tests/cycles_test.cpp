// `--engine cycles` against dynbench's own path tracer on one frame: the position and normal
// buffers must agree. Needs Blender (Debian's `blender`); the test says so and skips without it.
#include <cmath>

#include <gtest/gtest.h>

#include <fmt/format.h>

#include "core/image_io.h"
#include "gltf_builder.h"
#include "render/cycles_backend.h"
#include "external_tools.h"
#include "run_cli.h"

namespace dynbench {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A camera at (0, 2, 6) looking 20 degrees down at a 10 x 10 floor and a smooth unit sphere.
fs::path floorAndSphere(const fs::path& dir) {
  test::GltfBuilder b;
  b.doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorFactor", {0.6, 0.6, 0.6, 1}}, {"metallicFactor", 0.0}}}}});
  std::vector<float> p{-5, 0, -5, -5, 0, 5, 5, 0, 5, 5, 0, -5}, n{0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  std::vector<std::uint32_t> idx{0, 1, 2, 0, 2, 3};
  json floor = {{"attributes", {{"POSITION", b.accessor(p, "VEC3")}, {"NORMAL", b.accessor(n, "VEC3")}}}, {"indices", b.indices(idx)}, {"material", 0}};
  p.clear();
  n.clear();
  idx.clear();
  const int rings = 48, segments = 96;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * s / segments;
      const double x = std::sin(theta) * std::cos(phi), y = std::cos(theta), z = std::sin(theta) * std::sin(phi);
      p.insert(p.end(), {static_cast<float>(x), static_cast<float>(y + 1.0), static_cast<float>(z)});
      n.insert(n.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)});
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const auto a = static_cast<std::uint32_t>(r * (segments + 1) + s), c = a + static_cast<std::uint32_t>(segments + 1);
      idx.insert(idx.end(), {a, a + 1, c, a + 1, c + 1, c});  // counter-clockwise seen from outside
    }
  json sphere = {{"attributes", {{"POSITION", b.accessor(p, "VEC3")}, {"NORMAL", b.accessor(n, "VEC3")}}}, {"indices", b.indices(idx)}, {"material", 0}};
  b.doc["meshes"] = json::array({{{"primitives", json::array({floor})}}, {{"primitives", json::array({sphere})}}});
  b.node({{"name", "floor"}, {"mesh", 0}});
  b.node({{"name", "ball"}, {"mesh", 1}});
  const double half = 0.5 * (-20.0 * M_PI / 180.0);
  b.node({{"name", "eye"}, {"camera", b.perspectiveCamera(0.8)}, {"translation", {0, 2, 6}}, {"rotation", {std::sin(half), 0, 0, std::cos(half)}}});
  return b.write(dir, "floor_and_sphere");
}

std::vector<float> channels(const FloatImage& image, const std::vector<std::string>& names) {
  std::vector<std::size_t> at;
  for (const auto& name : names) {
    const auto it = std::find(image.channelNames.begin(), image.channelNames.end(), name);
    EXPECT_NE(it, image.channelNames.end()) << name;
    at.push_back(static_cast<std::size_t>(it - image.channelNames.begin()));
  }
  std::vector<float> out;
  for (std::size_t i = 0; i < static_cast<std::size_t>(image.width) * image.height; ++i)
    for (auto c : at) out.push_back(image.pixels[i * static_cast<std::size_t>(image.channels) + c]);
  return out;
}

TEST(Cycles, PositionAndNormalAgreeWithDynbench) {
  DYNBENCH_NEEDS(test::missingBlender());
  const auto dir = test::freshDir("cycles_pn");
  const fs::path scene = floorAndSphere(dir);
  const int w = 64, h = 48;
  for (const char* engine : {"embree", "cycles"}) {
    const auto r = dynbench(fmt::format("render {} -o {} --engine {} --res {}x{} --spp 4 --bounces 1 --env-constant 1", scene.string(),
                                        (dir / engine).string(), engine, w, h),
                            dir);
    ASSERT_EQ(r.status, 0) << engine << ": " << r.err;
  }
  auto ours = readImage(dir / "embree" / "frame_00000.exr"), theirs = readImage(dir / "cycles" / "frame_00000.exr");
  ASSERT_TRUE(ours && theirs);
  const auto pa = channels(*ours, {"P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z", "hit", "Z"});
  const auto id = channels(*ours, {"id"});
  auto silhouette = [&](int i) {
    const int x = i % w, y = i / w;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = std::clamp(x + dx, 0, w - 1), ny = std::clamp(y + dy, 0, h - 1);
        if (id[static_cast<std::size_t>(ny * w + nx)] != id[static_cast<std::size_t>(i)]) return true;
      }
    return false;
  };
  const auto pb = channels(*theirs, {"P.X", "P.Y", "P.Z", "N.X", "N.Y", "N.Z", "hit", "Z"});
  // Tolerance: Cycles averages P and N over the pixel's square (box filter of width 1), dynbench
  // takes the pixel centre. On a smooth surface the two differ by less than the pixel's footprint
  // at that depth, f = Z * 2 tan(yfov / 2) / H, and the normals by less than f / r (r = 1 for the
  // sphere; the floor is flat). A pixel that a silhouette crosses mixes two surfaces in Cycles'
  // average and has one of them in dynbench's: those pixels (an instance-id change in the 3 x 3
  // neighbourhood of dynbench's id buffer, about 8% of this small image) are counted apart, and
  // 99% of all the others must agree.
  const double perDepth = 2.0 * std::tan(0.4) / h;
  int agree = 0, both = 0, hitMismatch = 0, edges = 0;
  for (int i = 0; i < w * h; ++i) {
    if (silhouette(i)) {
      ++edges;
      continue;
    }
    const float* a = &pa[static_cast<std::size_t>(8 * i)];
    const float* b = &pb[static_cast<std::size_t>(8 * i)];
    if ((a[6] > 0) != (b[6] > 0)) {
      ++hitMismatch;
      continue;
    }
    if (a[6] == 0) {
      ++agree;
      continue;
    }
    ++both;
    const double footprint = a[7] * perDepth;
    const double dp = std::sqrt(std::pow(a[0] - b[0], 2) + std::pow(a[1] - b[1], 2) + std::pow(a[2] - b[2], 2));
    const double dn = std::sqrt(std::pow(a[3] - b[3], 2) + std::pow(a[4] - b[4], 2) + std::pow(a[5] - b[5], 2));
    if (dp <= footprint && dn <= footprint + 1e-3) ++agree;
  }
  EXPECT_GT(both, w * h / 2);
  EXPECT_LT(edges, w * h / 10);
  EXPECT_GE(agree, static_cast<int>(0.99 * (w * h - edges))) << "hit disagreements " << hitMismatch << ", pixels on geometry " << both;
  std::printf("P and N agree on %d of %d pixels off silhouettes (%d silhouette pixels, %d hit/miss disagreements)\n", agree,
              w * h - edges, edges, hitMismatch);
}

TEST(Cycles, MissingBlenderIsAClearError) {
  const auto dir = test::freshDir("cycles_missing");
  const fs::path scene = floorAndSphere(dir);
  const auto r = dynbench(fmt::format("render {} -o {} --engine cycles --blender {}", scene.string(), (dir / "out").string(),
                                      (dir / "no-blender").string()),
                          dir);
  EXPECT_EQ(r.status, 7) << r.err;  // ErrorCode::kExternalTool
  EXPECT_NE(r.err.find("no-blender"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "frame_00000.exr"));
}

}  // namespace
}  // namespace dynbench
