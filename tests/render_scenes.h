#pragma once
// Small analytic scenes for the renderer's tests (render_test.cpp, radiance_change_test.cpp): glTF
// materials, meshes, spheres and planes written with the test GltfBuilder, loaded by dynbench's own
// reader, and cameras and path tracers for them.
#include <memory>
#include <string>
#include <vector>

#include "gltf_builder.h"
#include "render/path_tracer.h"
#include "scene/scene.h"

namespace dynbench::render {

// A material the builder can add: base colour, metallic, roughness; specular 0 makes it Lambertian.
int addMaterial(test::GltfBuilder& b, glm::dvec3 base, double metallic, double roughness, bool lambert,
                glm::dvec3 emissive = glm::dvec3(0.0));
int addMesh(test::GltfBuilder& b, const std::vector<float>& positions, const std::vector<std::uint32_t>& indices, int material,
            const std::vector<float>& normals = {});
// A flat-shaded (no normals) UV sphere: convex, so a ray leaving it never comes back.
int addSphere(test::GltfBuilder& b, glm::dvec3 centre, double radius, int material, int rings = 24, int segments = 48);
// A y = height square of half size `half`, facing +Y.
int addPlane(test::GltfBuilder& b, double half, double height, int material);
// Writes the builder's glTF into a fresh folder named `name` and loads it (a failed load fails the test).
scene::Scene load(test::GltfBuilder& b, const std::string& name);
// A camera at the origin turned by `yawDegrees` about +Y (discard's and reprojection's tests).
RenderCamera yawCamera(double yawDegrees, int w, int h, double yfovDegrees);
// A camera at `position` looking along `forward` (up +Y, or -Z when looking straight down).
RenderCamera lookCamera(glm::dvec3 position, glm::dvec3 forward, double yfovDegrees, int w, int h);
// The path tracer for a scene (a failed creation fails the test and returns null).
std::unique_ptr<PathTracer> tracerFor(const scene::Scene& s, const RenderSettings& settings);
glm::dvec3 rgb(const std::vector<float>& buffer, std::size_t i);

}  // namespace dynbench::render
