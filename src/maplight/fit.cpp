#include "maplight/fit.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <map>
#include <set>
#include <cmath>
#include <fstream>
#include <numbers>
#include <numeric>
#include <regex>
#include <sstream>

#include <tbb/parallel_for.h>

#include "core/files.h"
#include "core/math.h"
#include "maplight/nnls.h"
#include "maplight/triangle_bvh.h"

namespace dynbench::maplight {

namespace {

constexpr double kNudge = 1.0;  // units a sample is lifted off its surface before tracing (q3map2 nudges too)
// Units between a candidate light and every surface. Lightmap texels are 16 units apart (q3map2's
// default sample size), so a light nearer than two of them can fit a few texels' values with a hot
// spot between them that the held-out texels show up (oa_bases3 at 16 units: variance explained
// on held-out texels fell below 0).
constexpr double kCandidateClearance = 32.0;
// The byte from which a lightmap texel is clipped. ColorToBytes scales a colour whose brightest
// channel passes 255 by 255 / max in float and truncates to a byte, which gives 254 as often as
// 255 (254.99997). The lightmaps show it: on seven of the nine stock maps the brightest channel is
// 254 on 5-30 times as many texels as on 250-253 (oa_dm2: 5,223 against about 180 each).
constexpr std::uint8_t kClippedByte = 254;

// A lightmap or light grid byte as linear lightmap units: q3map2's ColorToBytes applied the map's
// -gamma (255 (x / 255)^(1 / gamma)), undone here.
double linearFromByte(std::uint8_t b, double gamma) { return 255.0 * std::pow(b / 255.0, gamma); }

// Whether some channel of a stored colour is clipped (kClippedByte or above).
bool clippedColor(const std::uint8_t* rgb) { return std::max({rgb[0], rgb[1], rgb[2]}) >= kClippedByte; }

// Whether some channel of a stored colour reads the map's floor (minimumLightBytes; 0: none).
bool atFloor(const std::uint8_t* rgb, const glm::dvec3& floorBytes) {
  for (int k = 0; k < 3; ++k)
    if (floorBytes[k] > 0 && rgb[k] <= floorBytes[k]) return true;
  return false;
}
// Steps a fitted light may take at one scale of the refinement before the scale halves.
constexpr int kRefineStepsPerScale = 8;

struct Sample {
  glm::dvec3 position{0.0}, normal{0.0};
  glm::dvec3 value{0.0};  // linear lightmap units
  // Some channel at the map's lightmap floor (minimumLightBytes): the light there reads as the
  // floor whatever it is below it. The fit takes the value as it reads (a censored fit measured
  // worse: integrations/openarena/README.md); the recovery report asks which lights show above it.
  bool floored = false;
  // A light grid point (LightContributionToPoint) rather than a texel: it receives light from
  // every direction, its traces pass through what lies within `inhibit` of it, and, where
  // `mainDirection` is set, it is the point's directed light: each light's times its cosine to
  // that direction (TraceGrid). `normal` is then the main direction too (the residual's hot
  // spots put candidates along it).
  bool point = false;
  double inhibit = 0.0;
  glm::dvec3 mainDirection{0.0};
};

// Units a visibility trace leaves out at either end: its ends lie on surfaces (a texel nudged onto
// another face, an emitter's own face), which rounding would otherwise put in front of or behind
// them (Embree's tnear = 0 and float rounding did the same at the near end).
constexpr double kTraceMargin = 1e-3;

// The map's geometry as the fit's traces see it (maplight/triangle_bvh.h: why not Embree): `all`
// holds the solid surfaces (group 0) and the sky's (group 1); `solid` the solid ones alone, as
// q3map2's light traces see the map (light_trace.c ignores sky surfaces: light passes through them).
struct Occluders {
  TriangleBvh all, solid;
  // Surfaces nearer `from` than `inhibit` are passed through (q3map2's inhibitRadius: a grid
  // point's traces ignore what lies within half a grid step of it).
  bool visible(const glm::dvec3& from, const glm::dvec3& to, double inhibit = 0.0) const {
    const glm::dvec3 d = to - from;
    const double length = glm::length(d);
    if (length <= inhibit + 1e-6) return true;
    return !solid.occluded(from + inhibit * (d / length), d / length, kTraceMargin, length - inhibit - kTraceMargin);
  }
  // Whether a ray from `from` towards `direction` reaches the sky (or leaves the map).
  bool seesSky(const glm::dvec3& from, const glm::dvec3& direction, double inhibit = 0.0) const {
    const BvhHit hit = all.intersect(from + inhibit * direction, direction, kTraceMargin);
    return !hit.hit || hit.group == 1;
  }
};

bool drawn(const Bsp& bsp, const ShaderScripts& scripts, const BspSurface& s, bool& sky) {
  if (s.type == BspSurfaceType::kBad || s.type == BspSurfaceType::kFlare) return false;
  const BspShader& shader = bsp.shaders[static_cast<std::size_t>(s.shader)];
  const ShaderLighting* script = scripts.find(shader.name);
  sky = (shader.surfaceFlags & kSurfaceSky) != 0 || (script && script->sky);
  if ((shader.surfaceFlags & kSurfaceNoDraw) != 0 || (script && script->noDraw)) return false;
  return !(script && script->translucent) || sky;
}

Occluders buildOccluders(const Bsp& bsp, const ShaderScripts& scripts) {
  std::vector<BvhTriangle> all, solid;
  const BspModel& world = bsp.models[0];
  for (int i = world.firstSurface; i < world.firstSurface + world.surfaceCount; ++i) {
    bool sky = false;
    if (!drawn(bsp, scripts, bsp.surfaces[static_cast<std::size_t>(i)], sky)) continue;
    for (const SurfaceTriangle& t : surfaceTriangles(bsp, i)) {
      const BvhTriangle triangle{t.position, t.normal, sky ? 1 : 0};
      all.push_back(triangle);
      if (!sky) solid.push_back(triangle);
    }
  }
  return Occluders{TriangleBvh(std::move(all)), TriangleBvh(std::move(solid))};
}

double gammaOf(const Bsp& bsp) {
  if (bsp.entities.empty()) return 1.0;
  const std::string cmdline = entityValue(bsp.entities[0], "_q3map2_cmdline");
  static const std::regex gamma(R"((?:^|\s)-gamma\s+([0-9.]+))");
  std::smatch m;
  if (std::regex_search(cmdline, m, gamma)) {
    const double g = std::atof(m[1].str().c_str());
    if (g > 0) return g;
  }
  return 1.0;
}

}  // namespace

// The map's lightmap floor in bytes, per channel: q3map2 raises every texel's colour to at least
// worldspawn's `_minlight` times its `_color` (white when unset; light.c), then stores it with
// ColorToBytes (the -gamma curve, a brightest channel above 255 scaled down to it, truncated;
// lightmaps_ydnar.c, StoreSurfaceLightmaps). 0 where the map sets no floor. oa_ctf2's
// `_minlight 64` floors 80 % of its lit texels.
glm::dvec3 minimumLightBytes(const Bsp& bsp, double gamma) {
  if (bsp.entities.empty()) return glm::dvec3(0.0);
  const std::string value = entityValue(bsp.entities[0], "_minlight");
  const double f = value.empty() ? 0.0 : std::atof(value.c_str());
  if (!(f > 0)) return glm::dvec3(0.0);
  glm::dvec3 color(0.0);
  std::istringstream in(entityValue(bsp.entities[0], "_color"));
  in >> color.x >> color.y >> color.z;
  if (!in || glm::length(color) == 0.0) color = glm::dvec3(1.0);
  glm::dvec3 bytes = color * f;
  for (int k = 0; k < 3; ++k) bytes[k] = bytes[k] > 0 ? 255.0 * std::pow(bytes[k] / 255.0, 1.0 / gamma) : 0.0;
  const double brightest = std::max({bytes.x, bytes.y, bytes.z});
  if (brightest > 255.0) bytes *= 255.0 / brightest;
  return glm::floor(bytes);
}

namespace {

// A lightmap texel of a drawn, lightmapped world surface: where it lies on its page, and its sample.
struct Texel {
  int x = 0, y = 0;
  Sample sample;
};

struct LightmapTexels {
  std::vector<Texel> unclipped;  // in surface, triangle and row order
  std::size_t texels = 0, clipped = 0, floored = 0;
};

// Every lightmap texel of the world's drawn, lightmapped surfaces, each once (the first triangle
// over a texel's centre owns it); those clipped (kClippedByte) are only counted.
LightmapTexels lightmapTexels(const Bsp& bsp, const ShaderScripts& scripts, double gamma, const glm::dvec3& floorBytes) {
  LightmapTexels out;
  std::vector<std::vector<char>> owned(bsp.lightmaps.size(), std::vector<char>(kLightmapSize * kLightmapSize, 0));
  const BspModel& world = bsp.models[0];
  for (int i = world.firstSurface; i < world.firstSurface + world.surfaceCount; ++i) {
    const BspSurface& s = bsp.surfaces[static_cast<std::size_t>(i)];
    bool sky = false;
    if (s.lightmap < 0 || !drawn(bsp, scripts, s, sky) || sky) continue;
    if (bsp.shaders[static_cast<std::size_t>(s.shader)].surfaceFlags & kSurfaceNoLightmap) continue;
    const auto& page = bsp.lightmaps[static_cast<std::size_t>(s.lightmap)];
    auto& own = owned[static_cast<std::size_t>(s.lightmap)];
    for (const SurfaceTriangle& t : surfaceTriangles(bsp, i)) {
      std::array<glm::dvec2, 3> uv;
      for (int k = 0; k < 3; ++k) uv[static_cast<std::size_t>(k)] = t.lightmap[static_cast<std::size_t>(k)] * static_cast<double>(kLightmapSize);
      const double area = (uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (uv[1].y - uv[0].y);
      if (std::abs(area) < 1e-9) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({uv[0].x, uv[1].x, uv[2].x}))));
      const int x1 = std::min(kLightmapSize - 1, static_cast<int>(std::ceil(std::max({uv[0].x, uv[1].x, uv[2].x}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({uv[0].y, uv[1].y, uv[2].y}))));
      const int y1 = std::min(kLightmapSize - 1, static_cast<int>(std::ceil(std::max({uv[0].y, uv[1].y, uv[2].y}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const glm::dvec2 c(x + 0.5, y + 0.5);
          const double w1 = ((c.x - uv[0].x) * (uv[2].y - uv[0].y) - (uv[2].x - uv[0].x) * (c.y - uv[0].y)) / area;
          const double w2 = ((uv[1].x - uv[0].x) * (c.y - uv[0].y) - (c.x - uv[0].x) * (uv[1].y - uv[0].y)) / area;
          const double w0 = 1.0 - w1 - w2;
          if (w0 < 0 || w1 < 0 || w2 < 0) continue;
          char& mark = own[static_cast<std::size_t>(y * kLightmapSize + x)];
          if (mark) continue;
          mark = 1;
          const std::uint8_t* rgb = &page[static_cast<std::size_t>((y * kLightmapSize + x) * 3)];
          ++out.texels;
          // ColorToBytes normalises a colour whose brightest channel passes 255 to 255 in float and
          // truncates, so the clipped channel reads 254 or 255: its level is lost
          if (clippedColor(rgb)) {
            ++out.clipped;
            continue;
          }
          glm::dvec3 n = w0 * t.normal[0] + w1 * t.normal[1] + w2 * t.normal[2];
          if (glm::length(n) <= 0) continue;
          n = glm::normalize(n);
          Texel texel{x, y, {}};
          texel.sample.normal = n;
          texel.sample.position = w0 * t.position[0] + w1 * t.position[1] + w2 * t.position[2] + kNudge * n;
          for (int k = 0; k < 3; ++k) texel.sample.value[k] = linearFromByte(rgb[k], gamma);
          texel.sample.floored = atFloor(rgb, floorBytes);
          out.floored += texel.sample.floored;
          out.unclipped.push_back(texel);
        }
    }
  }
  return out;
}

// A regular subset of the texels: those whose page coordinates are multiples of `stride` plus `offset`.
std::vector<Sample> texelSubset(const std::vector<Texel>& texels, int stride, int offset) {
  std::vector<Sample> samples;
  for (const Texel& t : texels)
    if (((t.x - offset) % stride + stride) % stride == 0 && ((t.y - offset) % stride + stride) % stride == 0) samples.push_back(t.sample);
  return samples;
}

double polygonArea(const std::vector<glm::dvec3>& w) {
  glm::dvec3 sum(0.0);
  for (std::size_t i = 2; i < w.size(); ++i) sum += glm::cross(w[i - 1] - w[0], w[i] - w[0]);
  return 0.5 * glm::length(sum);
}

// A winding's axis-aligned bounds: {lowest, highest} corner.
std::pair<glm::dvec3, glm::dvec3> bounds(const std::vector<glm::dvec3>& w) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dvec3& p : w) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  return {lo, hi};
}

void subdivideInto(const std::vector<glm::dvec3>& w, double size, std::vector<std::vector<glm::dvec3>>& out, bool& split, int depth) {
  const auto [lo, hi] = bounds(w);
  for (int axis = 0; axis < 3 && depth < 24; ++axis) {
    if (hi[axis] - lo[axis] <= size) continue;
    const double mid = 0.5 * (hi[axis] + lo[axis]);
    std::vector<glm::dvec3> front, back;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const glm::dvec3& a = w[i];
      const glm::dvec3& b = w[(i + 1) % w.size()];
      const double da = a[axis] - mid, db = b[axis] - mid;
      if (da >= 0) front.push_back(a);
      if (da <= 0) back.push_back(a);
      if ((da > 0 && db < 0) || (da < 0 && db > 0)) {
        const glm::dvec3 m = a + (b - a) * (da / (da - db));
        front.push_back(m);
        back.push_back(m);
      }
    }
    split = true;
    if (front.size() >= 3) subdivideInto(front, size, out, split, depth + 1);
    if (back.size() >= 3) subdivideInto(back, size, out, split, depth + 1);
    return;
  }
  out.push_back(w);
}

std::vector<SurfaceEmitter> surfaceEmitters(const Bsp& bsp, const ShaderScripts& scripts, const GameFiles& files) {
  std::vector<SurfaceEmitter> emitters;
  std::map<int, glm::dvec3> colors;
  const BspModel& world = bsp.models[0];
  for (int i = world.firstSurface; i < world.firstSurface + world.surfaceCount; ++i) {
    const BspSurface& s = bsp.surfaces[static_cast<std::size_t>(i)];
    const ShaderLighting* script = scripts.find(bsp.shaders[static_cast<std::size_t>(s.shader)].name);
    if (!script || script->surfaceLight <= 0) continue;
    if (!colors.contains(s.shader)) colors[s.shader] = surfaceLightColor(*script, files);
    const double subdivide = script->lightSubdivide > 0 ? script->lightSubdivide : kDefaultLightSubdivide;
    // q3map2 makes area lights of each triangle (RadLightForTriangles; a patch's quads, here its
    // triangles), as its light stage reads them
    for (const SurfaceTriangle& t : surfaceTriangles(bsp, i)) {
      bool split = false;
      std::vector<std::vector<glm::dvec3>> pieces = subdivideWinding({t.position.begin(), t.position.end()}, subdivide, &split);
      const glm::dvec3 facing = t.normal[0] + t.normal[1] + t.normal[2];  // the side the BSP's normals give it
      if (glm::length(facing) <= 0) continue;
      for (auto& piece : pieces) {
        const double area = polygonArea(piece);
        if (area < 1.0 || area > 20000000.0) continue;  // q3map2's bounds
        const glm::dvec3 cross = glm::cross(piece[1] - piece[0], piece[2] - piece[0]);
        if (glm::length(cross) <= 1e-9) continue;
        SurfaceEmitter e;
        e.normal = glm::normalize(facing);
        const auto [lo, hi] = bounds(piece);
        e.origin = 0.5 * (lo + hi) + e.normal;
        e.winding = std::move(piece);
        e.color = colors[s.shader];
        e.value = script->surfaceLight;
        e.twoSided = script->twoSided;
        if (!split) {
          e.backsplashFraction = script->backsplashFraction;
          e.backsplashDistance = script->backsplashDistance;
        }
        e.shader = s.shader;
        e.shaderName = bsp.shaders[static_cast<std::size_t>(s.shader)].name;
        emitters.push_back(std::move(e));
      }
    }
  }
  return emitters;
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = a.size();
  if (n < 2) return 0.0;
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n, mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

struct Column {
  std::vector<std::uint32_t> rows;
  std::vector<float> values;
  double norm2 = 0.0;
};

// A group of known emitters whose strength the fit confirms with one weight: one light entity, one
// sun, or every piece of one shader's surface light. Its colour is shared.
// A two-sided surface light's back is a group of its own: q3map2 lights both sides of a `cull none`
// shader's surfaces (LIGHT_TWOSIDED) since some version, and the stock maps were compiled by
// several; the lightmaps then say with the back's weight whether that map's compile did.
enum class EmitterSide { kBoth, kFront, kBack };
struct EmitterGroup {
  std::string name;
  glm::dvec3 color{1.0};
  std::vector<std::size_t> lights;    // indices into MapLighting::lights
  std::vector<std::size_t> surfaces;  // indices into MapLighting::surfaceLights
  EmitterSide side = EmitterSide::kBoth;  // the surfaces' light from which side
  std::size_t backGroup = 0;              // a kFront group's kBack partner (same surfaces)
};

// The normal a sample receives light from `towards` with: a texel's own, or for a grid point
// the direction to the light (each emitter seen head on).
glm::dvec3 receivingNormal(const Sample& s, const glm::dvec3& towards) {
  if (!s.point) return s.normal;
  const glm::dvec3 d = towards - s.position;
  const double length = glm::length(d);
  return length > 0 ? d / length : glm::dvec3(0.0, 0.0, 1.0);
}

// The share of a light from direction `direction` a sample counts: all of it, or at a grid point
// read for its directed light, its cosine to the point's main direction (at least 0).
double directedShare(const Sample& s, const glm::dvec3& direction) {
  if (!s.point || s.mainDirection == glm::dvec3(0.0)) return 1.0;
  return std::max(0.0, glm::dot(direction, s.mainDirection));
}

// Every group's light at every sample (q3map2's model, lightmap units per unit colour, visibility
// included) as sparse columns.
std::vector<Column> groupColumns(const std::vector<Sample>& samples, const std::vector<EmitterGroup>& groups, const std::vector<MapLight>& lights,
                                 const std::vector<SurfaceEmitter>& surfaces, const Occluders& occluders) {
  const std::size_t g = groups.size();
  // per piece, once: the radius of its bounding sphere about the point traced to, and its area
  struct Piece {
    double radius = 0.0, area = 0.0;
  };
  std::vector<Piece> pieces(surfaces.size());
  for (std::size_t ei = 0; ei < surfaces.size(); ++ei) {
    const SurfaceEmitter& e = surfaces[ei];
    for (const glm::dvec3& p : e.winding) pieces[ei].radius = std::max(pieces[ei].radius, glm::length(p - e.origin));
    pieces[ei].area = polygonArea(e.winding);
  }
  std::vector<float> dense(samples.size() * g, 0.0f);
  tbb::parallel_for(std::size_t(0), samples.size(), [&](std::size_t i) {
    const Sample& s = samples[i];
    const double inhibit = s.inhibit;
    for (std::size_t k = 0; k < g; ++k) {
      double sum = 0.0;
      for (std::size_t li : groups[k].lights) {
        const MapLight& l = lights[li];
        const glm::dvec3 normal = l.kind == MapLightKind::kSun ? (s.point ? l.towardsSun : s.normal) : receivingNormal(s, l.position);
        const double add = lightContribution(l, s.position, normal) * directedShare(s, normal);
        if (add <= 0) continue;
        const bool visible = l.kind == MapLightKind::kSun ? occluders.seesSky(s.position, l.towardsSun, inhibit)
                                                           : occluders.visible(s.position, l.position, inhibit);
        if (visible) sum += add;
      }
      // a two-sided shader's pieces are evaluated once, by its front group, which credits its
      // back group with the light from behind
      const EmitterSide side = groups[k].side;
      if (side == EmitterSide::kBack) continue;
      double backSum = 0.0;
      for (std::size_t ei : groups[k].surfaces) {
        const SurfaceEmitter& e = surfaces[ei];
        const double area = pieces[ei].area;
        // a bound first: the form factor is at most area / (pi distance^2) from the piece's bounding sphere
        const double distance = glm::length(s.position - e.origin) - pieces[ei].radius;
        const bool negligible = distance > 0 && area / (std::numbers::pi * distance * distance) * e.value * kFormFactorValueScale * kAreaScale < 0.01;
        if (!negligible) {
          bool fromBack = false;
          const glm::dvec3 normal = receivingNormal(s, e.origin);
          const double add = surfaceContribution(e, s.position, normal, &fromBack) * directedShare(s, normal);
          if (add > 0 && occluders.visible(s.position, fromBack ? e.origin - 2.0 * e.normal : e.origin, inhibit)) {
            if (fromBack && side == EmitterSide::kFront) backSum += add;
            else sum += add;
          }
        }
        if (e.backsplashFraction > 0) {
          // the point light q3map2 puts in front of an undivided piece: photons V area areaScale fraction, no pointScale
          MapLight splash;
          splash.position = e.origin + e.normal * e.backsplashDistance;
          splash.value = e.value * area * kAreaScale * e.backsplashFraction / kPointScale;
          const glm::dvec3 normal = receivingNormal(s, splash.position);
          const double b = lightContribution(splash, s.position, normal) * directedShare(s, normal);
          if (b > 0.01 && occluders.visible(s.position, splash.position, inhibit)) sum += b;
        }
      }
      dense[i * g + k] = static_cast<float>(sum);
      if (side == EmitterSide::kFront) dense[i * g + groups[k].backGroup] = static_cast<float>(backSum);
    }
  });
  std::vector<Column> columns(g);
  for (std::size_t i = 0; i < samples.size(); ++i)
    for (std::size_t k = 0; k < g; ++k)
      if (const float v = dense[i * g + k]; v > 0) {
        columns[k].rows.push_back(static_cast<std::uint32_t>(i));
        columns[k].values.push_back(v);
        columns[k].norm2 += static_cast<double>(v) * v;
      }
  return columns;
}

// A candidate point light of V = 1 at `position`: its light at every sample, visibility included.
Column candidateColumn(const glm::dvec3& position, const std::vector<Sample>& samples, const Occluders& occluders) {
  Column c;
  MapLight light;
  light.position = position;
  light.value = 1.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    const glm::dvec3 normal = receivingNormal(s, position);
    const double add = lightContribution(light, s.position, normal) * directedShare(s, normal);
    // below 1/4 of a byte for the brightest entity lights q3map2 maps use (V ~ 1000): nothing
    if (add * 1000.0 < 0.25) continue;
    if (!occluders.visible(s.position, position, s.inhibit)) continue;
    c.rows.push_back(static_cast<std::uint32_t>(i));
    c.values.push_back(static_cast<float>(add));
    c.norm2 += add * add;
  }
  return c;
}

// Whether a point lies in open space: at least kCandidateClearance from every surface, inside the map's
// sealed hull (rays in 14 directions all end on the front of a surface or on the sky).
bool inOpenSpace(const glm::dvec3& p, const Occluders& occluders) {
  static const std::vector<glm::dvec3> directions = [] {
    std::vector<glm::dvec3> d;
    for (int a = 0; a < 3; ++a)
      for (int s : {-1, 1}) {
        glm::dvec3 axis(0.0);
        axis[a] = s;
        d.push_back(axis);
      }
    for (int x : {-1, 1})
      for (int y : {-1, 1})
        for (int z : {-1, 1}) d.push_back(glm::normalize(glm::dvec3(x, y, z)));
    return d;
  }();
  for (const glm::dvec3& d : directions) {
    const BvhHit hit = occluders.all.intersect(p, d, kTraceMargin);
    if (!hit.hit) return false;
    if (hit.group == 1) continue;  // the sky
    // the surface's own side: its vertex normals (the BSP's), not a winding convention
    if (hit.distance < kCandidateClearance || glm::dot(hit.shadingNormal, d) > 0) return false;
  }
  return true;
}

// Lattice points in open space, the lattice as fine as maxCandidates allows.
std::vector<glm::dvec3> openSpaceLattice(const Bsp& bsp, const Occluders& occluders, int maxCandidates, std::size_t& spacing) {
  const glm::dvec3 lo = glm::dvec3(bsp.models[0].mins) + kMinimumDistance, hi = glm::dvec3(bsp.models[0].maxs) - kMinimumDistance;
  const glm::dvec3 size = glm::max(hi - lo, glm::dvec3(1.0));
  const auto open = [&](const glm::dvec3& p) { return inOpenSpace(p, occluders); };
  // Off the map's grid by a fraction of a unit: brushes lie on whole (mostly 8- and 16-unit)
  // coordinates, so a lattice on them sends its axis and diagonal rays along walls' planes and
  // edges, where whether a ray hits is decided by rounding (half a million such rays on oa_dm1:
  // 14,155 hit differently in Embree and in triangle_bvh.h; none once off the grid).
  const glm::dvec3 offGrid(0.37, 0.23, 0.11);
  // Coarsen the lattice until the open points are few enough (deterministic: spacing in 8-unit steps).
  for (double step = 32.0;; step += 8.0) {
    const glm::ivec3 n = glm::ivec3(glm::floor(size / step)) + 1;
    const std::size_t total = static_cast<std::size_t>(n.x) * n.y * n.z;
    if (total > static_cast<std::size_t>(maxCandidates) * 20) continue;
    std::vector<char> isOpen(total, 0);
    tbb::parallel_for(std::size_t(0), total, [&](std::size_t k) {
      const int x = static_cast<int>(k % n.x), y = static_cast<int>((k / n.x) % n.y), z = static_cast<int>(k / (static_cast<std::size_t>(n.x) * n.y));
      isOpen[k] = open(lo + offGrid + glm::dvec3(x, y, z) * step) ? 1 : 0;
    });
    const auto count = static_cast<std::size_t>(std::count(isOpen.begin(), isOpen.end(), 1));
    if (count > static_cast<std::size_t>(maxCandidates)) continue;
    std::vector<glm::dvec3> points;
    for (std::size_t k = 0; k < total; ++k)
      if (isOpen[k]) {
        const int x = static_cast<int>(k % n.x), y = static_cast<int>((k / n.x) % n.y), z = static_cast<int>(k / (static_cast<std::size_t>(n.x) * n.y));
        points.push_back(lo + offGrid + glm::dvec3(x, y, z) * step);
      }
    spacing = static_cast<std::size_t>(step);
    return points;
  }
}

// Candidates where the lightmaps point at a light. A point light near a surface makes a hot spot
// at the foot of its perpendicular, so each peak of the residual (the texels less the known
// emitters and the constant) gets candidates along its normal. The lattice alone misses lights in
// spaces about as narrow as its spacing: oa_ctf2's dim lights (value 60) hang in corridors where
// its 64-unit-clear band holds few lattice points. Peaks: the samples in falling order of residual,
// each at least kPeakSeparation from every brighter one, down to a quarter of full light.
std::vector<glm::dvec3> hotSpotCandidates(const std::vector<Sample>& samples, const std::vector<double>& residual, const Occluders& occluders,
                                          std::size_t maxPeaks) {
  constexpr double kPeakSeparation = 48.0;  // units: three texels
  constexpr std::array kDistances{32.0, 48.0, 64.0, 96.0, 128.0};
  std::vector<std::size_t> order(samples.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return residual[a] > residual[b]; });
  std::vector<std::size_t> peaks;
  for (std::size_t i : order) {
    if (residual[i] < 0.25 * kFullLight || peaks.size() >= maxPeaks) break;
    const bool nearBrighter = std::any_of(peaks.begin(), peaks.end(), [&](std::size_t p) {
      return glm::length(samples[p].position - samples[i].position) < kPeakSeparation;
    });
    if (!nearBrighter) peaks.push_back(i);
  }
  std::vector<glm::dvec3> trials;
  for (std::size_t p : peaks)
    for (double d : kDistances) trials.push_back(samples[p].position + d * samples[p].normal);
  std::vector<char> open(trials.size(), 0);
  tbb::parallel_for(std::size_t(0), trials.size(), [&](std::size_t t) { open[t] = inOpenSpace(trials[t], occluders) ? 1 : 0; });
  std::vector<glm::dvec3> candidates;
  for (std::size_t t = 0; t < trials.size(); ++t)
    if (open[t]) candidates.push_back(trials[t]);
  return candidates;
}

