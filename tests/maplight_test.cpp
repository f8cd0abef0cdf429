// maplight: q3map2's light model (known answers), the NNLS solver (its optimality conditions), the
// BSP and shader readers (their refusals), and the fit on Debian's OpenArena maps: a map's
// lightmaps reproduced, real lights recovered when hidden, the same lights every run.
#include <sstream>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstring>
#include <numbers>
#include <random>

#include "core/files.h"
#include "external_tools.h"
#include "maplight/bsp.h"
#include "maplight/fit.h"
#include "maplight/nnls.h"
#include "maplight/shaders.h"
#include "other_machine.h"
#include "run_cli.h"

namespace dynbench::maplight {
namespace {

TEST(Nnls, HandDerivedKnownAnswer) {
  // A = [[1, 0], [0, 1], [1, 1]], b = (2, -1, 1): unconstrained (2, -1); with x2 >= 0 the
  // optimum is x2 = 0 and x1 minimising (x1 - 2)^2 + (x1 - 1)^2, 1.5.
  const std::vector<double> gram = {2, 1, 1, 2}, atb = {3, 0};
  const NnlsResult r = nnls(gram, atb);
  ASSERT_TRUE(r.converged);
  EXPECT_NEAR(r.x[0], 1.5, 1e-9);
  EXPECT_EQ(r.x[1], 0.0);
}

TEST(Nnls, RandomProblemsMeetTheOptimalityConditions) {
  // Karush-Kuhn-Tucker for min |Ax - b|^2, x >= 0: x >= 0, w = A^T (b - A x) <= 0, and w = 0 where x > 0.
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    const std::size_t rows = 60, cols = 14;
    std::vector<double> a(rows * cols), b(rows);
    for (double& v : a) v = std::abs(normal(rng));
    for (double& v : b) v = normal(rng) * 3.0 + 1.0;
    std::vector<double> gram(cols * cols, 0.0), atb(cols, 0.0);
    for (std::size_t i = 0; i < cols; ++i) {
      for (std::size_t j = 0; j < cols; ++j)
        for (std::size_t k = 0; k < rows; ++k) gram[i * cols + j] += a[k * cols + i] * a[k * cols + j];
      for (std::size_t k = 0; k < rows; ++k) atb[i] += a[k * cols + i] * b[k];
    }
    const NnlsResult r = nnls(gram, atb);
    ASSERT_TRUE(r.converged) << trial;
    std::size_t positive = 0;
    for (std::size_t i = 0; i < cols; ++i) {
      ASSERT_GE(r.x[i], 0.0);
      double w = atb[i];
      for (std::size_t j = 0; j < cols; ++j) w -= gram[i * cols + j] * r.x[j];
      const double scale = 1e-8 * (1.0 + std::abs(atb[i]));
      if (r.x[i] > 0) {
        ++positive;
        EXPECT_NEAR(w, 0.0, scale) << trial << " " << i;
      } else {
        EXPECT_LE(w, scale) << trial << " " << i;
      }
    }
    EXPECT_GT(positive, 0u);
  }
}

// The form factor from a point to a parallel rectangle with one corner straight above it, X = a/h,
// Y = b/h (the standard differential-area-to-rectangle view factor, e.g. Howell's catalogue, B-3):
// F = 1/(2 pi) (X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))).
TEST(MapLight, FormFactorOfARectangleOverACorner) {
  const double a = 3.0, b = 5.0, h = 2.0, x = a / h, y = b / h;
  const double expected = (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) + y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y))) /
                          (2.0 * std::numbers::pi);
  const glm::dvec3 p00(0, 0, h), p10(a, 0, h), p11(a, b, h), p01(0, b, h);
  const glm::dvec3 up(0, 0, 1);
  const double both = formFactor({p00, p10, p11}, glm::dvec3(0.0), up) + formFactor({p00, p11, p01}, glm::dvec3(0.0), up);
  EXPECT_NEAR(both, expected, 1e-12);
  // either winding
  const double reversed = formFactor({p11, p10, p00}, glm::dvec3(0.0), up) + formFactor({p01, p11, p00}, glm::dvec3(0.0), up);
  EXPECT_NEAR(reversed, expected, 1e-12);
  // a surface facing away sees it with the opposite sign (q3map2 then gives no light)
  EXPECT_NEAR(formFactor({p00, p10, p11}, glm::dvec3(0.0), -up), -formFactor({p00, p10, p11}, glm::dvec3(0.0), up), 1e-12);
  // the rectangle as one polygon, as q3map2 keeps an undivided winding
  EXPECT_NEAR(formFactor({p00, p10, p11, p01}, glm::dvec3(0.0), up), expected, 1e-12);
  // a surface emitter: formFactorValueScale x areaScale x V times it (beyond 8 units: q3map2 pushes
  // nearer points 8 units out from the emitter's plane)
  SurfaceEmitter e;
  e.winding = {p00 * 10.0, p10 * 10.0, p11 * 10.0};
  e.normal = -up;  // lights downwards
  e.origin = (e.winding[0] + e.winding[2]) * 0.5 + e.normal;
  e.value = 400.0;
  bool fromBack = true;
  EXPECT_NEAR(surfaceContribution(e, glm::dvec3(0.0), up, &fromBack), 0.75 * 400.0 * formFactor(e.winding, glm::dvec3(0.0), up), 1e-9);
  EXPECT_FALSE(fromBack);
  const glm::dvec3 above(0, 0, 40);  // above it, behind the side it lights
  EXPECT_EQ(surfaceContribution(e, above, -up), 0.0);
  // two-sided (cull none: lava) it lights the point above from its back, as much as one below
  e.twoSided = true;
  const glm::dvec3 below(0, 0, 0);
  EXPECT_NEAR(surfaceContribution(e, above, -up, &fromBack), surfaceContribution(e, below, up), 1e-9);
  EXPECT_TRUE(fromBack);
  // and, by q3map2's sign rule, a surface in front of it facing away from it
  EXPECT_NEAR(surfaceContribution(e, below, -up, &fromBack), surfaceContribution(e, below, up), 1e-9);
  EXPECT_TRUE(fromBack);
  e.twoSided = false;
  EXPECT_EQ(surfaceContribution(e, below, -up), 0.0);
}

