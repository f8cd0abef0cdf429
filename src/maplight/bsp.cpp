#include "maplight/bsp.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cctype>
#include <cstring>
#include <optional>
#include <sstream>

namespace dynbench::maplight {

namespace {
constexpr int kLumpEntities = 0, kLumpShaders = 1, kLumpModels = 7, kLumpVertices = 10, kLumpIndices = 11, kLumpSurfaces = 13,
              kLumpLightmaps = 14, kLumpLightGrid = 15, kLumpCount = 17;
constexpr std::size_t kShaderBytes = 72, kModelBytes = 40, kVertexBytes = 44, kSurfaceBytes = 104;

template <typename T>
T load(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));  // the file is little-endian, as this machine
  return value;
}

struct Lump {
  const char* data = nullptr;
  std::size_t size = 0;
};

// Entities: { "key" "value" ... } blocks (ioquake3's COM_Parse quoting; no escapes).
Expected<std::vector<BspEntity>> parseEntities(const std::string& text, const std::string& name) {
  std::vector<BspEntity> entities;
  std::size_t i = 0;
  const auto skip = [&] {
    while (i < text.size() && (std::isspace(static_cast<unsigned char>(text[i])) || text[i] == '\0')) ++i;
  };
  const auto quoted = [&]() -> std::optional<std::string> {
    skip();
    if (i >= text.size() || text[i] != '"') return std::nullopt;
    const std::size_t end = text.find('"', i + 1);
    if (end == std::string::npos) return std::nullopt;
    std::string s = text.substr(i + 1, end - i - 1);
    i = end + 1;
    return s;
  };
  for (;;) {
    skip();
    if (i >= text.size()) break;
    if (text[i] != '{') return fail(ErrorCode::kParse, "{}: entities lump: byte {}: expected '{{'", name, i);
    ++i;
    BspEntity entity;
    for (;;) {
      skip();
      if (i < text.size() && text[i] == '}') {
        ++i;
        break;
      }
      auto key = quoted();
      auto value = key ? quoted() : std::nullopt;
      if (!key || !value) return fail(ErrorCode::kParse, "{}: entities lump: byte {}: expected a quoted key and value or '}}'", name, i);
      entity[*key] = *value;
    }
    entities.push_back(std::move(entity));
  }
  return entities;
}
}  // namespace

std::string entityValue(const BspEntity& entity, const std::string& key) {
  for (const auto& [k, v] : entity)
    if (k.size() == key.size() && std::equal(k.begin(), k.end(), key.begin(), [](char a, char b) { return std::tolower(a) == std::tolower(b); }))
      return v;
  return {};
}

glm::dvec3 entityVector(const BspEntity& entity, const std::string& key) {
  std::istringstream in(entityValue(entity, key));
  glm::dvec3 v(0.0);
  in >> v.x >> v.y >> v.z;
  return in ? v : glm::dvec3(0.0);
}