double dot(const Column& c, const std::vector<double>& dense) {
  double s = 0;
  for (std::size_t k = 0; k < c.rows.size(); ++k) s += c.values[k] * dense[c.rows[k]];
  return s;
}

}  // namespace

std::vector<std::vector<glm::dvec3>> subdivideWinding(const std::vector<glm::dvec3>& winding, double size, bool* split) {
  std::vector<std::vector<glm::dvec3>> pieces;
  bool halved = false;
  subdivideInto(winding, size, pieces, halved, 0);
  if (split) *split = halved;
  return pieces;
}

double formFactor(const std::vector<glm::dvec3>& polygon, const glm::dvec3& point, const glm::dvec3& normal) {
  // Lambert: the projected solid angle is 1/2 sum_i gamma_i (n . u_i), with gamma_i the angle the
  // edge i subtends and u_i the unit normal of the plane through it and the point.
  const std::size_t n = polygon.size();
  if (n < 3) return 0.0;
  // on the stack for the usual windings (q3map2's subdivided pieces have 3-8 corners): this runs
  // for every sample and piece of every surface light
  std::array<glm::dvec3, 16> small;
  std::vector<glm::dvec3> large(n > small.size() ? n : 0);
  glm::dvec3* dirs = n > small.size() ? large.data() : small.data();
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 d = polygon[i] - point;
    const double l = glm::length(d);
    if (l <= 1e-12) return 0.0;
    dirs[i] = d / l;
  }
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3& a = dirs[i];
    const glm::dvec3& b = dirs[(i + 1) % n];
    const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
    const glm::dvec3 cross = glm::cross(a, b);
    const double length = glm::length(cross);
    if (length < 1e-12) continue;
    total += glm::dot(normal, cross / length) * angle;
  }
  // The sum's sign follows the winding: positive for a polygon wound clockwise seen from the
  // point. Either winding gives the same form factor here.
  const double side = glm::dot(glm::cross(polygon[1] - polygon[0], polygon[2] - polygon[0]), point - polygon[0]);
  return (side > 0 ? -total : total) / (2.0 * std::numbers::pi);
}