// q3map2 halves a surface light's winding at the mid-plane of its bounds, first axis first, while
// they exceed the subdivision: a 1000 x 100 rectangle at 300 units becomes four 250 x 100 pieces.
TEST(MapLight, SurfaceLightWindingsSubdivideAsQ3map2) {
  const std::vector<glm::dvec3> rectangle{{0, 0, 0}, {1000, 0, 0}, {1000, 100, 0}, {0, 100, 0}};
  bool split = false;
  const auto pieces = subdivideWinding(rectangle, 300.0, &split);
  EXPECT_TRUE(split);
  ASSERT_EQ(pieces.size(), 4u);
  std::vector<double> starts;
  for (const auto& piece : pieces) {
    glm::dvec3 lo(1e9), hi(-1e9);
    for (const glm::dvec3& p : piece) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    EXPECT_DOUBLE_EQ(hi.x - lo.x, 250.0);
    EXPECT_DOUBLE_EQ(hi.y - lo.y, 100.0);
    starts.push_back(lo.x);
  }
  std::sort(starts.begin(), starts.end());
  EXPECT_EQ(starts, (std::vector<double>{0, 250, 500, 750}));
  // within the subdivision: left whole (and so q3map2 gives it its backsplash light)
  const auto whole = subdivideWinding(rectangle, 999.0 + 1.0, &split);
  EXPECT_FALSE(split);
  ASSERT_EQ(whole.size(), 1u);
  EXPECT_EQ(whole[0], rectangle);
}

