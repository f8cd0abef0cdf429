// `--engine cycles` against dynbench's own path tracer on one frame: the position and normal
// buffers must agree. Needs Blender (Debian's `blender`); the test says so and skips without it.
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

#include <fmt/format.h>

#include "convert/sky.h"
#include "core/image_io.h"
#include "core/math.h"
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
  const std::vector<float> uv{0, 0, 0, 5, 5, 5, 5, 0};  // five texture repeats across the floor
  json floor = {{"attributes", {{"POSITION", b.accessor(p, "VEC3")}, {"NORMAL", b.accessor(n, "VEC3")}, {"TEXCOORD_0", b.accessor(uv, "VEC2")}}},
                {"indices", b.indices(idx)},
                {"material", 0}};
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
  // Both engines at their defaults: the radiance through the Blackman-Harris filter, the geometry
  // at the pixel centres (Cycles renders those passes apart, at 0.01 pixel). Tolerance: Cycles'
  // geometry render still spreads its sample over 0.01 pixel. On a smooth surface the two differ by less than the pixel's footprint
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

// The radiance test's scene: floorAndSphere's geometry with a checker-textured floor, a rough
// red sphere, and one kind of light at a time, so a disagreement names its source.
enum class LightKind { kSky, kPoint, kRangedPoint, kSpot, kDirectional };

fs::path litScene(const fs::path& dir, LightKind kind) {
  const fs::path base = floorAndSphere(dir);
  auto doc = json::parse(test::slurp(base));
  // A checker texture (8 x 8 texels, sRGB PNG) on the floor.
  FloatImage checker{8, 8, 3, {}, {}};
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) checker.pixels.push_back((x + y) % 2 ? 0.9f : (c == 2 ? 0.6f : 0.2f));
  EXPECT_TRUE(writeImage(dir / "checker.png", checker));
  doc["images"] = json::array({{{"uri", "checker.png"}}});
  doc["samplers"] = json::array({{{"magFilter", 9728}, {"minFilter", 9728}}});  // nearest: both engines look up the same texel
  doc["textures"] = json::array({{{"source", 0}, {"sampler", 0}}});
  doc["materials"] = json::array({{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}},
                                  {{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.3, 0.2, 1}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.5}}}}});
  doc["meshes"][1]["primitives"][0]["material"] = 1;
  std::string name;
  json light;
  json node = {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}};
  const double c45 = std::cos(M_PI / 4), s45 = std::sin(M_PI / 4);
  switch (kind) {
    case LightKind::kSky: {
      const auto sky = convert::preethamSky({3.0, 35.0, 60.0, 256});
      EXPECT_TRUE(writeImage(dir / "sky.hdr", FloatImage{sky.width, sky.height, 3, sky.rgb, {}}));
      doc["extensions"]["DYNBENCH_environment"] = {{"uri", "sky.hdr"}};
      doc["extensionsUsed"].push_back("DYNBENCH_environment");
      name = "sky";
      break;
    }
    case LightKind::kPoint:
      light = {{"type", "point"}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 40.0}};
      node["translation"] = {1.5, 2.5, 1.0};
      name = "point";
      break;
    case LightKind::kRangedPoint:  // KHR's range window, which Blender has no setting for
      light = {{"type", "point"}, {"color", {1.0, 0.9, 0.8}}, {"intensity", 40.0}, {"range", 3.5}};
      node["translation"] = {1.5, 2.5, 1.0};
      name = "ranged_point";
      break;
    case LightKind::kSpot:
      light = {{"type", "spot"}, {"intensity", 80.0}, {"spot", {{"innerConeAngle", 0.3}, {"outerConeAngle", 0.6}}}};
      node["translation"] = {-0.5, 4.0, 0.5};
      node["rotation"] = {-s45, 0, 0, c45};  // local -Z turned to -Y: straight down
      name = "spot";
      break;
    case LightKind::kDirectional:
      light = {{"type", "directional"}, {"color", {0.9, 0.95, 1.0}}, {"intensity", 5.0}};
      node["rotation"] = {-0.3535534, 0.3535534, 0.1464466, 0.8535534};  // down and to the side
      name = "directional";
      break;
  }
  if (kind != LightKind::kSky) {
    doc["extensions"]["KHR_lights_punctual"]["lights"] = json::array({light});
    doc["extensionsUsed"].push_back("KHR_lights_punctual");
    doc["nodes"].push_back(node);
    doc["scenes"][0]["nodes"].push_back(doc["nodes"].size() - 1);
  }
  const fs::path out = dir / (name + ".gltf");
  std::ofstream(out) << doc.dump();
  return out;
}