// TraceGrid splits each light c_i reaching a point into directed d_i c_i and ambient
// 0.25 (1 - d_i) c_i (d_i its cosine to the point's main direction, at least 0), then adds an
// eighth of the directed to the ambient: 0.5 directed + 4 ambient = sum of c_i. Exact without
// -bounce; the bounces' light (added without the eighth) counts half its directed part twice.
glm::dvec3 gridPointLight(const LightGridPoint& point, double gamma) {
  glm::dvec3 light(0.0);
  for (std::size_t k = 0; k < 3; ++k) light[static_cast<int>(k)] = 0.5 * linearFromByte(point.directed[k], gamma) + 4.0 * linearFromByte(point.ambient[k], gamma);
  return light;
}

namespace {
// A light grid point as a sample (LightContributionToPoint): it receives light from every
// direction, and its traces pass through what lies within the grid's inhibit radius.
Sample gridPointSample(const LightGrid& grid, std::size_t index) {
  Sample s;
  s.point = true;
  s.inhibit = grid.inhibitRadius();
  s.position = grid.position(index);
  return s;
}

bool emptyGridPoint(const LightGridPoint& g) {
  constexpr std::array<std::uint8_t, 3> kNone{};
  return g.ambient == kNone && g.directed == kNone;  // outside the map
}

// The step of a regular subset of at most `atMost` of `count` items.
std::size_t subsetStride(std::size_t count, int atMost) {
  const auto most = static_cast<std::size_t>(std::max(atMost, 1));
  return std::max<std::size_t>(1, (count + most - 1) / most);
}
}  // namespace

