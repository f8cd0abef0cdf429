#include "render/raytracing_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <embree3/rtcore.h>

#include "core/simd.h"
#include "render/prefetch.h"
#include "scene/queries.h"

namespace dynbench::render {
namespace {

// Embree reports errors through a callback; the last one is kept and turned into an Error.
void onEmbreeError(void* user, RTCError, const char* message) { *static_cast<std::string*>(user) = message ? message : "unknown"; }

struct Entry {  // what an Embree geometry is in the scene model
  int node = -1;
  int primitive = -1;
  const scene::Primitive* source = nullptr;  // the scene model's primitive (SurfaceHit::source)
  RTCGeometry geometry = nullptr;  // dynamic entries keep theirs to update it every frame
  bool enabled = true;
  bool previousValid = false;  // previousPositions hold the update before the last one
  std::vector<glm::dvec3> positions, normals;  // world space (double copies for exact hit data)
  std::vector<glm::dvec3> previousPositions;
  std::vector<std::uint32_t> indices;
};

// Embree calls this for every candidate hit on a geometry with an alpha test; rejecting the hit
// (valid = 0) lets the ray go on through the cut-out part of the surface.
struct AlphaFilterData {
  const AlphaTest* test = nullptr;
  int node = -1, primitive = -1;
};

void alphaFilter(const RTCFilterFunctionNArguments* args) {
  const auto* data = static_cast<const AlphaFilterData*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
    const glm::dvec2 uv(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    if (!data->test->opaque(data->node, data->primitive, prim, uv)) args->valid[i] = 0;
  }
}

// All vertices at one point (or none): the geometry covers no area.
bool collapsed(const std::vector<glm::dvec3>& positions) {
  for (const auto& p : positions)
    if (p != positions.front()) return false;
  return true;
}

}  // namespace

struct RayTracingScene::Impl {
  const scene::Scene* scene = nullptr;
  AlphaTest alphaTest;
  std::vector<std::unique_ptr<AlphaFilterData>> filterData;
  scene::Evaluator evaluator;
  std::string error;
  RTCDevice device = nullptr;
  RTCScene top = nullptr, staticScene = nullptr, dynamicScene = nullptr;
  std::vector<Entry> staticEntries, dynamicEntries;
  scene::ScenePose pose;                          // every node at the last update's time
  bool updated = false;                           // update() has run at least once
  RayTracingStats stats;

  explicit Impl(const scene::Scene& s) : scene(&s), evaluator(s) {}
  ~Impl() {
    for (auto& e : dynamicEntries)
      if (e.geometry) rtcReleaseGeometry(e.geometry);
    for (RTCScene* sc : {&top, &staticScene, &dynamicScene})
      if (*sc) rtcReleaseScene(*sc);
    if (device) rtcReleaseDevice(device);
  }

  static void copyVertices(RTCGeometry geometry, const std::vector<glm::dvec3>& positions) {
    auto* vertices = static_cast<float*>(rtcGetGeometryBufferData(geometry, RTC_BUFFER_TYPE_VERTEX, 0));
    for (std::size_t v = 0; v < positions.size(); ++v)
      for (int c = 0; c < 3; ++c) vertices[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(positions[v][c]);
  }

  // Adds a triangle geometry (a float copy for Embree). Dynamic geometries are refitted every
  // frame: same topology, new vertices, so Embree updates bounds instead of rebuilding.
  void addTriangles(RTCScene target, std::vector<Entry>& entries, Entry entry, bool dynamicGeometry) {
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), entry.positions.size());
    copyVertices(geometry, entry.positions);
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), entry.indices.size() / 3));
    std::copy(entry.indices.begin(), entry.indices.end(), indices);
    if (dynamicGeometry) rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_REFIT);
    if (alphaTest.needed && alphaTest.opaque && alphaTest.needed(entry.node, entry.primitive)) {
      filterData.push_back(std::make_unique<AlphaFilterData>(AlphaFilterData{&alphaTest, entry.node, entry.primitive}));
      rtcSetGeometryUserData(geometry, filterData.back().get());
      rtcSetGeometryIntersectFilterFunction(geometry, alphaFilter);
      rtcSetGeometryOccludedFilterFunction(geometry, alphaFilter);
    }
    // A dynamic geometry hidden at rest (a capturable that appears later, held at scale 0) starts
    // disabled: degenerate bounds of many such geometries trip Embree's two-level builder.
    if (dynamicGeometry && !entry.enabled) rtcDisableGeometry(geometry);
    rtcCommitGeometry(geometry);
    const unsigned id = rtcAttachGeometry(target, geometry);
    if (dynamicGeometry) entry.geometry = geometry;  // the scene holds a reference too
    else rtcReleaseGeometry(geometry);
    if (entries.size() <= id) entries.resize(id + 1);
    entries[id] = std::move(entry);
  }

  Entry evaluate(int node, int primitive, double t, const scene::ScenePose* pose = nullptr) const {
    Entry e;
    e.node = node;
    e.primitive = primitive;
    if (pose) evaluator.worldGeometry(node, static_cast<std::size_t>(primitive), t, *pose, e.positions, e.normals);
    else evaluator.worldGeometry(node, static_cast<std::size_t>(primitive), t, e.positions, e.normals);
    const auto& prim = scene->meshes[static_cast<std::size_t>(scene->nodes[static_cast<std::size_t>(node)].mesh)]
                           .primitives[static_cast<std::size_t>(primitive)];
    e.indices = prim.indices;
    e.source = &prim;
    return e;
  }
};

