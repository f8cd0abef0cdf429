#pragma once
// id Tech 3 maps as q3map2 writes them (IBSP version 46, Quake III Arena and OpenArena): the lumps
// the lighting needs. Layout from ioquake3's qfiles.h and q3map2's bspfile_ibsp.c; every count and
// offset is checked against the file's size, and an error names the map and the lump.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"

namespace dynbench::maplight {

inline constexpr int kLightmapSize = 128;  // texels per side of a lightmap page

// The BSP's surface flags q3map2 copies from the shader scripts (surfaceflags.h).
inline constexpr int kSurfaceSky = 0x4, kSurfaceNoDraw = 0x80, kSurfaceNoLightmap = 0x400;

struct BspShader {
  std::string name;
  int surfaceFlags = 0, contentFlags = 0;
};

struct BspVertex {
  glm::vec3 position{0.0f};  // game units (Z up)
  glm::vec2 st{0.0f};
  glm::vec2 lightmap{0.0f};  // on the surface's lightmap page, 0-1
  glm::vec3 normal{0.0f};
};

enum class BspSurfaceType { kBad = 0, kPlanar = 1, kPatch = 2, kTriangleSoup = 3, kFlare = 4 };

struct BspSurface {
  int shader = -1;
  BspSurfaceType type = BspSurfaceType::kBad;
  int firstVertex = 0, vertexCount = 0, firstIndex = 0, indexCount = 0;
  int lightmap = -1;  // page, or < 0 (vertex lit, none)
  int patchWidth = 0, patchHeight = 0;
};

struct BspModel {
  glm::vec3 mins{0.0f}, maxs{0.0f};
  int firstSurface = 0, surfaceCount = 0;
};

// The light grid (lump 15): q3map2's light at points of a regular lattice over the world's bounds,
// for lighting moving models (light.c, SetupGrid and TraceGrid). Point (x, y, z) is
// points[x + counts.x (y + counts.y z)] at origin + spacing (x, y, z). Bytes as ColorToBytes stores
// them (the map's -gamma, a brightest channel above 255 scaled down to it); a point q3map2 could
// not place in the map's open space (every byte 0) holds nothing.
struct LightGridPoint {
  std::array<std::uint8_t, 3> ambient{}, directed{};
  std::array<std::uint8_t, 2> direction{};  // q3map2's NormalToLatLong: polar angle, then azimuth, 255 / 360 per degree
  // The unit direction its light mainly comes from (towards the lights), decoded from `direction`.
  glm::dvec3 mainDirection() const;
};
struct LightGrid {
  glm::dvec3 origin{0.0}, spacing{0.0};
  glm::ivec3 counts{0};
  std::vector<LightGridPoint> points;
  glm::dvec3 position(std::size_t index) const;
  bool even(std::size_t index) const;  // whether x + y + z is even: a checkerboard that halves the lattice
  // TraceGrid's inhibitRadius: half the largest step (z's unless x's or y's is strictly the largest);
  // a point's traces pass through what lies nearer.
  double inhibitRadius() const;
};

using BspEntity = std::map<std::string, std::string>;  // keys as written (q3map2 compares without case)

struct Bsp {
  std::string name;  // for messages: "maps/oa_dm1.bsp"
  std::vector<BspEntity> entities;
  std::vector<BspShader> shaders;
  std::vector<BspModel> models;  // 0: the world; 1...: brush entities (doors, platforms)
  std::vector<BspVertex> vertices;
  std::vector<int> indices;
  std::vector<BspSurface> surfaces;
  std::vector<std::array<std::uint8_t, kLightmapSize * kLightmapSize * 3>> lightmaps;  // RGB bytes, rows of texels
  LightGrid lightGrid;  // empty when the lump is (a map compiled without -light)
};

Expected<Bsp> parseBsp(const std::string& bytes, const std::string& name);

// An entity key's value without case in the key, or "".
std::string entityValue(const BspEntity& entity, const std::string& key);
glm::dvec3 entityVector(const BspEntity& entity, const std::string& key);

// One triangle of a drawn surface, wound counter-clockwise seen from the side its normals face.
struct SurfaceTriangle {
  std::array<glm::dvec3, 3> position;
  std::array<glm::dvec3, 3> normal;
  std::array<glm::dvec2, 3> lightmap;
  int surface = -1;
};

// Planar faces and triangle soups as their indices give them; curved patches tessellated as the
// capture adapter tessellates them (patchLevel segments per 3x3 control block, biquadratic Bezier).
std::vector<SurfaceTriangle> surfaceTriangles(const Bsp& bsp, int surface, int patchLevel = 8);

}  // namespace dynbench::maplight