double lightContribution(const MapLight& light, const glm::dvec3& point, const glm::dvec3& normal) {
  if (light.kind == MapLightKind::kSun) {
    const double angle = light.angleAttenuation ? glm::dot(normal, light.towardsSun) : 1.0;
    return std::max(0.0, light.value * angle);
  }
  const glm::dvec3 toLight = light.position - point;
  if (glm::dot(toLight, normal) < 0.0) return 0.0;  // behind the surface
  const double d = glm::length(toLight);
  if (d <= 0) return 0.0;
  const double dist = std::max(d, kMinimumDistance);
  const double angle = light.angleAttenuation ? glm::dot(normal, toLight / d) : 1.0;
  const double photons = light.value * kPointScale;
  double add = light.linear ? std::max(0.0, angle * photons * kLinearScale - dist * light.fade) : photons / (dist * dist) * angle;
  if (light.kind == MapLightKind::kSpot) {
    const double along = glm::dot(point - light.position, light.spotAxis);
    if (along < 0.0) return 0.0;
    const double radiusAtDist = light.spotRadiusByDist * along;
    const double sampleRadius = glm::length(point - (light.position + along * light.spotAxis));
    if (sampleRadius >= radiusAtDist) return 0.0;
    if (sampleRadius > radiusAtDist - 32.0) add *= (radiusAtDist - sampleRadius) / 32.0;  // the cone's 32-unit edge
  }
  return std::max(0.0, add);
}