Expected<Bsp> parseBsp(const std::string& bytes, const std::string& name) {
  constexpr std::size_t header = 8 + kLumpCount * 8;
  if (bytes.size() < header) return fail(ErrorCode::kParse, "{}: {} bytes, shorter than a BSP header ({})", name, bytes.size(), header);
  if (bytes.compare(0, 4, "IBSP") != 0) return fail(ErrorCode::kParse, "{}: not an id Tech 3 map (expected 'IBSP' at byte 0)", name);
  if (const int version = load<int>(bytes.data() + 4); version != 46)
    return fail(ErrorCode::kUnsupported, "{}: BSP version {}; expected 46 (Quake III Arena, OpenArena)", name, version);
  std::array<Lump, kLumpCount> lumps;
  for (int l = 0; l < kLumpCount; ++l) {
    const int offset = load<int>(bytes.data() + 8 + l * 8), length = load<int>(bytes.data() + 12 + l * 8);
    if (offset < 0 || length < 0 || static_cast<std::size_t>(offset) + static_cast<std::size_t>(length) > bytes.size())
      return fail(ErrorCode::kInvalidData, "{}: lump {}: bytes {}-{} lie outside the file ({} bytes)", name, l, offset,
                  static_cast<long long>(offset) + length, bytes.size());
    lumps[static_cast<std::size_t>(l)] = {bytes.data() + offset, static_cast<std::size_t>(length)};
  }
  const auto count = [&](int lump, std::size_t stride, const char* what) -> Expected<std::size_t> {
    if (lumps[static_cast<std::size_t>(lump)].size % stride != 0)
      return fail(ErrorCode::kInvalidData, "{}: lump {} ({}): {} bytes, not a whole number of {}-byte records", name, lump, what,
                  lumps[static_cast<std::size_t>(lump)].size, stride);
    return lumps[static_cast<std::size_t>(lump)].size / stride;
  };
  Bsp bsp;
  bsp.name = name;
  {
    const Lump& l = lumps[kLumpEntities];
    auto entities = parseEntities(std::string(l.data, strnlen(l.data, l.size)), name);
    if (!entities) return std::unexpected(entities.error());
    bsp.entities = std::move(*entities);
  }
  auto shaders = count(kLumpShaders, kShaderBytes, "shaders");
  auto models = count(kLumpModels, kModelBytes, "models");
  auto vertices = count(kLumpVertices, kVertexBytes, "draw vertices");
  auto indices = count(kLumpIndices, 4, "draw indices");
  auto surfaces = count(kLumpSurfaces, kSurfaceBytes, "surfaces");
  auto lightmaps = count(kLumpLightmaps, sizeof(Bsp::lightmaps[0]), "lightmaps");
  for (const auto* c : {&shaders, &models, &vertices, &indices, &surfaces, &lightmaps})
    if (!*c) return std::unexpected(c->error());
  for (std::size_t i = 0; i < *shaders; ++i) {
    const char* p = lumps[kLumpShaders].data + i * kShaderBytes;
    bsp.shaders.push_back({std::string(p, strnlen(p, 64)), load<int>(p + 64), load<int>(p + 68)});
  }
  for (std::size_t i = 0; i < *models; ++i) {
    const char* p = lumps[kLumpModels].data + i * kModelBytes;
    bsp.models.push_back({{load<float>(p), load<float>(p + 4), load<float>(p + 8)},
                          {load<float>(p + 12), load<float>(p + 16), load<float>(p + 20)},
                          load<int>(p + 24),
                          load<int>(p + 28)});
  }
  for (std::size_t i = 0; i < *vertices; ++i) {
    const char* p = lumps[kLumpVertices].data + i * kVertexBytes;
    BspVertex v;
    v.position = {load<float>(p), load<float>(p + 4), load<float>(p + 8)};
    v.st = {load<float>(p + 12), load<float>(p + 16)};
    v.lightmap = {load<float>(p + 20), load<float>(p + 24)};
    v.normal = {load<float>(p + 28), load<float>(p + 32), load<float>(p + 36)};
    bsp.vertices.push_back(v);
  }
  bsp.indices.resize(*indices);
  if (*indices > 0) std::memcpy(bsp.indices.data(), lumps[kLumpIndices].data, *indices * 4);
  for (std::size_t i = 0; i < *surfaces; ++i) {
    const char* p = lumps[kLumpSurfaces].data + i * kSurfaceBytes;
    BspSurface s;
    s.shader = load<int>(p);
    const int type = load<int>(p + 8);
    s.type = type >= 1 && type <= 4 ? static_cast<BspSurfaceType>(type) : BspSurfaceType::kBad;
    s.firstVertex = load<int>(p + 12);
    s.vertexCount = load<int>(p + 16);
    s.firstIndex = load<int>(p + 20);
    s.indexCount = load<int>(p + 24);
    s.lightmap = load<int>(p + 28);
    s.patchWidth = load<int>(p + 96);
    s.patchHeight = load<int>(p + 100);
    const auto outside = [](long long first, long long n, std::size_t size) { return first < 0 || n < 0 || first + n > static_cast<long long>(size); };
    if (s.shader < 0 || static_cast<std::size_t>(s.shader) >= bsp.shaders.size() || outside(s.firstVertex, s.vertexCount, bsp.vertices.size()) ||
        outside(s.firstIndex, s.indexCount, bsp.indices.size()) || s.lightmap >= static_cast<int>(*lightmaps))
      return fail(ErrorCode::kInvalidData, "{}: surface {}: its shader, vertices, indices or lightmap page lie outside the file's lumps", name, i);
    bsp.surfaces.push_back(s);
  }
  for (const BspModel& m : bsp.models)
    if (m.firstSurface < 0 || m.surfaceCount < 0 || static_cast<std::size_t>(m.firstSurface) + static_cast<std::size_t>(m.surfaceCount) > bsp.surfaces.size())
      return fail(ErrorCode::kInvalidData, "{}: a model's surfaces lie outside the surfaces lump", name);
  if (bsp.models.empty()) return fail(ErrorCode::kInvalidData, "{}: no models (expected the world as model 0)", name);
  bsp.lightmaps.resize(*lightmaps);
  if (*lightmaps > 0) std::memcpy(bsp.lightmaps.data(), lumps[kLumpLightmaps].data, *lightmaps * sizeof(Bsp::lightmaps[0]));
  if (const Lump& grid = lumps[kLumpLightGrid]; grid.size > 0) {
    // The lattice as SetupGrid lays it (and ioquake3's R_LoadLightGrid reads it): worldspawn's
    // gridsize (64 64 128 unless set; q3map2 stores the size it enlarged to), the world's bounds
    // rounded inwards to multiples of it.
    LightGrid& g = bsp.lightGrid;
    g.spacing = glm::dvec3(64.0, 64.0, 128.0);
    if (!bsp.entities.empty() && !entityValue(bsp.entities[0], "gridsize").empty()) {
      const glm::dvec3 size = entityVector(bsp.entities[0], "gridsize");
      for (int k = 0; k < 3; ++k) g.spacing[k] = size[k] >= 8.0 ? std::floor(size[k]) : 8.0;
    }
    const BspModel& world = bsp.models[0];
    std::size_t expected = 1;
    for (int k = 0; k < 3; ++k) {
      g.origin[k] = g.spacing[k] * std::ceil(world.mins[k] / g.spacing[k]);
      const double top = g.spacing[k] * std::floor(world.maxs[k] / g.spacing[k]);
      g.counts[k] = std::max(0, static_cast<int>((top - g.origin[k]) / g.spacing[k]) + 1);
      expected *= static_cast<std::size_t>(g.counts[k]);
    }
    // A lump of another size is left out, as the engine leaves it out ("light grid mismatch"): the
    // map still plays, lit by its lightmaps; only the grid's check of the lights is lost.
    if (grid.size != expected * 8) {
      g.points.clear();
      g.counts = glm::ivec3(0);
    } else {
      g.points.resize(expected);
    }
    for (std::size_t i = 0; i < g.points.size(); ++i) {
      const auto* p = reinterpret_cast<const std::uint8_t*>(grid.data + i * 8);
      g.points[i] = {{p[0], p[1], p[2]}, {p[3], p[4], p[5]}, {p[6], p[7]}};
    }
  }
  return bsp;
}

