// maplight/triangle_bvh.h: the fit's own tracer. Known answers on single triangles; against Embree
// (render's tracer, an independent implementation) on a random triangle soup and on oa_dm1's
// surfaces, where the two may differ only at grazing edges; and no instruction in maplight whose
// result a CPU vendor decides.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <regex>
#include <string>

#include "external_tools.h"
#include "maplight/bsp.h"
#include "maplight/pak.h"
#include "maplight/shaders.h"
#include "maplight/triangle_bvh.h"
#include "render/raytracing_scene.h"
#include "scene/scene.h"

namespace dynbench::maplight {
namespace {

BvhTriangle triangle(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, int group = 0) {
  const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
  return BvhTriangle{{a, b, c}, {n, n, n}, group};
}

TEST(TriangleBvh, KnownAnswersOnOneTriangle) {
  // the triangle (0,0,0), (2,0,0), (0,2,0) in the plane z = 0, its normal +z
  const TriangleBvh bvh({triangle({0, 0, 0}, {2, 0, 0}, {0, 2, 0})});
  const BvhHit down = bvh.intersect({0.5, 0.5, 3.0}, {0, 0, -1}, 0.0);
  ASSERT_TRUE(down.hit);
  EXPECT_EQ(down.distance, 3.0);
  EXPECT_EQ(down.shadingNormal, glm::dvec3(0, 0, 1));
  // from behind: either side is hit
  const BvhHit up = bvh.intersect({0.5, 0.5, -1.5}, {0, 0, 1}, 0.0);
  ASSERT_TRUE(up.hit);
  EXPECT_EQ(up.distance, 1.5);
  // beyond the hypotenuse x + y = 2, and behind the origin
  EXPECT_FALSE(bvh.intersect({1.5, 1.5, 3.0}, {0, 0, -1}, 0.0).hit);
  EXPECT_FALSE(bvh.intersect({0.5, 0.5, 3.0}, {0, 0, 1}, 0.0).hit);
  // a slanted ray: from (0, 0, 4) towards (1, 0.5, 0), length sqrt(17.25)
  const glm::dvec3 d = glm::normalize(glm::dvec3(1, 0.5, -4));
  const BvhHit slant = bvh.intersect({0, 0, 4}, d, 0.0);
  ASSERT_TRUE(slant.hit);
  EXPECT_NEAR(slant.distance, std::sqrt(17.25), 1e-12);
  // occluded: only within [0, tMax]
  EXPECT_TRUE(bvh.occluded({0.5, 0.5, 3.0}, {0, 0, -1}, 0.0, 3.5));
  EXPECT_FALSE(bvh.occluded({0.5, 0.5, 3.0}, {0, 0, -1}, 0.0, 2.5));
  // parallel to the plane: no hit
  EXPECT_FALSE(bvh.occluded({-1, 0.5, 0.0}, {1, 0, 0}, 0.0, 10.0));
  // a ray that starts on the triangle: hit at t = 0, not beyond tMin
  EXPECT_TRUE(bvh.occluded({0.5, 0.5, 0.0}, {0, 0, 1}, 0.0, 10.0));
  EXPECT_FALSE(bvh.occluded({0.5, 0.5, 0.0}, {0, 0, 1}, 1e-3, 10.0));
  EXPECT_FALSE(bvh.intersect({0.5, 0.5, 0.0}, {0, 0, 1}, 1e-3).hit);
  // tMin cuts the near end: the triangle 3 units away is not hit from 3.5 on
  EXPECT_FALSE(bvh.occluded({0.5, 0.5, 3.0}, {0, 0, -1}, 3.5, 10.0));
}

TEST(TriangleBvh, NearestOfManyWithItsGroupAndInterpolatedNormal) {
  std::vector<BvhTriangle> soup;
  // a stack of squares z = 1 ... 10 (two triangles each); the sky (group 1) at z = 7
  for (int z = 1; z <= 10; ++z) {
    const int group = z == 7 ? 1 : 0;
    soup.push_back(triangle({-1, -1, z}, {1, -1, z}, {1, 1, z}, group));
    soup.push_back(triangle({-1, -1, z}, {1, 1, z}, {-1, 1, z}, group));
  }
  // one tilted triangle with distinct vertex normals, at x = 5
  BvhTriangle tilted = triangle({5, -1, -1}, {5, 1, -1}, {5, 0, 1});
  tilted.normal = {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)};
  soup.push_back(tilted);
  const TriangleBvh bvh(soup);
  EXPECT_EQ(bvh.triangleCount(), soup.size());
  for (int from = 0; from <= 10; ++from) {
    const BvhHit h = bvh.intersect({0.25, 0.1, from + 0.5}, {0, 0, 1}, 0.0);
    if (from >= 10) {
      EXPECT_FALSE(h.hit);
      continue;
    }
    ASSERT_TRUE(h.hit) << from;
    EXPECT_EQ(h.distance, 0.5) << from;
    EXPECT_EQ(h.group, from + 1 == 7 ? 1 : 0) << from;
  }
  // the tilted one at its centroid (barycentrics 1/3 each): the mean of the three normals, unit
  const glm::dvec3 centroid = (tilted.position[0] + tilted.position[1] + tilted.position[2]) / 3.0;
  const BvhHit h = bvh.intersect(centroid - glm::dvec3(3, 0, 0), {1, 0, 0}, 0.0);
  ASSERT_TRUE(h.hit);
  EXPECT_NEAR(h.distance, 3.0, 1e-12);
  EXPECT_NEAR(h.shadingNormal.x, 1.0 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(h.shadingNormal.y, 1.0 / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(h.shadingNormal.z, 1.0 / std::sqrt(3.0), 1e-12);
}

// The same rays through Embree and through the hierarchy: hits and misses agree except where a
// ray passes within float rounding of an edge (Embree traces in single precision).
struct Agreement {
  std::size_t rays = 0, hitDisagree = 0, occludedDisagree = 0, distanceDisagree = 0;
};

Agreement compareWithEmbree(const std::vector<BvhTriangle>& triangles, const glm::dvec3& lo, const glm::dvec3& hi, std::size_t rays) {
  scene::Scene s;
  s.meshes.resize(1);
  s.meshes[0].primitives.resize(1);
  scene::Primitive& p = s.meshes[0].primitives[0];
  for (const BvhTriangle& t : triangles)
    for (int k = 0; k < 3; ++k) {
      p.indices.push_back(static_cast<std::uint32_t>(p.positions.size()));
      p.positions.push_back(glm::vec3(t.position[static_cast<std::size_t>(k)]));
      p.normals.push_back(glm::vec3(t.normal[static_cast<std::size_t>(k)]));
    }
  scene::Node node;
  node.mesh = 0;
  s.nodes.push_back(node);
  s.roots.push_back(0);
  auto embree = render::RayTracingScene::create(s);
  EXPECT_TRUE(embree) << embree.error().message;
  if (!embree) return {};
  EXPECT_TRUE((*embree)->update(0.0));
  // the hierarchy gets the triangles Embree holds (float vertices), so only the tracing differs
  std::vector<BvhTriangle> asFloat = triangles;
  for (BvhTriangle& t : asFloat)
    for (glm::dvec3& v : t.position) v = glm::dvec3(glm::vec3(v));
  const TriangleBvh bvh(asFloat);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(lo.x, hi.x), y(lo.y, hi.y), z(lo.z, hi.z);
  std::normal_distribution<double> normal;
  Agreement a;
  for (std::size_t i = 0; i < rays; ++i) {
    // float origins and directions, as Embree takes them
    const glm::dvec3 o = glm::dvec3(glm::vec3(glm::dvec3(x(rng), y(rng), z(rng))));
    const glm::dvec3 d = glm::dvec3(glm::vec3(glm::normalize(glm::dvec3(normal(rng), normal(rng), normal(rng)))));
    const render::SurfaceHit e = (*embree)->intersect(render::Ray{o, d});
    const BvhHit b = bvh.intersect(o, d, 0.0);
    ++a.rays;
    if (e.hit != b.hit) ++a.hitDisagree;
    else if (e.hit && std::abs(e.distance - b.distance) > 1e-4 * (1.0 + b.distance)) ++a.distanceDisagree;
    const double length = 0.5 * glm::length(hi - lo);
    if ((*embree)->occluded(o, d, length) != bvh.occluded(o, d, 0.0, length)) ++a.occludedDisagree;
  }
  return a;
}

// `count` triangles of up to 3 units across, centred in the cube [-10, 10]^3.
std::vector<BvhTriangle> randomSoup(unsigned seed, int count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0), small(-1.5, 1.5);
  std::vector<BvhTriangle> soup;
  for (int i = 0; i < count; ++i) {
    const glm::dvec3 c(u(rng), u(rng), u(rng));
    soup.push_back(triangle(c + glm::dvec3(small(rng), small(rng), small(rng)), c + glm::dvec3(small(rng), small(rng), small(rng)),
                            c + glm::dvec3(small(rng), small(rng), small(rng))));
  }
  return soup;
}

TEST(TriangleBvh, AgreesWithEmbreeOnARandomSoup) {
  const std::vector<BvhTriangle> soup = randomSoup(5, 3000);
  const Agreement a = compareWithEmbree(soup, glm::dvec3(-12), glm::dvec3(12), 40000);
  EXPECT_EQ(a.rays, 40000u);
  // measured: 0 of 40,000 each (2026-11-28)
  EXPECT_LE(a.hitDisagree, a.rays / 2000);
  EXPECT_LE(a.distanceDisagree, a.rays / 2000);
  EXPECT_LE(a.occludedDisagree, a.rays / 2000);
}

// The shadow cache (occluded with lastBlocker) answers exactly as the plain test: rays side by side
// towards one light through a random soup, the cache carried from ray to ray; it is used (some
// rays are answered by the cached triangle) and a blocked ray leaves a triangle that blocks it.
TEST(TriangleBvh, TheShadowCacheAnswersAsThePlainTest) {
  const TriangleBvh bvh(randomSoup(11, 2000));
  const glm::dvec3 light(0.3, 11.0, -0.2);
  std::uint32_t lastBlocker = TriangleBvh::kNoBlocker;
  int blocked = 0, cacheAnswered = 0;
  for (int row = 0; row < 100; ++row)
    for (int column = 0; column < 100; ++column) {
      const glm::dvec3 from(-10.0 + 0.2 * column, -11.0, -10.0 + 0.2 * row);
      const glm::dvec3 d = light - from;
      const double length = glm::length(d);
      const std::uint32_t before = lastBlocker;
      const bool plain = bvh.occluded(from, d / length, 1e-6, length - 1e-6);
      const bool cached = bvh.occluded(from, d / length, 1e-6, length - 1e-6, lastBlocker);
      ASSERT_EQ(cached, plain) << row << " " << column;
      if (!plain) continue;
      ++blocked;
      cacheAnswered += lastBlocker == before;
      ASSERT_NE(lastBlocker, TriangleBvh::kNoBlocker);
    }
  EXPECT_GT(blocked, 1000);
  EXPECT_LT(blocked, 10000);
  EXPECT_GT(cacheAnswered, blocked / 4) << "neighbouring rays are often blocked by the same triangle";
  // A stale or unknown cache entry changes nothing.
  std::uint32_t stale = 12345678;
  EXPECT_FALSE(bvh.occluded({0, 50, 0}, {0, 1, 0}, 0.0, 10.0, stale));
}

// occluded()'s two-lane traversal answers as the one-box-at-a-time one, ray for ray: random
// segments of every length through a soup, from its triangles' own corners (rays that start on a
// surface) and along the axes (direction components of zero, the huge reciprocal).
TEST(TriangleBvh, TwoBoxesAtOnceAnswerAsOneAtATime) {
  const std::vector<BvhTriangle> soup = randomSoup(17, 3000);
  const TriangleBvh bvh(soup);
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-12.0, 12.0), length(0.01, 40.0);
  std::normal_distribution<double> normal;
  int blocked = 0;
  for (int i = 0; i < 60000; ++i) {
    glm::dvec3 o(u(rng), u(rng), u(rng));
    if (i % 3 == 0) o = soup[rng() % soup.size()].position[rng() % 3];
    glm::dvec3 d = glm::normalize(glm::dvec3(normal(rng), normal(rng), normal(rng)));
    if (i % 5 == 0) d = glm::dvec3(0.0), d[i % 3] = i % 2 ? 1.0 : -1.0;
    const double tMin = i % 3 == 0 ? 1e-6 : 0.0, tMax = length(rng);
    const bool plain = bvh.occludedOneBoxAtATime(o, d, tMin, tMax);
    ASSERT_EQ(bvh.occluded(o, d, tMin, tMax), plain) << "ray " << i;
    blocked += plain;
  }
  EXPECT_GT(blocked, 10000);
  EXPECT_LT(blocked, 50000);
}

TEST(OpenArena, TheFitsTracerAgreesWithEmbreeOnAMap) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  auto files = GameFiles::open("/usr/lib/openarena/baseoa");
  ASSERT_TRUE(files) << files.error().message;
  auto bytes = files->read("maps/oa_dm1.bsp");
  ASSERT_TRUE(bytes) << bytes.error().message;
  auto bsp = parseBsp(*bytes, "oa_dm1.bsp");
  ASSERT_TRUE(bsp) << bsp.error().message;
  std::vector<BvhTriangle> triangles;
  for (int i = bsp->models[0].firstSurface; i < bsp->models[0].firstSurface + bsp->models[0].surfaceCount; ++i)
    for (const SurfaceTriangle& t : surfaceTriangles(*bsp, i)) triangles.push_back(BvhTriangle{t.position, t.normal, 0});
  ASSERT_GT(triangles.size(), 5000u);
  const Agreement a = compareWithEmbree(triangles, glm::dvec3(bsp->models[0].mins), glm::dvec3(bsp->models[0].maxs), 40000);
  std::printf("oa_dm1: %zu triangles, %zu rays: hit %zu, distance %zu, occluded %zu disagree\n", triangles.size(), a.rays, a.hitDisagree,
              a.distanceDisagree, a.occludedDisagree);
  EXPECT_LE(a.hitDisagree, a.rays / 2000);
  EXPECT_LE(a.distanceDisagree, a.rays / 2000);
  EXPECT_LE(a.occludedDisagree, a.rays / 2000);
  // and its two-lane shadow traversal answers as the one-box-at-a-time one on the map's rooms,
  // between points of its surfaces (the fit's rays run from texel to light)
  const TriangleBvh bvh(triangles);
  std::mt19937 rng(5);
  int blocked = 0;
  for (int i = 0; i < 20000; ++i) {
    const BvhTriangle &from = triangles[rng() % triangles.size()], &to = triangles[rng() % triangles.size()];
    const glm::dvec3 a = (from.position[0] + from.position[1] + from.position[2]) / 3.0, b = (to.position[0] + to.position[1] + to.position[2]) / 3.0;
    const double distance = glm::length(b - a);
    if (!(distance > 0.1)) continue;
    const glm::dvec3 d = (b - a) / distance;
    const bool plain = bvh.occludedOneBoxAtATime(a, d, 0.01, distance - 0.01);
    ASSERT_EQ(bvh.occluded(a, d, 0.01, distance - 0.01), plain) << "ray " << i;
    blocked += plain;
  }
  EXPECT_GT(blocked, 5000);
}