double surfaceContribution(const SurfaceEmitter& e, const glm::dvec3& point, const glm::dvec3& normal, bool* fromBack) {
  if (fromBack) *fromBack = false;
  const double d = glm::dot(point - e.origin, e.normal);  // q3map2 measures from the plane through its origin
  if (d < 3.0) {
    if (!e.twoSided && d < -1.0) return 0.0;                        // behind the emitter
    if (d > -3.0 && glm::dot(normal, e.normal) > 0.9) return 0.0;  // coplanar with it
  }
  // q3map2 pushes a point close to the emitter's plane 8 units in front of it (no black edges)
  const glm::dvec3 pushed = d > -8.0 && d < 8.0 ? point + (8.0 - d) * e.normal : point;
  // formFactor is positive where the point's surface faces the emitter. q3map2's signed form factor
  // is positive where that agrees with the side of the emitter the point is on; where it does not,
  // a one-sided emitter gives nothing and a two-sided one its magnitude, traced to its back.
  const double factor = formFactor(e.winding, pushed, normal);
  if (factor == 0.0) return 0.0;
  const bool facing = factor > 0.0, inFront = glm::dot(pushed - e.origin, e.normal) >= 0.0;
  if (facing != inFront) {
    if (!e.twoSided) return 0.0;
    if (fromBack) *fromBack = true;
  }
  return std::abs(factor) * e.value * kFormFactorValueScale * kAreaScale;
}