namespace {

// Embree picks its kernels for the CPU at run time (SSE4.2 to AVX-512), and its AVX-512 and AVX2
// kernels hit differently (core/simd.h): every scene gets the AVX2 ones (core::kEmbreeDeviceConfig)
// unless DYNBENCH_EMBREE_CONFIG passes another device configuration (rtcNewDevice(3), e.g.
// "max_isa=sse4.2"), so that one machine can run as another would: the reproducibility checks of
// issue 45 use it (docs/suite.md, "Pins").
RTCDevice newDevice() {
  const char* config = std::getenv("DYNBENCH_EMBREE_CONFIG");
  return rtcNewDevice(config && *config ? config : core::kEmbreeDeviceConfig);
}

}  // namespace

RayTracingScene::RayTracingScene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RayTracingScene::~RayTracingScene() = default;

Expected<std::unique_ptr<RayTracingScene>> RayTracingScene::create(const scene::Scene& scene, AlphaTest alphaTest) {
  auto impl = std::make_unique<Impl>(scene);
  impl->alphaTest = std::move(alphaTest);
  impl->device = newDevice();
  if (!impl->device) return fail(ErrorCode::kExternalTool, "Embree: cannot create a device (error {})", static_cast<int>(rtcGetDeviceError(nullptr)));
  rtcSetDeviceErrorFunction(impl->device, onEmbreeError, &impl->error);
  impl->staticScene = rtcNewScene(impl->device);
  impl->dynamicScene = rtcNewScene(impl->device);
  rtcSetSceneBuildQuality(impl->dynamicScene, RTC_BUILD_QUALITY_LOW);  // rebuilt every frame
  rtcSetSceneFlags(impl->dynamicScene, RTC_SCENE_FLAG_DYNAMIC);

  // Static: not dynamic (docs/metrics.md), not skinned, no morph animation, visible at rest.
  const auto dynamic = scene::dynamicNodes(scene);
  const auto inScene = scene::nodesInScene(scene);
  std::vector<char> morphing(scene.nodes.size(), 0);
  for (const auto& a : scene.animations)
    for (const auto& c : a.channels)
      if (c.path == scene::AnimationPath::kWeights) morphing[static_cast<std::size_t>(c.node)] = 1;
  for (std::size_t i = 0; i < scene.nodes.size(); ++i) {
    const auto& node = scene.nodes[i];
    if (!inScene[i] || node.mesh < 0) continue;
    const auto& mesh = scene.meshes[static_cast<std::size_t>(node.mesh)];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
      if (mesh.primitives[p].triangleCount() == 0) continue;
      if (dynamic[i] || node.skin >= 0 || morphing[i]) {
        // Created once with the rest pose; update() refits it to each frame.
        Entry e = impl->evaluate(static_cast<int>(i), static_cast<int>(p), 0.0);
        e.enabled = impl->evaluator.visible(static_cast<int>(i), 0.0) && !collapsed(e.positions);
        impl->addTriangles(impl->dynamicScene, impl->dynamicEntries, std::move(e), true);
      } else if (impl->evaluator.visible(static_cast<int>(i), 0.0)) {
        Entry e = impl->evaluate(static_cast<int>(i), static_cast<int>(p), 0.0);
        impl->stats.staticTriangles += e.indices.size() / 3;
        impl->addTriangles(impl->staticScene, impl->staticEntries, std::move(e), false);
      }
    }
  }
  rtcCommitScene(impl->staticScene);
  impl->top = rtcNewScene(impl->device);
  for (RTCScene child : {impl->staticScene, impl->dynamicScene}) {
    RTCGeometry instance = rtcNewGeometry(impl->device, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(instance, child);
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryTransform(instance, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
    rtcCommitGeometry(instance);
    rtcAttachGeometry(impl->top, instance);  // instance 0: static, 1: dynamic
    rtcReleaseGeometry(instance);
  }
  rtcCommitScene(impl->dynamicScene);
  rtcCommitScene(impl->top);
  if (const RTCError code = rtcGetDeviceError(impl->device); code != RTC_ERROR_NONE || !impl->error.empty())
    return fail(ErrorCode::kExternalTool, "Embree: building the scene failed: {}",
                impl->error.empty() ? fmt::format("error code {}", static_cast<int>(code)) : impl->error);
  return std::unique_ptr<RayTracingScene>(new RayTracingScene(std::move(impl)));
}

Expected<void> RayTracingScene::update(double t) {
  Impl& m = *impl_;
  m.stats.dynamicTriangles = 0;
  m.evaluator.evaluate(t, m.pose);  // all world matrices and visibility once, then look them up
  for (auto& e : m.dynamicEntries) {
    if (!e.geometry) continue;
    bool visible = m.pose.visible[static_cast<std::size_t>(e.node)] != 0;
    if (visible) {
      std::swap(e.previousPositions, e.positions);
      m.evaluator.worldGeometry(e.node, static_cast<std::size_t>(e.primitive), t, m.pose, e.positions, e.normals);
      // Shrunk to a point (a skinned mesh whose model node is held at scale 0): nothing to hit.
      visible = !collapsed(e.positions);
      if (!visible) std::swap(e.previousPositions, e.positions);
    }
    if (!visible) {
      if (e.enabled) rtcDisableGeometry(e.geometry);
      e.enabled = false;
      e.previousValid = false;
      continue;
    }
    e.previousValid = e.enabled && m.updated;
    Impl::copyVertices(e.geometry, e.positions);
    rtcUpdateGeometryBuffer(e.geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    if (!e.enabled) rtcEnableGeometry(e.geometry);
    e.enabled = true;
    rtcCommitGeometry(e.geometry);
    m.stats.dynamicTriangles += e.indices.size() / 3;
  }
  rtcCommitScene(m.dynamicScene);
  rtcCommitGeometry(rtcGetGeometry(m.top, 1));
  rtcCommitScene(m.top);
  // Embree reports errors through the callback (and its error flag); a failed refit or commit
  // would otherwise trace against a half-updated BVH.
  if (const RTCError code = rtcGetDeviceError(m.device); code != RTC_ERROR_NONE || !m.error.empty()) {
    const std::string message = m.error.empty() ? fmt::format("error code {}", static_cast<int>(code)) : m.error;
    m.error.clear();
    return fail(ErrorCode::kExternalTool, "Embree: updating the scene to t = {} s failed: {}", t, message);
  }
  m.updated = true;
  return {};
}

glm::dvec3 RayTracingScene::previousPosition(const SurfaceHit& hit) const {
  if (!hit.hit || !hit.dynamicGeometry) return hit.position;
  const Entry& e = impl_->dynamicEntries[hit.geometry];
  if (!e.previousValid) return hit.position;
  const auto& idx = hit.vertices;
  const double u = hit.barycentric.x, v = hit.barycentric.y;
  return (1.0 - u - v) * e.previousPositions[idx[0]] + u * e.previousPositions[idx[1]] + v * e.previousPositions[idx[2]];
}

void RayTracingScene::forEachPrimitive(const std::function<void(const PrimitiveView&)>& visit) const {
  for (const auto* entries : {&impl_->staticEntries, &impl_->dynamicEntries})
    for (const Entry& e : *entries)
      if (e.node >= 0 && e.enabled) visit(PrimitiveView{e.node, e.primitive, &e.positions, &e.indices});
}

std::array<glm::dvec3, 3> RayTracingScene::trianglePositions(const SurfaceHit& hit) const {
  const Entry& e = (hit.dynamicGeometry ? impl_->dynamicEntries : impl_->staticEntries)[hit.geometry];
  const auto& idx = hit.vertices;
  return {e.positions[idx[0]], e.positions[idx[1]], e.positions[idx[2]]};
}

const scene::ScenePose& RayTracingScene::pose() const { return impl_->pose; }

namespace {

// Written field by field into the record Embree reads, not built on the stack and copied: GCC
// copies such a temporary with 16-byte loads of 4-byte stores just made, a store-forwarding stall
// per load (perf put a quarter of the hit bookkeeping's time on those copies).
void setEmbreeRay(RTCRayHit& rh, const Ray& ray, double tMin, double tMax) {
  rh.ray.org_x = static_cast<float>(ray.origin.x);
  rh.ray.org_y = static_cast<float>(ray.origin.y);
  rh.ray.org_z = static_cast<float>(ray.origin.z);
  rh.ray.tnear = static_cast<float>(tMin);
  rh.ray.dir_x = static_cast<float>(ray.direction.x);
  rh.ray.dir_y = static_cast<float>(ray.direction.y);
  rh.ray.dir_z = static_cast<float>(ray.direction.z);
  rh.ray.time = 0.0f;
  rh.ray.tfar = static_cast<float>(std::min(tMax, 1e30));
  rh.ray.mask = 0xFFFFFFFF;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

}  // namespace

static void setSurfacePoint(SurfaceHit& hit, const Entry& e, bool dynamicGeometry, unsigned geometry, unsigned triangle, glm::dvec2 b);

// The hit record of what Embree found: the scene model's ids and double-precision surface data,
// written in place (see setEmbreeRay).
static void setSurfaceHit(SurfaceHit& hit, const RayTracingScene::Impl& impl, const RTCRayHit& rh) {
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
    hit = SurfaceHit{};
    return;
  }
  const auto& entries = rh.hit.instID[0] == 0 ? impl.staticEntries : impl.dynamicEntries;
  hit.distance = rh.ray.tfar;
  setSurfacePoint(hit, entries[rh.hit.geomID], rh.hit.instID[0] != 0, rh.hit.geomID, rh.hit.primID, {rh.hit.u, rh.hit.v});
}

// The surface data of barycentric point b of triangle `triangle` of an entry, at its positions.
static void setSurfacePoint(SurfaceHit& hit, const Entry& e, bool dynamicGeometry, unsigned geometry, unsigned triangle, glm::dvec2 b) {
  hit.hit = true;
  hit.node = e.node;
  hit.primitive = e.primitive;
  hit.source = e.source;
  hit.triangle = triangle;
  hit.barycentric = b;
  hit.dynamicGeometry = dynamicGeometry;
  hit.geometry = geometry;
  const std::uint32_t i0 = e.indices[3 * triangle], i1 = e.indices[3 * triangle + 1], i2 = e.indices[3 * triangle + 2];
  hit.vertices = {i0, i1, i2};
  const double u = b.x, v = b.y, w = 1.0 - u - v;
  hit.position = w * e.positions[i0] + u * e.positions[i1] + v * e.positions[i2];
  hit.geometricNormal = glm::normalize(glm::cross(e.positions[i1] - e.positions[i0], e.positions[i2] - e.positions[i0]));
  hit.shadingNormal = hit.geometricNormal;
  if (!e.normals.empty()) {
    const glm::dvec3 n = w * e.normals[i0] + u * e.normals[i1] + v * e.normals[i2];
    if (glm::length(n) > 0) hit.shadingNormal = glm::normalize(n);
  }
}

SurfaceHit RayTracingScene::surfaceAt(const SurfaceHit& other) const {
  SurfaceHit hit;
  if (!other.hit) return hit;
  const auto& entries = other.dynamicGeometry ? impl_->dynamicEntries : impl_->staticEntries;
  if (other.geometry >= entries.size()) return hit;
  const Entry& e = entries[other.geometry];
  // Hidden at this update (a geometry that appears later, or held at scale 0): no such point.
  if (e.node != other.node || e.primitive != other.primitive || !e.enabled || 3 * (other.triangle + 1) > e.indices.size()) return hit;
  setSurfacePoint(hit, e, other.dynamicGeometry, other.geometry, other.triangle, other.barycentric);
  hit.distance = other.distance;
  return hit;
}

SurfaceHit RayTracingScene::intersect(const Ray& ray, double tMin, double tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  setEmbreeRay(rh, ray, tMin, tMax);
  rtcIntersect1(impl_->top, &context, &rh);
  SurfaceHit hit;
  setSurfaceHit(hit, *impl_, rh);
  return hit;
}

void RayTracingScene::intersect(std::span<const Ray> rays, std::span<SurfaceHit> hits) const {
  // Embree's ray records, kept per thread between calls so that a stream does not allocate.
  thread_local std::vector<RTCRayHit> stream;
  stream.resize(rays.size());
  for (std::size_t k = 0; k < rays.size(); ++k) setEmbreeRay(stream[k], rays[k], 0.0, 1e30);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  rtcIntersect1M(impl_->top, &context, stream.data(), static_cast<unsigned>(stream.size()), sizeof(RTCRayHit));
  // The hit records read each triangle's indices, then its vertices: prefetched for every ray
  // first, in two passes, instead of waiting on them one ray at a time.
  auto entryOf = [&](const RTCRayHit& rh) -> const Entry& {
    return (rh.hit.instID[0] == 0 ? impl_->staticEntries : impl_->dynamicEntries)[rh.hit.geomID];
  };
  for (const RTCRayHit& rh : stream)
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) prefetchLine(&entryOf(rh).indices[3 * rh.hit.primID]);
  for (const RTCRayHit& rh : stream) {
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    const Entry& e = entryOf(rh);
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = e.indices[3 * rh.hit.primID + static_cast<unsigned>(c)];
      prefetchLine(&e.positions[v]);
      if (!e.normals.empty()) prefetchLine(&e.normals[v]);
    }
  }
  for (std::size_t k = 0; k < rays.size(); ++k) setSurfaceHit(hits[k], *impl_, stream[k]);
}