// The instructions whose results the x86 manuals leave to the implementation: the reciprocal and
// square-root estimates (RCPPS, RSQRTPS and their AVX-512 forms) and the x87 transcendentals.
// Counted in a library's disassembly (binutils' objdump, which the compiler's package brings).
const std::regex& vendorDependentMnemonic() {
  static const std::regex mnemonic(
      R"(^\s*[0-9a-f]+:\s+(v?rcp(ps|ss|14ps|14ss|14pd|14sd|28ps|28ss)|v?rsqrt(ps|ss|14ps|14ss|14pd|14sd|28ps|28ss)|fsin|fcos|fsincos|fptan|fpatan|f2xm1|fyl2x|fyl2xp1)\s)");
  return mnemonic;
}

struct Disassembly {
  std::size_t lines = 0, vendorDependent = 0;
};

Disassembly disassemble(const std::string& library) {
  Disassembly d;
  FILE* pipe = ::popen(("objdump -d --no-show-raw-insn '" + library + "' 2>/dev/null").c_str(), "r");
  if (!pipe) return d;
  char line[4096];
  while (std::fgets(line, sizeof line, pipe)) {
    ++d.lines;
    if (std::regex_search(line, vendorDependentMnemonic())) ++d.vendorDependent;
  }
  ::pclose(pipe);
  return d;
}