glm::dvec3 LightGridPoint::mainDirection() const {
  constexpr double kPerByte = 2.0 * std::numbers::pi / 255.0;  // NormalToLatLong's 255 / 360 per degree
  const double polar = direction[0] * kPerByte, azimuth = direction[1] * kPerByte;
  return {std::cos(azimuth) * std::sin(polar), std::sin(azimuth) * std::sin(polar), std::cos(polar)};
}

bool LightGrid::even(std::size_t index) const {
  const auto nx = static_cast<std::size_t>(counts.x), ny = static_cast<std::size_t>(counts.y);
  return (index % nx + index / nx % ny + index / (nx * ny)) % 2 == 0;
}

double LightGrid::inhibitRadius() const {
  const glm::dvec3& s = spacing;
  return 0.5 * (s.x > s.y && s.x > s.z ? s.x : s.y > s.x && s.y > s.z ? s.y : s.z);
}

glm::dvec3 LightGrid::position(std::size_t index) const {
  const auto nx = static_cast<std::size_t>(counts.x), ny = static_cast<std::size_t>(counts.y);
  return origin + spacing * glm::dvec3(static_cast<double>(index % nx), static_cast<double>(index / nx % ny), static_cast<double>(index / (nx * ny)));
}

std::vector<SurfaceTriangle> surfaceTriangles(const Bsp& bsp, int index, int patchLevel) {
  std::vector<SurfaceTriangle> out;
  const BspSurface& s = bsp.surfaces[static_cast<std::size_t>(index)];
  const auto vertex = [&](int i) -> const BspVertex& { return bsp.vertices[static_cast<std::size_t>(s.firstVertex + i)]; };
  if (s.type == BspSurfaceType::kPatch) {
    const int w = s.patchWidth, h = s.patchHeight;
    if (w < 3 || h < 3 || w % 2 == 0 || h % 2 == 0 || w * h > s.vertexCount) return out;
    struct Point {
      glm::dvec3 p, n;
      glm::dvec2 lm;
    };
    std::vector<Point> grid(static_cast<std::size_t>((patchLevel + 1) * (patchLevel + 1)));
    for (int py = 0; py + 2 < h; py += 2)
      for (int px = 0; px + 2 < w; px += 2) {
        for (int j = 0; j <= patchLevel; ++j)
          for (int i = 0; i <= patchLevel; ++i) {
            const double u = static_cast<double>(i) / patchLevel, v = static_cast<double>(j) / patchLevel;
            const double bu[3] = {(1 - u) * (1 - u), 2 * u * (1 - u), u * u}, bv[3] = {(1 - v) * (1 - v), 2 * v * (1 - v), v * v};
            Point q{glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec2(0.0)};
            for (int b = 0; b < 3; ++b)
              for (int a = 0; a < 3; ++a) {
                const BspVertex& c = vertex((py + b) * w + px + a);
                const double weight = bu[a] * bv[b];
                q.p += weight * glm::dvec3(c.position);
                q.n += weight * glm::dvec3(c.normal);
                q.lm += weight * glm::dvec2(c.lightmap);
              }
            if (glm::length(q.n) > 0) q.n = glm::normalize(q.n);
            grid[static_cast<std::size_t>(j * (patchLevel + 1) + i)] = q;
          }
        // The control normals follow cross(P(i+1, j) - P(i, j), P(i, j+1) - P(i, j)) (the capture
        // adapter's note): (a, c, b) and (b, c, d) face them.
        for (int j = 0; j < patchLevel; ++j)
          for (int i = 0; i < patchLevel; ++i) {
            const int a = j * (patchLevel + 1) + i, b = a + 1, c = a + patchLevel + 1, d = c + 1;
            for (const auto& tri : {std::array<int, 3>{a, c, b}, std::array<int, 3>{b, c, d}}) {
              SurfaceTriangle t;
              t.surface = index;
              for (int k = 0; k < 3; ++k) {
                const Point& q = grid[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])];
                t.position[static_cast<std::size_t>(k)] = q.p;
                t.normal[static_cast<std::size_t>(k)] = q.n;
                t.lightmap[static_cast<std::size_t>(k)] = q.lm;
              }
              out.push_back(t);
            }
          }
      }
    return out;
  }
  if (s.type != BspSurfaceType::kPlanar && s.type != BspSurfaceType::kTriangleSoup) return out;
  for (int i = 0; i + 2 < s.indexCount; i += 3) {
    std::array<int, 3> corner{};
    bool valid = true;
    for (int k = 0; k < 3; ++k) {
      corner[static_cast<std::size_t>(k)] = bsp.indices[static_cast<std::size_t>(s.firstIndex + i + k)];
      valid = valid && corner[static_cast<std::size_t>(k)] >= 0 && corner[static_cast<std::size_t>(k)] < s.vertexCount;
    }
    if (!valid) continue;
    // Planar faces and soups are wound clockwise seen from the front: turned round here.
    SurfaceTriangle t;
    t.surface = index;
    const std::array<int, 3> order{corner[0], corner[2], corner[1]};
    for (int k = 0; k < 3; ++k) {
      const BspVertex& v = vertex(order[static_cast<std::size_t>(k)]);
      t.position[static_cast<std::size_t>(k)] = glm::dvec3(v.position);
      t.normal[static_cast<std::size_t>(k)] = glm::dvec3(v.normal);
      t.lightmap[static_cast<std::size_t>(k)] = glm::dvec2(v.lightmap);
    }
    out.push_back(t);
  }
  return out;
}

}  // namespace dynbench::maplight
