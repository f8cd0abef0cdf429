#pragma once
// The light fit's step 1 (maplight/fit.h): what q3map2 left of the lights, as samples. A lightmap
// texel of a drawn world surface is a sample (position, normal, linear value); so is a light grid
// point, which receives light from every direction. Internal to maplight.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "maplight/bsp.h"
#include "maplight/fit.h"
#include "maplight/shaders.h"

namespace dynbench::maplight {

// The byte from which a lightmap texel is clipped. ColorToBytes scales a colour whose brightest
// channel passes 255 by 255 / max in float and truncates to a byte, which gives 254 as often as
// 255 (254.99997). The lightmaps show it: on seven of the nine stock maps the brightest channel is
// 254 on 5-30 times as many texels as on 250-253 (oa_dm2: 5,223 against about 180 each).
constexpr std::uint8_t kClippedByte = 254;

// A lightmap or light grid byte as linear lightmap units: q3map2's ColorToBytes applied the map's
// -gamma (255 (x / 255)^(1 / gamma)), undone here.
double linearFromByte(std::uint8_t b, double gamma);

// Whether some channel of a stored colour is clipped (kClippedByte or above).
bool clippedColor(const std::uint8_t* rgb);

// Whether some channel of a stored colour reads the map's floor (minimumLightBytes; 0: none).
bool atFloor(const std::uint8_t* rgb, const glm::dvec3& floorBytes);

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

// The map's -gamma (from worldspawn's _q3map2_cmdline), 1 where it sets none.
double gammaOf(const Bsp& bsp);

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
LightmapTexels lightmapTexels(const Bsp& bsp, const ShaderScripts& scripts, double gamma, const glm::dvec3& floorBytes);

// A regular subset of the texels: those whose page coordinates are multiples of `stride` plus `offset`.
std::vector<Sample> texelSubset(const std::vector<Texel>& texels, int stride, int offset);

// The light grid's points as fit data (MapLightFitOptions::gridFit): a regular subset of at most
// `atMost` of its even points that are neither empty nor clipped.
std::vector<Sample> gridFitRows(const LightGrid& grid, int atMost, const glm::dvec3& floorBytes, double gamma);
// The light grid's points that judge the lights: a regular subset of at most `atMost` of the usable
// ones (the odd ones alone where the even ones were fitted), each with its light from every direction.
std::vector<Sample> gridJudgeSamples(const LightGrid& grid, bool evenFitted, int atMost, const glm::dvec3& floorBytes, double gamma);

}  // namespace dynbench::maplight