std::vector<MapLight> entityLights(const Bsp& bsp) {
  std::vector<MapLight> lights;
  for (std::size_t i = 0; i < bsp.entities.size(); ++i) {
    const BspEntity& e = bsp.entities[i];
    std::string classname = entityValue(e, "classname");
    std::transform(classname.begin(), classname.end(), classname.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (!classname.starts_with("light") || classname.starts_with("lightjunior")) continue;
    if (entityValue(e, "noradiosity") == "1") continue;
    MapLight l;
    l.source = fmt::format("entity {}", i);
    const int spawnflags = std::atoi(entityValue(e, "spawnflags").c_str());
    l.linear = (spawnflags & 1) != 0;
    l.angleAttenuation = (spawnflags & 3) == 0;
    if (l.linear) {
      l.fade = std::atof(entityValue(e, "fade").c_str());
      if (l.fade == 0) l.fade = 1.0;
    }
    l.position = entityVector(e, "origin");
    double intensity = std::atof(entityValue(e, "_light").c_str());
    if (intensity == 0) intensity = std::atof(entityValue(e, "light").c_str());
    if (intensity == 0) intensity = 300.0;
    if (const double scale = std::atof(entityValue(e, "scale").c_str()); scale != 0) intensity *= scale;
    l.value = intensity;
    if (const std::string color = entityValue(e, "_color"); !color.empty()) {
      std::istringstream in(color);
      glm::dvec3 c(0.0);
      in >> c.r >> c.g >> c.b;
      const double peak = std::max({c.r, c.g, c.b});
      l.color = peak > 0 ? c / peak : glm::dvec3(1.0);
    }
    if (const std::string target = entityValue(e, "target"); !target.empty()) {
      const auto found = std::find_if(bsp.entities.begin(), bsp.entities.end(), [&](const BspEntity& o) { return entityValue(o, "targetname") == target; });
      if (found != bsp.entities.end()) {
        glm::dvec3 axis = entityVector(*found, "origin") - l.position;
        double dist = glm::length(axis);
        axis = dist > 0 ? axis / dist : glm::dvec3(0, 0, -1);
        double radius = std::atof(entityValue(e, "radius").c_str());
        if (radius == 0) radius = 64.0;
        if (dist == 0) dist = 64.0;
        if (entityValue(e, "_sun") == "1") {
          l.kind = MapLightKind::kSun;
          l.towardsSun = -axis;
          l.color = glm::length(l.color) > 0 ? glm::normalize(l.color) : l.color;
        } else {
          l.kind = MapLightKind::kSpot;
          l.spotAxis = axis;
          l.spotRadiusByDist = (radius + 16.0) / dist;
          l.linear = false;  // spots: inverse square with angle attenuation always
          l.angleAttenuation = true;
          l.fade = 1.0;
        }
      }
    }
    lights.push_back(l);
  }
  return lights;
}

Expected<MapLighting> fitMapLighting(const GameFiles& files, const std::string& map, const MapLightFitOptions& options,
                                     const MapLightProgress& progress) {
  const auto report = [&](const std::string& step, std::size_t done, std::size_t total) {
    if (progress) progress(step, done, total);
  };
  const std::string path = "maps/" + map + ".bsp";
  auto bytes = files.read(path);
  if (!bytes) return std::unexpected(bytes.error());
  auto bsp = parseBsp(*bytes, files.archiveOf(path) + ":" + path);
  if (!bsp) return std::unexpected(bsp.error());
  auto scripts = ShaderScripts::read(files);
  if (!scripts) return std::unexpected(scripts.error());
  const Occluders occluders = buildOccluders(*bsp, *scripts);

  MapLighting result;
  result.map = map;
  MapLightFitReport& r = result.report;
  r.gamma = gammaOf(*bsp);

  // The known emitters, in groups: each light entity, each sun, each surface-light shader.
  std::vector<EmitterGroup> groups;
  if (!options.hideEntityLights) result.lights = entityLights(*bsp);
  r.entityLights = result.lights.size();
  for (std::size_t i = 0; i < result.lights.size(); ++i) groups.push_back({result.lights[i].source, result.lights[i].color, {i}, {}});
  std::set<int> usedShaders;
  for (const BspSurface& s : bsp->surfaces) usedShaders.insert(s.shader);
  for (int shader : usedShaders) {
    const ShaderLighting* script = scripts->find(bsp->shaders[static_cast<std::size_t>(shader)].name);
    if (!script) continue;
    r.skyLightShaders += script->skyLight > 0;
    for (const ShaderSun& sun : script->suns) {
      MapLight l;
      l.kind = MapLightKind::kSun;
      l.color = sun.color;
      l.value = sun.intensity;
      l.towardsSun = sun.towardsSun;
      l.source = "sun of " + script->name;
      groups.push_back({l.source, l.color, {result.lights.size()}, {}});
      result.lights.push_back(l);
      ++r.suns;
    }
  }
  result.surfaceLights = surfaceEmitters(*bsp, *scripts, files);
  r.surfaceEmitters = result.surfaceLights.size();
  {
    std::map<std::pair<int, EmitterSide>, std::size_t> byShader;
    for (std::size_t i = 0; i < result.surfaceLights.size(); ++i) {
      const SurfaceEmitter& e = result.surfaceLights[i];
      for (const EmitterSide side : e.twoSided ? std::vector{EmitterSide::kFront, EmitterSide::kBack} : std::vector{EmitterSide::kBoth}) {
        auto [it, fresh] = byShader.emplace(std::pair{e.shader, side}, groups.size());
        if (fresh) {
          groups.push_back({"surface light " + e.shaderName + (side == EmitterSide::kBack ? " (its back)" : ""), e.color, {}, {}, side});
          if (side == EmitterSide::kBack) groups[byShader.at({e.shader, EmitterSide::kFront})].backGroup = it->second;
        }
        groups[it->second].surfaces.push_back(i);
      }
    }
  }
  // The lightmap texels (the fit's and the judge's samples are regular subsets of them, below).
  r.floorBytes = minimumLightBytes(*bsp, r.gamma);
  const LightmapTexels texels = lightmapTexels(*bsp, *scripts, r.gamma, r.floorBytes);
  r.texels = texels.texels;
  r.clippedTexels = texels.clipped;
  r.flooredTexels = texels.floored;

  // The light grid as fit data, on the lattice's even points (the odd ones judge the lights below).
  // Its directed light has no floor and each point says where its light mainly comes from, so it
  // shows lights a lightmap floor hides. Where the lightmaps are not floored they are the better
  // data: fitted on every map, the grid cost oa_dm3 (0.914 -> 0.878 held out, 256 lights, 3 min)
  // and oa_bases3's recovery (96 -> 87 %); integrations/openarena/README.md has the figures.
  const LightGrid& grid = bsp->lightGrid;
  const bool floorHidesMost = 2 * texels.floored > texels.texels;
  r.gridFitted = options.gridFit == GridFit::kAlways || (options.gridFit == GridFit::kWhereFloored && floorHidesMost);
  std::vector<Sample> gridRows;
  if (r.gridFitted) {
    std::vector<std::size_t> usable;
    for (std::size_t i = 0; i < grid.points.size(); ++i) {
      const LightGridPoint& g = grid.points[i];
      if (!emptyGridPoint(g) && grid.even(i) && !clippedColor(g.directed.data())) usable.push_back(i);
    }
    const std::size_t stride = subsetStride(usable.size(), options.gridFitSamples);
    for (std::size_t u = 0; u < usable.size(); u += stride) {
      const LightGridPoint& g = grid.points[usable[u]];
      Sample s = gridPointSample(grid, usable[u]);
      s.normal = g.mainDirection();
      // The light from every direction where the ambient is neither clipped nor floored (what the
      // grid's judge compares, gridPointLight); else the directed light alone, each light's times
      // its cosine to the main direction (TraceGrid), with no floor in it.
      const bool whole = !clippedColor(g.ambient.data()) && !atFloor(g.ambient.data(), r.floorBytes);
      if (whole) s.value = gridPointLight(g, r.gamma);
      else {
        s.mainDirection = s.normal;
        for (std::size_t k = 0; k < 3; ++k) s.value[static_cast<int>(k)] = linearFromByte(g.directed[k], r.gamma);
      }
      gridRows.push_back(s);
    }
  }
  // The grid's bounced light takes a constant of its own: a group with no emitters, its column set below.
  const std::size_t gridConstant = groups.size();
  if (!gridRows.empty()) groups.push_back({"the light grid's bounced light (a constant)", glm::dvec3(1.0), {}, {}});
  const std::size_t knownLights = result.lights.size(), groupCount = groups.size();

  const int stride =
      std::max(2, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(texels.texels) / std::max(options.fitSamples, 1)))));
  std::vector<Sample> fit = texelSubset(texels.unclipped, stride, 0);
  const std::vector<Sample> heldOut = texelSubset(texels.unclipped, stride, stride / 2);
  r.fitSamples = fit.size();
  const std::size_t texelRows = fit.size();  // the texels come first, then the grid's points
  fit.insert(fit.end(), gridRows.begin(), gridRows.end());
  r.gridFitPoints = gridRows.size();
  r.heldOutSamples = heldOut.size();
  if (texelRows < 16) return fail(ErrorCode::kUnsupported, "{}: {} lightmap texels to fit; the map has no lightmaps to recover lights from", path, texelRows);
  report("known emitters", 0, 1);
  std::vector<Column> columns = groupColumns(fit, groups, result.lights, result.surfaceLights, occluders);
  if (!gridRows.empty()) {
    Column& c = columns[gridConstant];
    for (std::size_t i = texelRows; i < fit.size(); ++i) {
      c.rows.push_back(static_cast<std::uint32_t>(i));
      c.values.push_back(1.0f);
    }
    c.norm2 = static_cast<double>(gridRows.size());
  }
  report("known emitters", 1, 1);
  // The fit's own constant (bounced light and ambient in the lightmaps) is over the texels alone.
  const auto texelSum = [&](const Column& c) {
    double sum = 0.0;
    for (std::size_t k = 0; k < c.rows.size(); ++k)
      if (c.rows[k] < texelRows) sum += c.values[k];
    return sum;
  };

  // A column's colour: its group's, white for a candidate. `channel` 3 is luminance.
  const auto colorOf = [&](std::size_t column, int channel) {
    const glm::dvec3 color = column < groupCount ? groups[column].color : glm::dvec3(1.0);
    return channel == 3 ? luminance(color) : color[channel];
  };

  // Non-negative least squares over the known groups (each with a weight, q3map2's strength being
  // 1), the chosen candidates and a constant; candidates chosen greedily on luminance. The chosen
  // columns' Gram matrix is kept as they come and go (a column's products with the others are
  // computed once), so a step costs one pass over the candidates, not over the set squared.
  const std::size_t n = fit.size();
  std::vector<std::size_t> chosen;            // column indices; the constant is the last unknown
  std::vector<std::vector<double>> gramRows;  // gramRows[a][b] = column a . column b, a, b in chosen (colourless)
  std::vector<double> columnSums;             // column a . the constant's column of ones
  std::vector<double> dense(n, 0.0);
  const auto addColumn = [&](std::size_t j) {
    const Column& cj = columns[j];
    for (std::size_t k = 0; k < cj.rows.size(); ++k) dense[cj.rows[k]] = cj.values[k];
    std::vector<double> row(chosen.size() + 1);
    for (std::size_t a = 0; a < chosen.size(); ++a) {
      row[a] = dot(columns[chosen[a]], dense);
      gramRows[a].push_back(row[a]);
    }
    row[chosen.size()] = cj.norm2;
    for (std::uint32_t i : cj.rows) dense[i] = 0.0;
    gramRows.push_back(std::move(row));
    columnSums.push_back(texelSum(cj));
    chosen.push_back(j);
  };
  const auto removeColumns = [&](const std::vector<char>& drop) {
    std::vector<std::size_t> keep;
    for (std::size_t a = 0; a < chosen.size(); ++a)
      if (!drop[a]) keep.push_back(a);
    std::vector<std::vector<double>> rows;
    std::vector<double> sums;
    std::vector<std::size_t> cols;
    for (std::size_t a : keep) {
      std::vector<double> row;
      for (std::size_t b : keep) row.push_back(gramRows[a][b]);
      rows.push_back(std::move(row));
      sums.push_back(columnSums[a]);
      cols.push_back(chosen[a]);
    }
    gramRows = std::move(rows);
    columnSums = std::move(sums);
    chosen = std::move(cols);
  };
  const auto solve = [&](const std::vector<double>& y, int channel) {
    const std::size_t m = chosen.size() + 1;
    std::vector<double> gram(m * m, 0.0), atb(m, 0.0);
    for (std::size_t a = 0; a < chosen.size(); ++a) {
      const double ca = colorOf(chosen[a], channel);
      for (std::size_t b = 0; b < chosen.size(); ++b) gram[a * m + b] = gramRows[a][b] * ca * colorOf(chosen[b], channel);
      gram[a * m + m - 1] = gram[(m - 1) * m + a] = columnSums[a] * ca;
      atb[a] = dot(columns[chosen[a]], y) * ca;
    }
    gram[(m - 1) * m + m - 1] = static_cast<double>(texelRows);
    atb[m - 1] = std::accumulate(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(texelRows), 0.0);
    return nnls(gram, atb).x;
  };
  const auto residualOf = [&](const std::vector<double>& y, const std::vector<double>& x, int channel, std::vector<double>& out) {
    out.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) out[i] = i < texelRows ? y[i] - x.back() : y[i];
    for (std::size_t a = 0; a < chosen.size(); ++a) {
      const Column& c = columns[chosen[a]];
      const double w = x[a] * colorOf(chosen[a], channel);
      for (std::size_t k = 0; k < c.rows.size(); ++k) out[c.rows[k]] -= w * c.values[k];
    }
    double s = 0;
    for (double v : out) s += v * v;
    return s;
  };
  std::vector<double> target(n), residual;
  for (std::size_t i = 0; i < n; ++i) target[i] = luminance(fit[i].value);
  // The lightmaps' signal (the texels' variance) sets when the greedy fit stops, the grid's rows or not.
  double signal = 0.0;
  {
    const auto texelsEnd = target.begin() + static_cast<std::ptrdiff_t>(texelRows);
    const double mean = std::accumulate(target.begin(), texelsEnd, 0.0) / static_cast<double>(texelRows);
    for (auto t = target.begin(); t != texelsEnd; ++t) signal += (*t - mean) * (*t - mean);
  }
  for (std::size_t k = 0; k < groupCount; ++k) addColumn(k);
  double error = residualOf(target, solve(target, 3), 3, residual);

  // Candidates and their columns, after the groups': the lattice, then the residual's hot spots.
  std::vector<glm::dvec3> candidates = openSpaceLattice(*bsp, occluders, options.maxCandidates, r.latticeSpacing);
  r.latticeCandidates = candidates.size();
  if (options.hotSpotPeaks > 0) {
    const std::vector<glm::dvec3> hot = hotSpotCandidates(fit, residual, occluders, static_cast<std::size_t>(options.hotSpotPeaks));
    candidates.insert(candidates.end(), hot.begin(), hot.end());
  }
  r.candidates = candidates.size();
  columns.resize(groupCount + candidates.size());
  std::atomic<std::size_t> done{0};
  tbb::parallel_for(std::size_t(0), candidates.size(), [&](std::size_t j) {
    columns[groupCount + j] = candidateColumn(candidates[j], fit, occluders);
    const std::size_t finished = ++done;
    if (finished % 64 == 0) report("candidate lights", finished, candidates.size());
  });
  report("candidate lights", candidates.size(), candidates.size());
  std::vector<char> taken(columns.size(), 0);
  std::fill(taken.begin(), taken.begin() + static_cast<std::ptrdiff_t>(groupCount), 1);
  std::vector<double> scores(columns.size());
  while (static_cast<int>(chosen.size() - groupCount) < options.maxLights) {
    tbb::parallel_for(std::size_t(0), columns.size(), [&](std::size_t j) {
      scores[j] = taken[j] || columns[j].norm2 <= 0 ? 0.0 : dot(columns[j], residual) / std::sqrt(columns[j].norm2);
    });
    std::size_t best = columns.size();
    double bestScore = 0.0;
    for (std::size_t j = 0; j < columns.size(); ++j)
      if (scores[j] > bestScore) {
        bestScore = scores[j];
        best = j;
      }
    if (best == columns.size()) break;
    addColumn(best);
    taken[best] = 1;
    std::vector<double> nextResidual;
    const std::vector<double> next = solve(target, 3);
    const double nextError = residualOf(target, next, 3, nextResidual);
    std::vector<char> drop(chosen.size(), 0);
    if (error - nextError < options.minimumGain * signal) {
      drop.back() = 1;
      removeColumns(drop);
      break;
    }
    residual = std::move(nextResidual);
    error = nextError;
    // candidates NNLS set to zero leave the set (they may be chosen again); groups stay
    for (std::size_t a = groupCount; a < chosen.size(); ++a)
      if (!(next[a] > 0)) {
        drop[a] = 1;
        taken[chosen[a]] = 0;
      }
    removeColumns(drop);
    report("fitting lights", chosen.size() - groupCount, static_cast<std::size_t>(options.maxLights));
  }

  // Refinement: the lattice is coarse (up to ~170 units on large maps), so each fitted light then
  // moves among its neighbours at half, a quarter, an eighth and a sixteenth of the lattice
  // spacing (in open space), its weight re-solved in closed form with the others held, while that
  // lowers the residual; the weights are solved together again afterwards.
  if (options.refine) {
    const std::vector<double> held = solve(target, 3);
    residualOf(target, held, 3, residual);
    const double spacing = static_cast<double>(r.latticeSpacing);
    for (std::size_t a = groupCount; a < chosen.size(); ++a) {
      const double w = held[a];
      if (!(w > 0)) continue;
      std::vector<double> without = residual;  // the residual without this light
      {
        const Column& c = columns[chosen[a]];
        for (std::size_t k = 0; k < c.rows.size(); ++k) without[c.rows[k]] += w * c.values[k];
      }
      double withoutNorm = 0;
      for (double v : without) withoutNorm += v * v;
      glm::dvec3 position = candidates[chosen[a] - groupCount];
      const Column* current = &columns[chosen[a]];
      double currentWeight = w, currentDot = dot(*current, without);
      double currentError = withoutNorm - 2.0 * currentWeight * currentDot + currentWeight * currentWeight * current->norm2;
      Column best;
      bool moved = false;
      // Positions already tried for this light. A tried position's error was at least the error
      // then held, which only falls, so the strict test below never picks it again: skipping it
      // (the step back to where the light came from, above all) leaves the search's path as it was.
      std::set<std::array<double, 3>> tried;
      // A pattern search: at each scale the light keeps stepping to its best axis neighbour
      // while that lowers the residual (up to kRefineStepsPerScale steps), then the scale halves.
      for (const double step : {spacing / 2, spacing / 4, spacing / 8, spacing / 16}) {
        for (int stepsTaken = 0; stepsTaken < kRefineStepsPerScale; ++stepsTaken) {
          std::vector<glm::dvec3> trials;
          for (int axis = 0; axis < 3; ++axis)
            for (const double sign : {-1.0, 1.0}) {
              glm::dvec3 p = position;
              p[axis] += sign * step;
              if (tried.insert({p.x, p.y, p.z}).second) trials.push_back(p);
            }
          std::vector<Column> trialColumns(trials.size());
          std::vector<char> usable(trials.size(), 0);
          tbb::parallel_for(std::size_t(0), trials.size(), [&](std::size_t t) {
            if (!inOpenSpace(trials[t], occluders)) return;
            trialColumns[t] = candidateColumn(trials[t], fit, occluders);
            usable[t] = trialColumns[t].norm2 > 0;
          });
          bool improved = false;
          for (std::size_t t = 0; t < trials.size(); ++t) {
            if (!usable[t]) continue;
            const double d = dot(trialColumns[t], without);
            const double weight = std::max(0.0, d / trialColumns[t].norm2);
            const double error = withoutNorm - 2.0 * weight * d + weight * weight * trialColumns[t].norm2;
            if (error < currentError) {
              currentError = error;
              currentWeight = weight;
              position = trials[t];
              best = std::move(trialColumns[t]);
              current = &best;
              moved = improved = true;
            }
          }
          if (!improved) break;
        }
      }
      if (!moved) continue;
      // the moved light: a new column (and candidate position) in place of the old one
      candidates.push_back(position);
      columns.push_back(std::move(best));
      const std::size_t j = columns.size() - 1;
      const Column& cj = columns[j];
      for (std::size_t k = 0; k < cj.rows.size(); ++k) dense[cj.rows[k]] = cj.values[k];
      for (std::size_t b = 0; b < chosen.size(); ++b)
        if (b != a) gramRows[a][b] = gramRows[b][a] = dot(columns[chosen[b]], dense);
      for (std::uint32_t i : cj.rows) dense[i] = 0.0;
      gramRows[a][a] = cj.norm2;
      columnSums[a] = texelSum(cj);
      chosen[a] = j;
      residual = std::move(without);
      for (std::size_t k = 0; k < cj.rows.size(); ++k) residual[cj.rows[k]] -= currentWeight * cj.values[k];
      ++r.refinedLights;
      report("refining lights", a - groupCount + 1, chosen.size() - groupCount);
    }
  }

  // Colours and strengths: the same set fitted per channel. A group's weight is the luminance
  // fit's (its colour is the map's); a fitted light's colour is its channels' ratio.
  const std::vector<double> weights = solve(target, 3);

  std::array<std::vector<double>, 3> perChannel;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> y(n);
    for (std::size_t i = 0; i < n; ++i) y[i] = fit[i].value[c];
    perChannel[static_cast<std::size_t>(c)] = solve(y, c);
    r.constant[c] = perChannel[static_cast<std::size_t>(c)].back();
  }
  // q3map2's own strengths, for judging the fit on held-out texels below
  const std::vector<MapLight> unweightedLights = result.lights;
  const std::vector<SurfaceEmitter> unweightedSurfaces = result.surfaceLights;
  for (std::size_t k = 0; k < groupCount; ++k) {
    r.groupWeights.push_back({groups[k].name, weights[k]});
    for (std::size_t li : groups[k].lights) result.lights[li].value *= weights[k];
    // the dataset's emitter takes its front's weight; the back's is reported
    if (groups[k].side != EmitterSide::kBack)
      for (std::size_t ei : groups[k].surfaces) result.surfaceLights[ei].value *= weights[k];
  }
  for (std::size_t a = groupCount; a < chosen.size(); ++a) {
    const glm::dvec3 v(perChannel[0][a], perChannel[1][a], perChannel[2][a]);
    const double peak = std::max({v.r, v.g, v.b});
    if (!(peak > 0)) continue;
    MapLight l;
    l.position = candidates[chosen[a] - groupCount];
    l.color = v / peak;
    l.value = peak;
    l.source = "fitted";
    result.lights.push_back(l);
  }
  r.fittedLights = result.lights.size() - knownLights;
  if (options.hideEntityLights) {
    // How much of the hidden lights' value has a fitted light near it.
    // Whether the lightmaps show a hidden light at all: q3map2's model of it gives at least one
    // lightmap unit (a byte at -gamma 1) on some fitted texel that is neither clipped nor at the
    // map's floor. Elsewhere the texels read the same with it or without it.
    const std::vector<MapLight> hidden = entityLights(*bsp);
    std::vector<EmitterGroup> hiddenGroups;
    for (std::size_t i = 0; i < hidden.size(); ++i) hiddenGroups.push_back({hidden[i].source, hidden[i].color, {i}, {}});
    const std::vector<Column> hiddenColumns = groupColumns(fit, hiddenGroups, hidden, {}, occluders);
    double total = 0.0, found = 0.0, shown = 0.0, shownFound = 0.0;
    for (std::size_t h = 0; h < hidden.size(); ++h) {
      if (hidden[h].kind == MapLightKind::kSun) continue;
      total += hidden[h].value;
      bool inLightmaps = false;
      const Column& c = hiddenColumns[h];
      for (std::size_t k = 0; k < c.rows.size() && !inLightmaps; ++k)
        inLightmaps = !fit[c.rows[k]].floored && !fit[c.rows[k]].point && c.values[k] * luminance(hidden[h].color) >= kShownLightmapUnits;
      bool near = false;
      for (std::size_t i = knownLights; i < result.lights.size() && !near; ++i)
        near = glm::length(result.lights[i].position - hidden[h].position) <= kRecoveryRadius;
      found += near ? hidden[h].value : 0.0;
      shown += inLightmaps ? hidden[h].value : 0.0;
      shownFound += inLightmaps && near ? hidden[h].value : 0.0;
    }
    r.hiddenLightValue = total;
    r.recoveredShare = total > 0 ? found / total : 0.0;
    r.shownLightValue = shown;
    r.recoveredShownShare = shown > 0 ? shownFound / shown : 0.0;
  }

  if (!options.judgeOnHeldOut) return result;
  // Judged on the held-out texels: the known emitters as q3map2 gives them, and the dataset's
  // lights (the known ones weighted, the fitted ones).
  report("held-out texels", 0, 1);
  std::vector<EmitterGroup> all = groups;
  std::vector<double> allWeights = weights;
  allWeights.resize(groupCount);
  for (std::size_t i = knownLights; i < result.lights.size(); ++i) {
    all.push_back({"fitted", result.lights[i].color, {i}, {}});
    allWeights.push_back(1.0);
  }
  std::vector<MapLight> heldLights = unweightedLights;
  heldLights.insert(heldLights.end(), result.lights.begin() + static_cast<std::ptrdiff_t>(knownLights), result.lights.end());
  // The luminance q3map2's model gives each sample: of the known emitters alone (their strength as
  // q3map2 gives it), and of the dataset's lights (weighted, with the fitted ones).
  const auto modelLuminance = [&](const std::vector<Sample>& samples, std::vector<double>& knownLum, std::vector<double>& allLum) {
    const std::vector<Column> columnsHere = groupColumns(samples, all, heldLights, unweightedSurfaces, occluders);
    knownLum.assign(samples.size(), 0.0);
    allLum.assign(samples.size(), 0.0);
    for (std::size_t k = 0; k < all.size(); ++k) {
      const double lum = luminance(all[k].color);
      for (std::size_t q = 0; q < columnsHere[k].rows.size(); ++q) {
        const double v = columnsHere[k].values[q] * lum;  // q3map2's strength (a fitted light's own)
        allLum[columnsHere[k].rows[q]] += v * allWeights[k];
        if (k < groupCount) knownLum[columnsHere[k].rows[q]] += v;
      }
    }
  };
  std::vector<double> texel(heldOut.size()), knownLum, allLum;
  for (std::size_t i = 0; i < heldOut.size(); ++i) texel[i] = luminance(heldOut[i].value);
  modelLuminance(heldOut, knownLum, allLum);
  r.heldOutCorrelation = pearson(texel, allLum);
  r.knownCorrelation = pearson(texel, knownLum);
  const auto explained = [&](const std::vector<double>& model, double offset) {
    const double mean = std::accumulate(texel.begin(), texel.end(), 0.0) / static_cast<double>(texel.size());
    double total = 0, rest = 0;
    for (std::size_t i = 0; i < texel.size(); ++i) {
      total += (texel[i] - mean) * (texel[i] - mean);
      rest += (texel[i] - model[i] - offset) * (texel[i] - model[i] - offset);
    }
    return total > 0 ? 1.0 - rest / total : 0.0;
  };
  r.knownExplained = explained(knownLum, 0.0);
  r.totalExplained = explained(allLum, weights.back());
  report("held-out texels", 1, 1);

  // Judged on the light grid, which the fit never sees: q3map2's record of the same lights at
  // points of the map's open space, where players move (gridPointLight). Left out: points with
  // nothing (outside the map), a byte clipped, or the ambient at the map's floor (_minlight raises
  // the grid's ambient too).
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < grid.points.size(); ++i) {
    if (r.gridFitted && grid.even(i)) continue;  // fitted
    const LightGridPoint& g = grid.points[i];
    const bool clipped = clippedColor(g.ambient.data()) || clippedColor(g.directed.data());
    if (!emptyGridPoint(g) && !clipped && !atFloor(g.ambient.data(), r.floorBytes)) usable.push_back(i);
  }
  const std::size_t gridStride = subsetStride(usable.size(), options.gridSamples);
  std::vector<Sample> gridSamples;
  std::vector<double> gridLum;
  for (std::size_t u = 0; u < usable.size(); u += gridStride) {
    const LightGridPoint& g = grid.points[usable[u]];
    Sample s = gridPointSample(grid, usable[u]);
    s.value = gridPointLight(g, r.gamma);
    gridSamples.push_back(s);
    gridLum.push_back(luminance(s.value));
  }
  r.gridPoints = gridSamples.size();
  if (gridSamples.size() >= 16) {
    report("light grid", 0, 1);
    modelLuminance(gridSamples, knownLum, allLum);
    r.gridCorrelation = pearson(gridLum, allLum);
    r.gridKnownCorrelation = pearson(gridLum, knownLum);
    report("light grid", 1, 1);
  }
  return result;
}