TEST(MapLight, PointSpotAndSunFollowQ3map2) {
  MapLight l;
  l.value = 300.0;
  l.position = {0, 0, 100};
  const glm::dvec3 up(0, 0, 1);
  EXPECT_DOUBLE_EQ(lightContribution(l, glm::dvec3(0.0), up), 300.0 * 7500.0 / (100.0 * 100.0));  // 225
  // 60 degrees off the normal: cos = 1/2 at the same distance
  const glm::dvec3 side(100.0 * std::sin(std::numbers::pi / 3), 0.0, 100.0 - 100.0 * std::cos(std::numbers::pi / 3));
  EXPECT_NEAR(lightContribution(l, side, up), 112.5, 1e-9);
  // nearer than 16 units: the distance is clamped
  EXPECT_DOUBLE_EQ(lightContribution(l, glm::dvec3(0, 0, 92), up), 300.0 * 7500.0 / 256.0);
  EXPECT_EQ(lightContribution(l, glm::dvec3(0.0), -up), 0.0);  // behind the surface
  l.angleAttenuation = false;
  EXPECT_NEAR(lightContribution(l, side, up), 225.0, 1e-9);
  l.angleAttenuation = true;
  l.linear = true;  // V pointScale linearScale cos - d fade
  EXPECT_NEAR(lightContribution(l, glm::dvec3(0.0), up), 300.0 * 7500.0 / 8000.0 - 100.0, 1e-9);
  l.linear = false;
  l.kind = MapLightKind::kSpot;
  l.spotAxis = -up;
  l.spotRadiusByDist = 0.5;  // 50 units of radius at the floor, 100 below
  EXPECT_DOUBLE_EQ(lightContribution(l, glm::dvec3(0.0), up), 225.0);
  EXPECT_EQ(lightContribution(l, glm::dvec3(60, 0, 0), up), 0.0);  // outside the cone
  const double edge = lightContribution(l, glm::dvec3(34, 0, 0), up);  // in its 32-unit soft edge: (50 - 34) / 32
  const double d2 = 34.0 * 34.0 + 100.0 * 100.0;
  EXPECT_NEAR(edge, 300.0 * 7500.0 / d2 * (100.0 / std::sqrt(d2)) * (16.0 / 32.0), 1e-9);
  MapLight sun;
  sun.kind = MapLightKind::kSun;
  sun.value = 80.0;
  sun.towardsSun = glm::normalize(glm::dvec3(1, 0, 1));
  EXPECT_NEAR(lightContribution(sun, glm::dvec3(0.0), up), 80.0 / std::sqrt(2.0), 1e-12);
}

// q3map2's envelope (SetupEnvelopes): sqrt(V pointScale / falloffTolerance) for the inverse
// square, nothing from it on; the dataset's end instead (MapLight::range): KHR's window
// max(0, 1 - (d/range)^4) on the inverse square, which never takes more than the tolerance (1
// lightmap unit) from the hard cut's light, the most at the range itself.
TEST(MapLight, LightsEndAtQ3map2sEnvelope) {
  MapLight l;
  l.value = 300.0;
  l.position = {0, 0, 0};
  const double envelope = std::sqrt(300.0 * 7500.0);  // 1500 units
  EXPECT_DOUBLE_EQ(lightEnvelope(l), envelope);
  const glm::dvec3 facing(0, 0, -1);
  // just inside the envelope: the inverse square; from it on: nothing
  EXPECT_NEAR(lightContribution(l, glm::dvec3(0, 0, envelope - 1.0), facing), 300.0 * 7500.0 / ((envelope - 1.0) * (envelope - 1.0)), 1e-12);
  EXPECT_EQ(lightContribution(l, glm::dvec3(0, 0, envelope), facing), 0.0);
  l.linear = true;
  l.fade = 2.0;
  EXPECT_DOUBLE_EQ(lightEnvelope(l), (300.0 * 7500.0 / 8000.0 - 1.0) / 2.0);
  l.linear = false;
  MapLight sun;
  sun.kind = MapLightKind::kSun;
  EXPECT_TRUE(std::isinf(lightEnvelope(sun)));
  // the window: at half the range 1 - 1/16 of the inverse square, at 0.9 of it 1 - 0.9^4
  l.range = envelope;
  for (const double x : {0.5, 0.9, 0.999}) {
    const double d = x * envelope;
    const double inverseSquare = 300.0 * 7500.0 / (d * d);
    const double windowed = lightContribution(l, glm::dvec3(0, 0, d), facing);
    EXPECT_NEAR(windowed, inverseSquare * (1.0 - x * x * x * x), 1e-9 * inverseSquare);
    EXPECT_LE(inverseSquare - windowed, kFalloffTolerance * (1.0 + 1e-9)) << "at " << x << " of the range";
  }
  EXPECT_EQ(lightContribution(l, glm::dvec3(0, 0, envelope * 1.01), facing), 0.0);
  // an infinite range: no end (the candidates the fit chooses from)
  l.range = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(lightContribution(l, glm::dvec3(0, 0, 2.0 * envelope), facing), 300.0 * 7500.0 / (4.0 * envelope * envelope));
}