TEST(TriangleBvh, TheFitsCodeHasNoInstructionAVendorDecides) {
  // the pattern finds them as objdump prints them (lines from Debian's libembree3, which has 24,085)
  for (const char* line : {"  4a3f10:\trcpps  %xmm1,%xmm0\n", "   1c2:\tvrcp14ps %zmm2,%zmm3\n", "  88:\tvrsqrtss %xmm0,%xmm0,%xmm1\n",
                           "  10:\tfsin   \n"})
    EXPECT_TRUE(std::regex_search(line, vendorDependentMnemonic())) << line;
  for (const char* line : {"  4a3f10:\tsqrtsd %xmm1,%xmm0\n", "  4a3f14:\tdivpd  %xmm1,%xmm0\n", "  20:\tcall   4a <rcpps_like>\n"})
    EXPECT_FALSE(std::regex_search(line, vendorDependentMnemonic())) << line;
  // maplight's code (the fit and its tracer) and the core it calls have none
  for (const char* library : {DYNBENCH_MAPLIGHT_LIBRARY, DYNBENCH_CORE_LIBRARY}) {
    const Disassembly d = disassemble(library);
    EXPECT_GT(d.lines, 10000u) << library << ": objdump printed no disassembly";
    EXPECT_EQ(d.vendorDependent, 0u) << library;
  }
}

}  // namespace
}  // namespace dynbench::maplight