struct MeanRadiance {
  double direct = 0, indirect = 0;
};

MeanRadiance meanRadiance(const fs::path& exr) {
  auto image = readImage(exr);
  EXPECT_TRUE(image) << exr;
  MeanRadiance m;
  if (!image) return m;
  const auto d = channels(*image, {"direct.R", "direct.G", "direct.B"}), i = channels(*image, {"indirect.R", "indirect.G", "indirect.B"});
  const std::size_t n = d.size() / 3;
  for (std::size_t k = 0; k < n; ++k) {
    m.direct += luminance(glm::dvec3(d[3 * k], d[3 * k + 1], d[3 * k + 2])) / static_cast<double>(n);
    m.indirect += luminance(glm::dvec3(i[3 * k], i[3 * k + 1], i[3 * k + 2])) / static_cast<double>(n);
  }
  return m;
}

TEST(Cycles, RadianceAgreesWithDynbenchForEachKindOfLight) {
  DYNBENCH_NEEDS(test::missingBlender());
  const auto dir = test::freshDir("cycles_radiance");
  for (const auto kind : {LightKind::kSky, LightKind::kPoint, LightKind::kRangedPoint, LightKind::kSpot, LightKind::kDirectional}) {
    const fs::path scene = litScene(dir, kind);
    const std::string name = scene.stem().string();
    MeanRadiance m[2];
    for (int e = 0; e < 2; ++e) {
      const std::string engine = e ? "cycles" : "embree";
      const auto out = dir / (name + "_" + engine);
      // At the pixel centres: the light transport is compared, not the two engines' pixel filters
      // (Cycles multiplies each filtered colour pass by its filtered light pass).
      const auto r = dynbench(fmt::format("render {} -o {} --engine {} --res 64x48 --spp {} --bounces 2 --pixel-filter centre", scene.string(),
                                          out.string(), engine, e ? 256 : 64),
                              dir);
      ASSERT_EQ(r.status, 0) << engine << ": " << r.err;
      m[e] = meanRadiance(out / "frame_00000.exr");
    }
    const double directRatio = m[1].direct / m[0].direct, indirectRatio = m[1].indirect / m[0].indirect;
    std::printf("%-12s direct dynbench %.5g cycles %.5g (ratio %.4f); indirect dynbench %.5g cycles %.5g (ratio %.4f)\n", name.c_str(),
                m[0].direct, m[1].direct, directRatio, m[0].indirect, m[1].indirect, indirectRatio);
    // Both engines render glTF's BRDF (tools/blender/render_cycles.py builds it from Cycles
    // closures), KHR's spot ramp and range window. What is left, pinned (docs/feature-buffers.md,
    // "Agreement with Cycles"): Cycles' diffuse weight is fixed at 1 - f0 where glTF's is
    // 1 - F(v.h), within 2.5 % here, and its indirect light is 2-7 % brighter. A change in either
    // renderer that moves a ratio out of its band fails here.
    EXPECT_GT(directRatio, 0.98) << name;
    EXPECT_LT(directRatio, 1.03) << name;
    EXPECT_GT(indirectRatio, 1.0) << name;
    EXPECT_LT(indirectRatio, 1.08) << name;
  }
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