bool RayTracingScene::occluded(const glm::dvec3& origin, const glm::dvec3& direction, double tMax) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = static_cast<float>(origin.x);
  ray.org_y = static_cast<float>(origin.y);
  ray.org_z = static_cast<float>(origin.z);
  ray.dir_x = static_cast<float>(direction.x);
  ray.dir_y = static_cast<float>(direction.y);
  ray.dir_z = static_cast<float>(direction.z);
  ray.tnear = 0.0f;
  ray.tfar = static_cast<float>(tMax);
  ray.mask = 0xFFFFFFFF;
  rtcOccluded1(impl_->top, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

RayTracingStats RayTracingScene::stats() const { return impl_->stats; }

struct SphereIndex::Impl {
  std::string error;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// Float boxes that contain the double spheres: grown by a relative margin so rounding cannot cut
// off a point the exact test accepts.
void sphereBounds(const RTCBoundsFunctionArguments* args) {
  const auto& s = (*static_cast<const std::vector<glm::dvec4>*>(args->geometryUserPtr))[args->primID];
  const double r = s.w * (1.0 + 1e-5) + 1e-6 * std::max({1.0, std::abs(s.x), std::abs(s.y), std::abs(s.z)});
  args->bounds_o->lower_x = static_cast<float>(s.x - r);
  args->bounds_o->lower_y = static_cast<float>(s.y - r);
  args->bounds_o->lower_z = static_cast<float>(s.z - r);
  args->bounds_o->upper_x = static_cast<float>(s.x + r);
  args->bounds_o->upper_y = static_cast<float>(s.y + r);
  args->bounds_o->upper_z = static_cast<float>(s.z + r);
}

struct SphereQuery {
  const std::vector<glm::dvec4>* spheres;
  glm::dvec3 point;
  std::vector<std::uint32_t>* found;
};

bool sphereQueryVisit(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<SphereQuery*>(args->userPtr);
  const glm::dvec4& s = (*q->spheres)[args->primID];
  const glm::dvec3 d = q->point - glm::dvec3(s);
  if (glm::dot(d, d) < s.w * s.w) q->found->push_back(args->primID);
  return false;  // the query radius stays 0
}

}  // namespace

SphereIndex::SphereIndex() : impl_(std::make_unique<Impl>()) {}
SphereIndex::~SphereIndex() = default;

Expected<void> SphereIndex::build(const std::vector<glm::dvec4>& spheres) {
  for (std::size_t i = 0; i < spheres.size(); ++i)
    if (!(spheres[i].w > 0) || !std::isfinite(spheres[i].w))
      return fail(ErrorCode::kInternal, "sphere index: sphere {} has radius {}; expected a finite positive radius", i, spheres[i].w);
  spheres_ = spheres;
  if (!impl_->device) {
    impl_->device = newDevice();
    if (!impl_->device) return fail(ErrorCode::kExternalTool, "Embree: cannot create a device (error {})", static_cast<int>(rtcGetDeviceError(nullptr)));
    rtcSetDeviceErrorFunction(impl_->device, onEmbreeError, &impl_->error);
  }
  if (impl_->scene) rtcReleaseScene(impl_->scene);
  impl_->scene = nullptr;
  if (spheres_.empty()) return {};
  impl_->scene = rtcNewScene(impl_->device);
  RTCGeometry geometry = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(geometry, static_cast<unsigned>(spheres_.size()));
  rtcSetGeometryUserData(geometry, &spheres_);
  rtcSetGeometryBoundsFunction(geometry, sphereBounds, nullptr);
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(impl_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(impl_->scene);
  if (!impl_->error.empty()) return fail(ErrorCode::kExternalTool, "Embree: building the light hierarchy failed: {}", impl_->error);
  return {};
}

void SphereIndex::query(const glm::dvec3& p, std::vector<std::uint32_t>& found) const {
  found.clear();
  if (!impl_->scene) return;
  RTCPointQuery query;
  query.x = static_cast<float>(p.x);
  query.y = static_cast<float>(p.y);
  query.z = static_cast<float>(p.z);
  query.radius = 0.0f;
  query.time = 0.0f;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  SphereQuery q{&spheres_, p, &found};
  rtcPointQuery(impl_->scene, &query, &context, sphereQueryVisit, &q);
}

Expected<StaticGeometry> StaticGeometry::create(const scene::Scene& scene) {
  scene::Scene still = scene;
  const auto dynamic = scene::dynamicNodes(still);
  for (std::size_t n = 0; n < still.nodes.size(); ++n)
    if (dynamic[n]) still.nodes[n].mesh = still.nodes[n].skin = -1;
  auto tracer = RayTracingScene::create(still);
  if (!tracer) return std::unexpected(tracer.error());
  if (auto ok = (*tracer)->update(still.timeRange().start); !ok) return std::unexpected(ok.error());
  return StaticGeometry(std::move(*tracer));
}

std::vector<std::size_t> StaticGeometry::segmentsThrough(const std::vector<glm::dvec3>& points) const {
  std::vector<std::size_t> crossing;
  for (std::size_t k = 0; k + 1 < points.size(); ++k) {
    const glm::dvec3 d = points[k + 1] - points[k];
    const double length = glm::length(d);
    if (length > 0 && tracer_->occluded(points[k], d / length, length)) crossing.push_back(k);
  }
  return crossing;
}

StaticGeometry::Obstacle StaticGeometry::firstObstacle(const glm::dvec3& origin, const glm::dvec3& direction, double tMax) const {
  const SurfaceHit hit = tracer_->intersect(Ray{origin, direction}, 0.0, tMax);
  if (!hit.hit) return {std::numeric_limits<double>::infinity(), glm::dvec3(0.0)};
  return {hit.distance, hit.geometricNormal};
}

Expected<std::vector<std::size_t>> segmentsThroughStaticGeometry(const scene::Scene& scene, const std::vector<glm::dvec3>& points) {
  auto geometry = StaticGeometry::create(scene);
  if (!geometry) return std::unexpected(geometry.error());
  return geometry->segmentsThrough(points);
}

}  // namespace dynbench::render