std::string header(const std::vector<std::pair<int, int>>& lumps) {
  std::string bytes = "IBSP";
  const int version = 46;
  bytes.append(reinterpret_cast<const char*>(&version), 4);
  for (int l = 0; l < 17; ++l) {
    const std::pair<int, int> lump = l < static_cast<int>(lumps.size()) ? lumps[static_cast<std::size_t>(l)] : std::pair<int, int>{144, 0};
    bytes.append(reinterpret_cast<const char*>(&lump.first), 4);
    bytes.append(reinterpret_cast<const char*>(&lump.second), 4);
  }
  return bytes;
}

TEST(Bsp, EntitiesAndLightsAsQ3map2ReadsThem) {
  const std::string entities =
      "{ \"classname\" \"worldspawn\" }\n"
      "{ \"classname\" \"light\" \"origin\" \"0 0 64\" }\n"
      "{ \"classname\" \"light\" \"origin\" \"10 0 64\" \"light\" \"500\" \"_color\" \"1 0.5 0\" \"target\" \"t1\" \"radius\" \"48\" }\n"
      "{ \"classname\" \"target_position\" \"origin\" \"10 0 0\" \"targetname\" \"t1\" }\n"
      "{ \"classname\" \"light\" \"origin\" \"0 0 0\" \"spawnflags\" \"1\" \"_light\" \"200\" }\n";
  std::string bytes = header({{144, static_cast<int>(entities.size())}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {0, 0}, {static_cast<int>(144 + entities.size()), 40}});
  bytes += entities;
  bytes.append(40, '\0');  // one model: the world, no surfaces
  auto bsp = parseBsp(bytes, "maps/test.bsp");
  ASSERT_TRUE(bsp) << bsp.error().message;
  ASSERT_EQ(bsp->entities.size(), 5u);
  const std::vector<MapLight> lights = entityLights(*bsp);
  ASSERT_EQ(lights.size(), 3u);
  EXPECT_EQ(lights[0].value, 300.0);  // q3map2's default
  EXPECT_EQ(lights[0].kind, MapLightKind::kPoint);
  EXPECT_EQ(lights[1].kind, MapLightKind::kSpot);
  EXPECT_EQ(lights[1].value, 500.0);
  EXPECT_EQ(lights[1].color, glm::dvec3(1, 0.5, 0));
  EXPECT_EQ(lights[1].spotAxis, glm::dvec3(0, 0, -1));
  EXPECT_DOUBLE_EQ(lights[1].spotRadiusByDist, (48.0 + 16.0) / 64.0);
  EXPECT_TRUE(lights[2].linear);
  EXPECT_FALSE(lights[2].angleAttenuation);
  EXPECT_EQ(lights[2].value, 200.0);
}

