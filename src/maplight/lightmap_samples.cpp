#include "maplight/lightmap_samples.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <regex>
#include <sstream>

#include "maplight/fit_visibility.h"

namespace dynbench::maplight {

namespace {

constexpr double kNudge = 1.0;  // units a sample is lifted off its surface before tracing (q3map2 nudges too)

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

double linearFromByte(std::uint8_t b, double gamma) { return 255.0 * std::pow(b / 255.0, gamma); }

bool clippedColor(const std::uint8_t* rgb) { return std::max({rgb[0], rgb[1], rgb[2]}) >= kClippedByte; }

bool atFloor(const std::uint8_t* rgb, const glm::dvec3& floorBytes) {
  for (int k = 0; k < 3; ++k)
    if (floorBytes[k] > 0 && rgb[k] <= floorBytes[k]) return true;
  return false;
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

std::vector<Sample> texelSubset(const std::vector<Texel>& texels, int stride, int offset) {
  std::vector<Sample> samples;
  for (const Texel& t : texels)
    if (((t.x - offset) % stride + stride) % stride == 0 && ((t.y - offset) % stride + stride) % stride == 0) samples.push_back(t.sample);
  return samples;
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

std::vector<Sample> gridFitRows(const LightGrid& grid, int atMost, const glm::dvec3& floorBytes, double gamma) {
  std::vector<Sample> rows;
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < grid.points.size(); ++i) {
    const LightGridPoint& g = grid.points[i];
    if (!emptyGridPoint(g) && grid.even(i) && !clippedColor(g.directed.data())) usable.push_back(i);
  }
  const std::size_t stride = subsetStride(usable.size(), atMost);
  for (std::size_t u = 0; u < usable.size(); u += stride) {
    const LightGridPoint& g = grid.points[usable[u]];
    Sample s = gridPointSample(grid, usable[u]);
    s.normal = g.mainDirection();
    // The light from every direction where the ambient is neither clipped nor floored (what the
    // grid's judge compares, gridPointLight); else the directed light alone, each light's times
    // its cosine to the main direction (TraceGrid), with no floor in it.
    const bool whole = !clippedColor(g.ambient.data()) && !atFloor(g.ambient.data(), floorBytes);
    if (whole) s.value = gridPointLight(g, gamma);
    else {
      s.mainDirection = s.normal;
      for (std::size_t k = 0; k < 3; ++k) s.value[static_cast<int>(k)] = linearFromByte(g.directed[k], gamma);
    }
    rows.push_back(s);
  }
  return rows;
}

std::vector<Sample> gridJudgeSamples(const LightGrid& grid, bool evenFitted, int atMost, const glm::dvec3& floorBytes, double gamma) {
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < grid.points.size(); ++i) {
    if (evenFitted && grid.even(i)) continue;  // fitted
    const LightGridPoint& g = grid.points[i];
    const bool clipped = clippedColor(g.ambient.data()) || clippedColor(g.directed.data());
    if (!emptyGridPoint(g) && !clipped && !atFloor(g.ambient.data(), floorBytes)) usable.push_back(i);
  }
  const std::size_t stride = subsetStride(usable.size(), atMost);
  std::vector<Sample> samples;
  for (std::size_t u = 0; u < usable.size(); u += stride) {
    const LightGridPoint& g = grid.points[usable[u]];
    Sample s = gridPointSample(grid, usable[u]);
    s.value = gridPointLight(g, gamma);
    samples.push_back(s);
  }
  return samples;
}

}  // namespace dynbench::maplight