Expected<void> writeAdapterLights(const std::filesystem::path& file, const MapLighting& lighting) {
  // In the engine's full light (kFullLight lightmap units), as the capture format counts light.
  std::ostringstream out;
  out << "# dynbench map lights of " << lighting.map << " (src/maplight/fit.h): game axes and units, colours in full-light units\n";
  for (const MapLight& l : lighting.lights) {
    if (l.kind == MapLightKind::kSun) {
      const glm::dvec3 rgb = l.color * l.value / kFullLight;  // V cos lightmap units on a surface facing it
      out << fmt::format("sun {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g}\n", l.towardsSun.x, l.towardsSun.y, l.towardsSun.z, rgb.r, rgb.g, rgb.b);
    } else {
      // V pointScale / d^2 lightmap units is full light at d = sqrt(V pointScale / kFullLight). Spots
      // and linear lights are written as the inverse-square point light of the same value.
      const double fullLightDistance = std::sqrt(l.value * kPointScale / kFullLight);
      out << fmt::format("point {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g}\n", l.position.x, l.position.y, l.position.z, l.color.r, l.color.g,
                         l.color.b, fullLightDistance);
    }
  }
  std::set<int> shaders;
  for (const SurfaceEmitter& e : lighting.surfaceLights)
    if (shaders.insert(e.shader).second) {
      // radiance formFactorValueScale areaScale V / pi lightmap units: a surface facing it closely
      // gets formFactorValueScale areaScale V, the emission (full-light units) it is given
      const glm::dvec3 emission = e.color * kFormFactorValueScale * kAreaScale * e.value / kFullLight;
      out << fmt::format("surface {} {:.6g} {:.6g} {:.6g}\n", e.shaderName, emission.r, emission.g, emission.b);
    }
  return writeFileAtomic(file, out.str());
}

}  // namespace dynbench::maplight
