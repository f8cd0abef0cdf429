#include "render_scenes.h"

#include <gtest/gtest.h>

#include "core/math.h"
#include "scene/load.h"

namespace dynbench::render {

using nlohmann::json;

// A material the builder can add: base colour, metallic, roughness; specular 0 makes it Lambertian.
int addMaterial(test::GltfBuilder& b, glm::dvec3 base, double metallic, double roughness, bool lambert, glm::dvec3 emissive) {
  json m = {{"pbrMetallicRoughness", {{"baseColorFactor", {base.r, base.g, base.b, 1.0}}, {"metallicFactor", metallic}, {"roughnessFactor", roughness}}},
            {"emissiveFactor", {emissive.r, emissive.g, emissive.b}}};
  if (lambert) m["extensions"] = {{"KHR_materials_specular", {{"specularFactor", 0.0}}}};
  b.doc["materials"].push_back(m);
  return static_cast<int>(b.doc["materials"].size()) - 1;
}

int addMesh(test::GltfBuilder& b, const std::vector<float>& positions, const std::vector<std::uint32_t>& indices, int material,
            const std::vector<float>& normals) {
  json attributes = {{"POSITION", b.accessor(positions, "VEC3")}};
  if (!normals.empty()) attributes["NORMAL"] = b.accessor(normals, "VEC3");
  json primitive = {{"attributes", attributes}, {"indices", b.indices(indices)}, {"material", material}};
  b.doc["meshes"].push_back({{"primitives", json::array({primitive})}});
  return static_cast<int>(b.doc["meshes"].size()) - 1;
}

// A flat-shaded (no normals) UV sphere: convex, so a ray leaving it never comes back.
int addSphere(test::GltfBuilder& b, glm::dvec3 centre, double radius, int material, int rings, int segments) {
  std::vector<float> p;
  std::vector<std::uint32_t> idx;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const double theta = kPi * r / rings, phi = 2 * kPi * s / segments;
      const glm::dvec3 v = centre + radius * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      p.insert(p.end(), {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)});
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const auto a = static_cast<std::uint32_t>(r * (segments + 1) + s), c = a + static_cast<std::uint32_t>(segments + 1);
      if (r > 0) idx.insert(idx.end(), {a, a + 1, c});
      if (r < rings - 1) idx.insert(idx.end(), {a + 1, c + 1, c});
    }
  return addMesh(b, p, idx, material);
}

// A y = height square of half size `half`, facing +Y.
int addPlane(test::GltfBuilder& b, double half, double height, int material) {
  const auto h = static_cast<float>(half), y = static_cast<float>(height);
  return addMesh(b, {-h, y, -h, -h, y, h, h, y, h, h, y, -h}, {0, 1, 2, 0, 2, 3}, material, {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0});
}

scene::Scene load(test::GltfBuilder& b, const std::string& name) {
  auto s = scene::loadScene(b.write(test::freshDir(name), name));
  EXPECT_TRUE(s) << s.error().message;
  return s ? std::move(*s) : scene::Scene{};
}

// A camera at `position` looking along `forward` (up +Y, or -Z when looking straight down).
RenderCamera yawCamera(double yawDegrees, int w, int h, double yfovDegrees) {
  const glm::dmat4 world = glm::mat4_cast(quatFromYawPitchRoll(radians(yawDegrees), 0.0, 0.0));
  scene::Camera lens;
  lens.yfov = radians(yfovDegrees);
  lens.znear = 0.1;
  lens.zfar = 1000;
  return RenderCamera(world, lens, w, h);
}

RenderCamera lookCamera(glm::dvec3 position, glm::dvec3 forward, double yfovDegrees, int w, int h) {
  forward = glm::normalize(forward);
  const glm::dvec3 up = std::abs(forward.y) > 0.99 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
  const glm::dvec3 x = glm::normalize(glm::cross(forward, up)), y = glm::cross(x, forward);
  glm::dmat4 world(1.0);
  world[0] = glm::dvec4(x, 0);
  world[1] = glm::dvec4(y, 0);
  world[2] = glm::dvec4(-forward, 0);
  world[3] = glm::dvec4(position, 1);
  scene::Camera lens;
  lens.yfov = radians(yfovDegrees);
  lens.znear = 0.01;
  return RenderCamera(world, lens, w, h);
}

std::unique_ptr<PathTracer> tracerFor(const scene::Scene& s, const RenderSettings& settings) {
  std::vector<std::string> warnings;
  auto t = PathTracer::create(s, settings, warnings);
  EXPECT_TRUE(t) << t.error().message;
  return t ? std::move(*t) : nullptr;
}

glm::dvec3 rgb(const std::vector<float>& buffer, std::size_t i) {
  return {buffer[3 * i], buffer[3 * i + 1], buffer[3 * i + 2]};
}

}  // namespace dynbench::render