TEST(Bsp, TheLightmapFloorAsQ3map2StoresIt) {
  // _minlight times _color (white when unset), through ColorToBytes: the -gamma curve, a brightest
  // channel above 255 scaled down to 255, truncated.
  const auto floorOf = [](const std::string& worldspawn, double gamma) {
    Bsp bsp;
    bsp.entities.push_back({{"classname", "worldspawn"}});
    std::istringstream in(worldspawn);
    std::string key, value;
    while (in >> key >> value) bsp.entities[0][key] = value;
    return minimumLightBytes(bsp, gamma);
  };
  EXPECT_EQ(floorOf("", 1.0), glm::dvec3(0.0));
  EXPECT_EQ(floorOf("_minlight 64", 1.0), glm::dvec3(64.0));
  EXPECT_EQ(floorOf("_minlight 64", 2.0), glm::dvec3(127.0));  // 255 (64/255)^(1/2) = 127.75
  Bsp coloured;
  coloured.entities.push_back({{"_minlight", "200"}, {"_color", "2 1 1"}});
  // (400, 200, 200) x (255 / 400), truncated: 254.99999... gives 254, as q3map2's clipped bytes do
  EXPECT_EQ(minimumLightBytes(coloured, 1.0), glm::dvec3(254.0, 127.0, 127.0));
}

TEST(Bsp, TheLightGridLiesWhereSetupGridLaysIt) {
  // The world's bounds (-100, -10, 0)-(130, 70, 256) with gridsize 32 32 100.7 (floored to 100):
  // x from 32 ceil(-100/32) = -96 to 32 floor(130/32) = 128, 8 points; y from 0 to 64, 3; z from 0
  // to 200, 3: 72 points of 8 bytes.
  const std::string entities = "{ \"classname\" \"worldspawn\" \"gridsize\" \"32 32 100.7\" }\n";
  const auto mapWithGrid = [&](int gridBytes) {
    const int models = 144 + static_cast<int>(entities.size()), grid = models + 40;
    std::vector<std::pair<int, int>> lumps(17, {144, 0});
    lumps[0] = {144, static_cast<int>(entities.size())};
    lumps[7] = {models, 40};
    lumps[15] = {grid, gridBytes};
    std::string bytes = header(lumps) + entities;
    const float bounds[6] = {-100, -10, 0, 130, 70, 256};
    bytes.append(reinterpret_cast<const char*>(bounds), sizeof(bounds));
    bytes.append(16, '\0');  // no surfaces or brushes
    for (int i = 0; i < gridBytes; ++i) bytes += static_cast<char>(i % 251);
    return parseBsp(bytes, "maps/grid.bsp");
  };
  auto bsp = mapWithGrid(72 * 8);
  ASSERT_TRUE(bsp) << bsp.error().message;
  const LightGrid& g = bsp->lightGrid;
  EXPECT_EQ(g.counts, glm::ivec3(8, 3, 3));
  EXPECT_EQ(g.spacing, glm::dvec3(32, 32, 100));
  EXPECT_EQ(g.origin, glm::dvec3(-96, 0, 0));
  ASSERT_EQ(g.points.size(), 72u);
  EXPECT_EQ(g.position(45), glm::dvec3(-96 + 5 * 32, 2 * 32, 100));  // 45 = 5 + 8 (2 + 3 * 1)
  EXPECT_EQ(g.points[45].ambient, (std::array<std::uint8_t, 3>{45 * 8 % 251, 45 * 8 % 251 + 1, 45 * 8 % 251 + 2}));
  EXPECT_EQ(g.points[45].direction[1], 45 * 8 % 251 + 7);
  // the checkerboard that halves the lattice: 45 is (5, 2, 1), 46 is (6, 2, 1)
  EXPECT_TRUE(g.even(45));
  EXPECT_FALSE(g.even(46));
  EXPECT_EQ(g.inhibitRadius(), 50.0);  // half z's step, the largest
  // NormalToLatLong by hand for (1, 1, 1)/sqrt 3: polar acos(1/sqrt 3) = 54.74 deg -> byte
  // (int)(54.74 * 255/360) = 38, azimuth 45 deg -> 31; decoded within the bytes' truncation
  // (under 1.42 deg on each angle); (0, 0) is straight up
  LightGridPoint p;
  p.direction = {38, 31};
  const double angle = std::acos(glm::dot(p.mainDirection(), glm::normalize(glm::dvec3(1.0)))) * 180.0 / std::numbers::pi;
  EXPECT_LT(angle, 2.0);
  EXPECT_GT(angle, 1.0);
  p.direction = {0, 0};
  EXPECT_NEAR(glm::length(p.mainDirection() - glm::dvec3(0, 0, 1)), 0.0, 1e-12);
  // a lump of another size is left out, as the engine leaves it out ("light grid mismatch")
  auto mismatched = mapWithGrid(71 * 8);
  ASSERT_TRUE(mismatched) << mismatched.error().message;
  EXPECT_TRUE(mismatched->lightGrid.points.empty());
}

TEST(MapLight, AGridPointsLightIsTheSumOfItsLights) {
  // TraceGrid by hand for two lights at a point: 100 units from +x and 40 from +y. The main
  // direction is (100, 40) normalised, d = (0.928, 0.371); directed = sum d c, ambient =
  // sum 0.25 (1 - d) c + directed / 8, stored truncated to bytes (gamma 1). The light from every
  // direction read back is the sum, 140, within the truncation (half a byte of directed, four of ambient).
  const glm::dvec2 main = glm::normalize(glm::dvec2(100, 40));
  const double d1 = main.x, d2 = main.y;
  const double directed = d1 * 100 + d2 * 40, ambient = 0.25 * (1 - d1) * 100 + 0.25 * (1 - d2) * 40 + directed / 8;
  LightGridPoint p;
  for (std::size_t k = 0; k < 3; ++k) {
    p.directed[k] = static_cast<std::uint8_t>(directed);
    p.ambient[k] = static_cast<std::uint8_t>(ambient);
  }
  EXPECT_EQ(p.directed[0], 107);
  EXPECT_EQ(p.ambient[0], 21);
  const glm::dvec3 light = gridPointLight(p, 1.0);
  EXPECT_NEAR(light.r, 140.0, 0.5 + 4.0);
  EXPECT_DOUBLE_EQ(light.r, 0.5 * 107 + 4 * 21);
  // -gamma 2 stores 255 (x / 255)^(1/2): undone before the sum
  LightGridPoint g2;
  g2.ambient = {128, 128, 128};
  EXPECT_NEAR(gridPointLight(g2, 2.0).g, 4.0 * 255.0 * std::pow(128.0 / 255.0, 2.0), 1e-9);
}

TEST(Bsp, BrokenFilesAreRefusedNamingTheMapAndLump) {
  auto shortFile = parseBsp("IBSP", "maps/a.bsp");
  ASSERT_FALSE(shortFile);
  EXPECT_NE(shortFile.error().message.find("maps/a.bsp"), std::string::npos);
  std::string wrong = header({});
  wrong[0] = 'X';
  auto ident = parseBsp(wrong, "maps/b.bsp");
  ASSERT_FALSE(ident);
  EXPECT_NE(ident.error().message.find("expected 'IBSP'"), std::string::npos);
  auto outside = parseBsp(header({{144, 0}, {100000, 72}}), "maps/c.bsp");
  ASSERT_FALSE(outside);
  EXPECT_NE(outside.error().message.find("maps/c.bsp: lump 1"), std::string::npos) << outside.error().message;
  auto ragged = parseBsp(header({{144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}, {144, 0}}) , "maps/d.bsp");
  ASSERT_FALSE(ragged);  // no world model
  EXPECT_NE(ragged.error().message.find("no models"), std::string::npos) << ragged.error().message;
}

TEST(ShaderScripts, LightKeywordsAndTheFirstDefinitionWin) {
  ShaderScripts scripts;
  ASSERT_TRUE(scripts.add("// a comment\n"
                          "textures/x/lamp\n{\n  q3map_surfacelight 2500\n  q3map_lightRGB 2 1 0\n  q3map_backsplash 10 16\n"
                          "  q3map_lightSubdivide 64\n  cull none\n  { map textures/x/lamp.tga\n  }\n}\n"
                          "textures/x/sky\n{\n  q3map_sun 1 1 1 120 90 45 /* noon-ish */\n  surfaceparm nolightmap\n}\n",
                          "a.shader"));
  ASSERT_TRUE(scripts.add("textures/x/LAMP\n{\n  q3map_surfacelight 1\n}\n", "b.shader"));
  const ShaderLighting* lamp = scripts.find("textures/X/lamp");
  ASSERT_NE(lamp, nullptr);
  EXPECT_EQ(lamp->surfaceLight, 2500.0);  // a.shader's, the first
  ASSERT_TRUE(lamp->lightRgb);
  EXPECT_EQ(*lamp->lightRgb, glm::dvec3(1, 0.5, 0));
  EXPECT_DOUBLE_EQ(lamp->backsplashFraction, 0.1);
  EXPECT_EQ(lamp->lightSubdivide, 64.0);
  EXPECT_TRUE(lamp->twoSided);
  EXPECT_EQ(lamp->firstStageImage, "textures/x/lamp.tga");
  const ShaderLighting* sky = scripts.find("textures/x/sky");
  ASSERT_NE(sky, nullptr);
  ASSERT_EQ(sky->suns.size(), 1u);
  EXPECT_TRUE(sky->sky);
  EXPECT_FALSE(sky->twoSided);
  EXPECT_EQ(sky->lightSubdivide, 0.0);
  EXPECT_NEAR(glm::length(sky->suns[0].color), 1.0, 1e-12);
  EXPECT_NEAR(sky->suns[0].towardsSun.y, std::cos(std::numbers::pi / 4), 1e-12);
  EXPECT_NEAR(sky->suns[0].towardsSun.z, std::sin(std::numbers::pi / 4), 1e-12);
  auto unclosed = scripts.add("textures/x/broken\n{\n  q3map_surfacelight 5\n", "c.shader");
  ASSERT_FALSE(unclosed);
  EXPECT_NE(unclosed.error().message.find("c.shader:1: shader 'textures/x/broken' is not closed"), std::string::npos) << unclosed.error().message;
}

TEST(GameFiles, AFolderWithoutArchivesIsAnError) {
  const auto folder = std::filesystem::temp_directory_path() / "dynbench-no-paks";
  std::filesystem::create_directories(folder);
  auto files = GameFiles::open(folder);
  ASSERT_FALSE(files);
  EXPECT_NE(files.error().message.find("no .pk3 archives"), std::string::npos);
  std::filesystem::remove_all(folder);
}

// On Debian's OpenArena data (no game run), three fits, each its own test so that ctest can run
// them beside others: oa_dm2's lightmaps are reproduced by its fitted lights; oa_ctf2's real lights,
// hidden, are found again (its 48 dim lights in narrow corridors are the hardest of the four maps
// that keep their lights: 48 % of their value with the lattice's candidates alone, before the
// residual's hot spots added theirs); and a fit run as another machine would run it, unjudged as
// a capture runs it, gives the same lights byte for byte (a smaller fit of q3dm6ish with the light
// grid as fit data, to keep the suite's time).
MapLightFitOptions hiddenLights() {
  MapLightFitOptions hidden;
  hidden.hideEntityLights = true;
  return hidden;
}

TEST(OpenArena, FittedLightsReproduceTheLightmapsAndTheLightGrid) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  auto files = GameFiles::open("/usr/lib/openarena/baseoa");
  ASSERT_TRUE(files) << files.error().message;
  // oa_dm2 (converted from Quake 1): 0.75 before q3map2's own surface lights (a light per
  // triangle, two-sided lava, light through the sky) and its clipped texels at 254 (fit version 6)
  auto dm2 = fitMapLighting(*files, "oa_dm2");
  ASSERT_TRUE(dm2) << dm2.error().message;
  EXPECT_GE(dm2->report.heldOutCorrelation, 0.80);
  EXPECT_GT(dm2->report.fittedLights, 20u);
  const auto back = std::find_if(dm2->report.groupWeights.begin(), dm2->report.groupWeights.end(),
                                 [](const auto& g) { return g.first == "surface light textures/liquids/lavahell_xdm1 (its back)"; });
  EXPECT_NE(back, dm2->report.groupWeights.end()) << "the lava (cull none) lights from its back too";
  // The light grid, never fitted, agrees with the fitted lights (0.781 on 1,454 points, 2026-11-28)
  // far better than with the known emitters alone (0.371)
  EXPECT_GT(dm2->report.gridPoints, 1000u);
  EXPECT_GE(dm2->report.gridCorrelation, 0.70);
  EXPECT_GT(dm2->report.gridCorrelation, dm2->report.gridKnownCorrelation + 0.2);
  EXPECT_FALSE(dm2->report.gridFitted) << "no floor: the lightmaps alone are fitted";
}

TEST(OpenArena, HiddenLightsAreFoundAgain) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  auto files = GameFiles::open("/usr/lib/openarena/baseoa");
  ASSERT_TRUE(files) << files.error().message;
  auto recovered = fitMapLighting(*files, "oa_ctf2", hiddenLights());
  ASSERT_TRUE(recovered) << recovered.error().message;
  EXPECT_EQ(recovered->report.hiddenLightValue, 48 * 60.0);
  EXPECT_GT(recovered->report.candidates, recovered->report.latticeCandidates) << "candidates at the residual's hot spots";
  // 81.2 % with the light grid as fit data beside the floored lightmaps, 77.1 % without (2026-11-28)
  EXPECT_GE(recovered->report.recoveredShare, 0.80);
  EXPECT_TRUE(recovered->report.gridFitted);
  EXPECT_GT(recovered->report.gridFitPoints, 5000u);
  // oa_ctf2's _minlight 64: most texels read the floor, and some of its dim lights light none above it
  EXPECT_EQ(recovered->report.floorBytes, glm::dvec3(64.0));
  EXPECT_GT(recovered->report.flooredTexels, recovered->report.texels / 2);
  EXPECT_LT(recovered->report.shownLightValue, recovered->report.hiddenLightValue);
  EXPECT_GT(recovered->report.shownLightValue, 0.5 * recovered->report.hiddenLightValue);
  EXPECT_GT(recovered->report.recoveredShownShare, recovered->report.recoveredShare);
  EXPECT_EQ(recovered->report.gridPoints, 0u) << "the floor raises every grid point's ambient too";
}

TEST(OpenArena, AFitIsTheSameBytesOnAnotherMachineAndUnjudged) {
  DYNBENCH_NEEDS(test::missingOpenArena());
  auto files = GameFiles::open("/usr/lib/openarena/baseoa");
  ASSERT_TRUE(files) << files.error().message;
  MapLightFitOptions small = hiddenLights();
  small.fitSamples = 6000;
  small.maxCandidates = 2000;
  small.gridFit = GridFit::kAlways;  // the light grid's rows too, which oa_ctf2's fit uses
  auto here = fitMapLighting(*files, "q3dm6ish", small);
  ASSERT_TRUE(here) << here.error().message;
  EXPECT_GT(here->report.fittedLights, 5u);
  const auto dir = std::filesystem::temp_directory_path() / "dynbench-maplight-test";
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(writeAdapterLights(dir / "a.txt", *here));
  {
    // as another machine would fit it (glibc's maths without AVX2 and FMA; the fit's tracer has no
    // instruction a vendor decides: TriangleBvh.TheFitsCodeHasNoInstructionAVendorDecides), and as
    // a capture fits it, unjudged
    test::OtherMachine other;
    const auto r = ::dynbench::dynbench(fmt::format("map-lights q3dm6ish --hide-entity-lights --fit-samples 6000 --max-candidates 2000 --grid-fit always "
                                                    "--no-judge --adapter-lights {}",
                                                    (dir / "c.txt").string()),
                                        dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("not judged (--no-judge)"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("held-out texels ("), std::string::npos) << r.out;
  }
  EXPECT_EQ(test::slurp(dir / "a.txt"), test::slurp(dir / "c.txt"));
  const auto unknown = ::dynbench::dynbench("map-lights q3dm6ish --grid-fit sometimes", dir);
  EXPECT_EQ(unknown.status, 2);
  EXPECT_NE(unknown.err.find("--grid-fit: sometimes not in {where-floored,never,always}"), std::string::npos) << unknown.err;
  EXPECT_GT(here->report.heldOutCorrelation, 0.5);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dynbench::maplight
