#include "render/lights.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/image_io.h"
#include "core/math.h"
#include "render/equirect_batch.h"

namespace dynbench::render {

Expected<EnvironmentLight> EnvironmentLight::load(const scene::Environment& environment) {
  auto image = readImage(environment.file);
  if (!image) return std::unexpected(image.error());
  if (image->channels < 3 || image->width < 2 || image->height < 1)
    return fail(ErrorCode::kInvalidData, "{}: the environment must be an RGB image (got {}x{} with {} channels)",
                environment.file.string(), image->width, image->height, image->channels);
  EnvironmentLight env;
  env.width_ = image->width;
  env.height_ = image->height;
  env.pixels_.resize(static_cast<std::size_t>(env.width_) * env.height_);
  std::vector<double> weights(env.pixels_.size());
  double total = 0.0, solidAngle = 0.0;
  for (int y = 0; y < env.height_; ++y) {
    const double pixelSolidAngle = equirectPixelSolidAngle(y, env.width_, env.height_);
    for (int x = 0; x < env.width_; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * env.width_ + x;
      const float* p = &image->pixels[i * static_cast<std::size_t>(image->channels)];
      glm::vec3 value(p[0], p[1], p[2]);
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(value[c]) || value[c] < 0) value[c] = 0;  // NaN/negative texels emit nothing
      env.pixels_[i] = glm::vec4(value * environment.intensity, 0.0f);
      const double y709 = luminance(glm::dvec3(env.pixels_[i]));
      weights[i] = y709 * pixelSolidAngle;
      total += y709 * pixelSolidAngle;
      solidAngle += pixelSolidAngle;
    }
  }
  env.meanLuminance_ = solidAngle > 0 ? total / solidAngle : 0.0;
  env.distribution_ = Distribution2D(weights, env.width_, env.height_);
  if (!env.distribution_.empty())
    for (int y = 0; y < env.height_; ++y)
      for (int x = 0; x < env.width_; ++x)
        env.pixels_[static_cast<std::size_t>(y) * env.width_ + x].w =
            static_cast<float>(env.distribution_.density({(x + 0.5) / env.width_, (y + 0.5) / env.height_}));
  return env;
}

EnvironmentLight EnvironmentLight::constant(const glm::dvec3& radiance) {
  EnvironmentLight env;
  env.width_ = 2;  // two columns so the mapping has a seam like any other image
  env.height_ = 1;
  env.pixels_.assign(2, glm::vec4(glm::vec3(radiance), 0.0f));  // density unused: sampled as a sphere
  // Weight by solid angle only: with one row this samples the sphere uniformly.
  const std::vector<double> weights{1.0, 1.0};
  env.distribution_ = Distribution2D(weights, 2, 1);
  env.meanLuminance_ = luminance(radiance);
  return env;
}

std::size_t EnvironmentLight::pixelAt(glm::dvec2 uv) const {
  const int x = std::clamp(static_cast<int>(uv.x * width_), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(uv.y * height_), 0, height_ - 1);
  return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
}

glm::dvec3 EnvironmentLight::radiance(const glm::dvec3& direction) const {
  return glm::dvec3(pixels_[pixelAt(equirectCoordinates(direction))]);
}

// A density over the image square becomes a solid-angle density through the equirectangular
// Jacobian: dω = 2π² sin θ du dv.
double EnvironmentLight::solidAngleDensity(double density, double sinTheta) { return sinTheta > 0 ? density / (2.0 * kPi * kPi * sinTheta) : 0.0; }

glm::dvec3 EnvironmentLight::radiance(const glm::dvec3& direction, double* pdf) const {
  double sinTheta = 0.0;
  const glm::dvec2 uv = equirectCoordinates(direction, &sinTheta);
  return radianceAt(uv, sinTheta, pdf);
}

void EnvironmentLight::prefetchPixel(glm::dvec2 uv) const { prefetchLine(&pixels_[pixelAt(uv)]); }

glm::dvec3 EnvironmentLight::radianceAt(glm::dvec2 uv, double sinTheta, double* pdf) const {
  const glm::vec4& pixel = pixels_[pixelAt(uv)];
  if (distribution_.empty()) *pdf = 0.0;
  else if (height_ == 1) *pdf = 1.0 / (4.0 * kPi);
  else *pdf = solidAngleDensity(pixel.w, sinTheta);
  return glm::dvec3(pixel);
}

glm::dvec3 EnvironmentLight::sample(glm::dvec2 u, double* pdf, glm::dvec3* radiance) const {
  std::size_t pixel = 0;
  const glm::dvec2 point = samplePoint(sampleRow(u), u, &pixel);
  return sampleAt(point, pixel, pdf, radiance);
}

Distribution2D::RowSample EnvironmentLight::sampleRow(glm::dvec2 u) const {
  if (distribution_.empty() || height_ == 1) return {};
  const Distribution2D::RowSample row = distribution_.sampleRow(u.y);
  distribution_.prefetchColumn(row, u.x);
  return row;
}

glm::dvec2 EnvironmentLight::samplePoint(const Distribution2D::RowSample& row, glm::dvec2 u, std::size_t* pixel) const {
  *pixel = 0;
  if (distribution_.empty() || height_ == 1) return u;  // nothing to sample, or the sphere uniformly (sampleAt)
  return distribution_.sampleColumn(row, u.x, pixel);
}

glm::dvec3 EnvironmentLight::sampleAt(glm::dvec2 point, std::size_t pixel, double* pdf, glm::dvec3* radiance) const {
  if (distribution_.empty()) {  // a black environment: nothing to sample
    *pdf = 0.0;
    return {0, 1, 0};
  }
  if (height_ == 1) {
    // A single row (constant environment): sample the sphere uniformly instead of in (u, v), so
    // the density stays bounded at the poles.
    const glm::dvec2 u = point;
    const double z = 1.0 - 2.0 * u.y, r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const SinCos phi = sinCosSingle(2.0 * kPi * u.x);
    *pdf = 1.0 / (4.0 * kPi);
    const glm::dvec3 d(r * phi.cos, z, r * phi.sin);
    if (radiance) *radiance = this->radiance(d);
    return d;
  }
  double sinTheta = 0.0;
  const glm::dvec3 direction = equirectDirection(point.x, point.y, &sinTheta);
  return sampleMapped(direction, sinTheta, pixel, pdf, radiance);
}

glm::dvec3 EnvironmentLight::sampleMapped(const glm::dvec3& direction, double sinTheta, std::size_t pixel, double* pdf,
                                          glm::dvec3* radiance) const {
  const glm::vec4& texel = pixels_[pixel];
  *pdf = solidAngleDensity(texel.w, sinTheta);
  if (radiance) *radiance = glm::dvec3(texel);
  return direction;
}

double EnvironmentLight::pdf(const glm::dvec3& direction) const {
  double p = 0.0;
  radiance(direction, &p);
  return p;
}

Expected<void> LightSet::build(const scene::Scene& scene, const RayTracingScene& rayTracing, const EnvironmentLight* environment,
                               double sceneRadius, EmissionFunction emission) {
  punctual_.clear();
  directional_.clear();
  treeLight_.clear();
  triangles_.clear();
  environment_ = environment;
  emission_ = std::move(emission);
  const auto& pose = rayTracing.pose();
  for (std::size_t n = 0; n < scene.nodes.size() && n < pose.world.size(); ++n) {
    const int li = scene.nodes[n].light;
    if (li < 0 || !pose.visible[n]) continue;
    const auto& l = pose.lights[static_cast<std::size_t>(li)];  // colour and intensity as animated
    Punctual p;
    p.type = l.type;
    const RigidPose rigid = decomposeRigid(pose.world[n]);
    p.position = rigid.position;
    p.direction = glm::normalize(rigid.rotation * glm::dvec3(0, 0, -1));
    p.intensity = glm::dvec3(l.color) * static_cast<double>(l.intensity);
    p.range = l.range;
    if (l.type == scene::Light::Type::kSpot) {
      p.cosOuter = std::cos(static_cast<double>(l.outerConeAngle));
      p.cosInner = std::cos(static_cast<double>(l.innerConeAngle));
    }
    if (!(std::max({p.intensity.x, p.intensity.y, p.intensity.z}) > 0)) continue;
    punctual_.push_back(p);
  }

  // Directional lights light every point; point and spot lights go into the light tree, which
  // bounds their positions, power and range.
  std::vector<LightTree::Light> treeLights;
  for (std::size_t i = 0; i < punctual_.size(); ++i) {
    const Punctual& p = punctual_[i];
    if (p.type == scene::Light::Type::kDirectional) {
      directional_.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    treeLights.push_back(treeLightOf(p));
    treeLight_.push_back(static_cast<std::uint32_t>(i));
  }
  tree_.build(treeLights);

  std::vector<double> weights;
  const double disc = kPi * sceneRadius * sceneRadius;  // area a distant light's power crosses
  weights.push_back(environment_ ? environment_->meanLuminance() * kPi * disc : 0.0);
  std::vector<double> triangleWeights;
  if (emission_) {
    rayTracing.forEachPrimitive([&](const PrimitiveView& v) {
      const auto& node = scene.nodes[static_cast<std::size_t>(v.node)];
      const int material = scene.meshes[static_cast<std::size_t>(node.mesh)].primitives[static_cast<std::size_t>(v.primitive)].material;
      if (material < 0) return;
      const double weight = emissiveWeight(glm::dvec3(scene.materials[static_cast<std::size_t>(material)].emissiveFactor));
      if (weight <= 0) return;
      const auto& idx = *v.indices;
      for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const Triangle tri{(*v.positions)[idx[t]], (*v.positions)[idx[t + 1]], (*v.positions)[idx[t + 2]], v.node, v.primitive,
                           static_cast<unsigned>(t / 3)};
        const double area = 0.5 * glm::length(glm::cross(tri.p1 - tri.p0, tri.p2 - tri.p0));
        if (!(area > 0)) continue;
        triangles_.push_back(tri);
        triangleWeights.push_back(area * weight);
      }
    });
  }
  triangleChoice_ = Distribution1D(triangleWeights);
  weights.push_back(kPi * triangleChoice_.total());  // power of one side of a Lambertian emitter: π L A
  choice_ = Distribution1D(weights);
  if (choice_.empty()) {
    choice_ = Distribution1D();
    environmentChoice_ = emissiveChoice_ = 0.0;
    return {};
  }
  environmentChoice_ = choice_.probability(0);
  emissiveChoice_ = choice_.probability(1);
  return {};
}

void LightSet::selectPunctual(const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights,
                              std::vector<LightTree::Selected>& selected, const LightTree::Guide& guide,
                              std::span<const std::uint32_t> seen) const {
  if (maxLights > 0) {
    // Where the tree did not take every light in reach, it sampled among the lights not seen
    // (their factors), and the seen ones are summed.
    const bool everyLight = tree_.select(point, normal, u, maxLights, selected, guide);
    for (auto& s : selected) s.light = treeLight_[s.light];
    if (!everyLight)
      for (const std::uint32_t k : seen)
        if (reaches(treeLight_[k], point, normal)) selected.push_back({treeLight_[k], 1.0});
  } else {
    // Every light that can reach the point, each with probability 1, found without the tree:
    // a light whose range ends before the point, or that is behind the surface, gives nothing.
    selected.clear();
    for (const std::uint32_t l : treeLight_)
      if (reaches(l, point, normal)) selected.push_back({l, 1.0});
  }
  for (const std::uint32_t l : directional_) selected.push_back({l, 1.0});
}

LightTree::Light LightSet::treeLightOf(const Punctual& p) { return {p.position, std::max(luminance(p.intensity), 1e-30), p.range}; }

bool LightSet::reaches(std::uint32_t light, const glm::dvec3& point, const glm::dvec3& normal) const {
  const Punctual& p = punctual_[light];
  const glm::dvec3 toLight = p.position - point;
  if (glm::dot(toLight, normal) <= 0) return false;
  return !(p.range > 0 && std::isfinite(p.range) && glm::dot(toLight, toLight) >= p.range * p.range);
}

bool LightSet::anyLightReaches(const glm::dvec3& point, const glm::dvec3& normal, const Visibility& visible) const {
  LightSample s;
  for (std::size_t light = 0; light < punctual_.size(); ++light) {
    // samplePunctual gives no light beyond a range or outside a cone
    if (!samplePunctual(light, point, s) || !(luminance(s.radiance) > 0) || glm::dot(s.direction, normal) <= 0) continue;
    if (visible(s.direction, s.distance)) return true;
  }
  // Barycentric points of a triangle: the centroid, then halfway from it to each corner.
  static constexpr std::array<glm::dvec2, 4> kPoints{glm::dvec2(1.0 / 3, 1.0 / 3), glm::dvec2(1.0 / 6, 1.0 / 6), glm::dvec2(2.0 / 3, 1.0 / 6),
                                                      glm::dvec2(1.0 / 6, 2.0 / 3)};
  for (const Triangle& tri : triangles_) {
    const glm::dvec3 facing = glm::cross(tri.p1 - tri.p0, tri.p2 - tri.p0);
    for (const glm::dvec2 b : kPoints) {
      const glm::dvec3 toLight = (1.0 - b.x - b.y) * tri.p0 + b.x * tri.p1 + b.y * tri.p2 - point;
      const double distance = glm::length(toLight);
      if (!(distance > 0)) continue;
      const glm::dvec3 direction = toLight / distance;
      // Emissive surfaces emit from both faces (sample()'s |cos| at the light).
      if (glm::dot(direction, normal) <= 0 || glm::dot(facing, direction) == 0) continue;
      if (!(luminance(emission_(tri.node, tri.primitive, tri.index, b)) > 0)) continue;
      if (visible(direction, distance)) return true;
    }
  }
  if (environment_) {
    // A spherical Fibonacci set (golden-angle spiral, equal areas): directions i = 0..N-1 at
    // z = 1 - (2i + 1) / N, azimuth 2 pi i / phi^2.
    constexpr int kDirections = 256;
    const double goldenAngle = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < kDirections; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / kDirections, r = std::sqrt(std::max(0.0, 1.0 - z * z));
      const glm::dvec3 direction(r * std::cos(goldenAngle * i), r * std::sin(goldenAngle * i), z);
      if (glm::dot(direction, normal) <= 0 || !(luminance(environment_->radiance(direction)) > 0)) continue;
      if (visible(direction, std::numeric_limits<double>::infinity())) return true;
    }
  }
  return false;
}

void PairLights::build(const LightSet& now, const LightSet& before) {
  halves_ = {&now, &before};
  for (auto& v : sharedLight_) v.clear();
  for (auto& v : changed_) v.clear();
  // Each half's point and spot lights in one order of every parameter, then merged: equal
  // parameters are the same light in both frames (two coincident equal lights pair up one to one).
  auto key = [](const LightSet::Punctual& p) {
    return std::array<double, 13>{static_cast<double>(p.type), p.position.x,  p.position.y,  p.position.z, p.direction.x,
                                  p.direction.y,               p.direction.z, p.intensity.x, p.intensity.y, p.intensity.z,
                                  p.range,                     p.cosOuter,    p.cosInner};
  };
  std::array<std::vector<std::uint32_t>, 2> sorted;
  for (std::size_t h = 0; h < 2; ++h) {
    sorted[h] = halves_[h]->treeLight_;
    const auto& lights = halves_[h]->punctual_;
    std::stable_sort(sorted[h].begin(), sorted[h].end(), [&](std::uint32_t a, std::uint32_t b) { return key(lights[a]) < key(lights[b]); });
  }
  std::size_t i = 0, j = 0;
  while (i < sorted[0].size() || j < sorted[1].size()) {
    if (j == sorted[1].size()) {
      changed_[0].push_back(sorted[0][i++]);
    } else if (i == sorted[0].size()) {
      changed_[1].push_back(sorted[1][j++]);
    } else {
      const auto a = key(now.punctual_[sorted[0][i]]), b = key(before.punctual_[sorted[1][j]]);
      if (a < b) changed_[0].push_back(sorted[0][i++]);
      else if (b < a) changed_[1].push_back(sorted[1][j++]);
      else {
        sharedLight_[0].push_back(sorted[0][i++]);
        sharedLight_[1].push_back(sorted[1][j++]);
      }
    }
  }
  std::vector<LightTree::Light> treeLights;
  treeLights.reserve(sharedLight_[0].size());
  for (const std::uint32_t l : sharedLight_[0]) treeLights.push_back(LightSet::treeLightOf(now.punctual_[l]));
  shared_.build(treeLights);
}

void PairLights::select(int half, const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights,
                        std::vector<LightTree::Selected>& selected, int everyLightUpTo) const {
  const LightSet& lights = *halves_[static_cast<std::size_t>(half)];
  const auto& sharedLight = sharedLight_[static_cast<std::size_t>(half)];
  selected.clear();
  if (maxLights > 0 && !shared_.empty()) {
    LightGuide guide;
    guide.everyLightUpTo = everyLightUpTo;
    shared_.select(point, normal, u, maxLights, selected, guide);
    for (auto& s : selected) s.light = sharedLight[s.light];
  } else {
    for (const std::uint32_t l : sharedLight)
      if (lights.reaches(l, point, normal)) selected.push_back({l, 1.0});
  }
  for (const std::uint32_t l : changed_[static_cast<std::size_t>(half)])
    if (lights.reaches(l, point, normal)) selected.push_back({l, 1.0});
  for (const std::uint32_t l : lights.directional_) selected.push_back({l, 1.0});
}

bool LightSet::samplePunctual(std::size_t light, const glm::dvec3& point, LightSample& s) const {
  const Punctual& l = punctual_[light];
  s.delta = true;
  s.pdf = 1.0;
  if (l.type == scene::Light::Type::kDirectional) {
    s.direction = -l.direction;
    s.distance = std::numeric_limits<double>::infinity();
    s.radiance = l.intensity;
    return true;
  }
  const glm::dvec3 toLight = l.position - point;
  const double d2 = glm::dot(toLight, toLight);
  if (!(d2 > 0)) return false;
  s.distance = std::sqrt(d2);
  s.direction = toLight / s.distance;
  double attenuation = 1.0 / d2;
  if (l.range > 0) {  // KHR_lights_punctual's recommended window: max(min(1 - (d/range)^4, 1), 0) / d^2
    const double r = s.distance / l.range;
    attenuation *= std::clamp(1.0 - r * r * r * r, 0.0, 1.0);
  }
  if (l.type == scene::Light::Type::kSpot) {  // KHR_lights_punctual's spot falloff, a squared linear ramp
    const double cd = glm::dot(l.direction, -s.direction);
    const double scale = 1.0 / std::max(1e-3, l.cosInner - l.cosOuter);
    const double a = std::clamp((cd - l.cosOuter) * scale, 0.0, 1.0);
    attenuation *= a * a;
  }
  if (attenuation <= 0) return false;
  s.radiance = l.intensity * attenuation;
  return true;
}

void LightSet::startChoice(double uChoice, glm::dvec2 u, Choice& c) const {
  c.kind = Choice::Kind::kNone;
  c.probability = 0.0;
  if (choice_.empty()) return;
  c.u = u;
  if (choice_.sampleDiscrete(uChoice, &c.probability) == 0) {
    c.kind = Choice::Kind::kEnvironment;
    c.row = environment_->sampleRow(u);
  } else {
    c.kind = Choice::Kind::kTriangle;
    triangleChoice_.prefetch(u.x);
  }
}

void LightSet::finishChoice(Choice& c) const {
  c.mapped = false;
  if (c.kind == Choice::Kind::kEnvironment) {
    c.point = environment_->samplePoint(c.row, c.u, &c.index);
    environment_->prefetchPixel(c.index);
  } else if (c.kind == Choice::Kind::kTriangle) {
    // An emissive triangle by area x emissive luminance, then a uniform point on it.
    double remapped = 0.0, triangleProbability = 0.0;
    c.index = triangleChoice_.sampleDiscrete(c.u.x, &triangleProbability, &remapped);
    c.probability *= triangleProbability;
    c.point = {remapped, c.u.y};
    prefetchLine(&triangles_[c.index]);
  }
}

void LightSet::mapDirections(std::span<Choice* const> choices, EquirectBatch& scratch) const {
  if (!environment_ || !environment_->mapsImagePoints()) return;
  std::size_t lanes = 0;
  scratch.reserve(choices.size());
  for (const Choice* c : choices)
    if (c->kind == Choice::Kind::kEnvironment) scratch.setPoint(lanes++, c->point);
  if (lanes == 0) return;
  scratch.directions(lanes);
  std::size_t lane = 0;
  for (Choice* c : choices)
    if (c->kind == Choice::Kind::kEnvironment) {
      c->direction = scratch.direction(lane++, &c->sinTheta);
      c->mapped = true;
    }
}

bool LightSet::sample(const glm::dvec3& point, const Choice& c, LightSample& s) const {
  s.delta = false;
  if (c.kind == Choice::Kind::kNone) return false;
  if (c.kind == Choice::Kind::kEnvironment) {
    double pdf = 0.0;
    s.direction = c.mapped ? environment_->sampleMapped(c.direction, c.sinTheta, c.index, &pdf, &s.radiance)
                           : environment_->sampleAt(c.point, c.index, &pdf, &s.radiance);
    if (!(pdf > 0)) return false;
    s.distance = std::numeric_limits<double>::infinity();
    s.pdf = c.probability * pdf;
    return true;
  }
  const Triangle& tri = triangles_[c.index];
  const glm::dvec2 b = sampleTriangle(c.point);
  const glm::dvec3 p = (1.0 - b.x - b.y) * tri.p0 + b.x * tri.p1 + b.y * tri.p2;
  const glm::dvec3 toLight = p - point;
  const double d2 = glm::dot(toLight, toLight);
  if (!(d2 > 0)) return false;
  s.distance = std::sqrt(d2);
  s.direction = toLight / s.distance;
  const glm::dvec3 cross = glm::cross(tri.p1 - tri.p0, tri.p2 - tri.p0);
  const double area = 0.5 * glm::length(cross);
  const double cosLight = std::abs(glm::dot(cross / (2.0 * area), s.direction));
  if (cosLight <= 1e-12) return false;
  s.radiance = emission_(tri.node, tri.primitive, tri.index, b);
  s.pdf = c.probability * d2 / (area * cosLight);
  return true;
}

glm::dvec3 LightSet::environmentRadianceAt(glm::dvec2 uv, double sinTheta, double* pdf) const {
  *pdf = 0.0;
  if (!environment_) return glm::dvec3(0.0);
  double p = 0.0;
  const glm::dvec3 le = environment_->radianceAt(uv, sinTheta, &p);
  if (environmentChoice_ > 0) *pdf = environmentChoice_ * p;
  return le;
}

// Choice of the triangle ∝ area x weight, then uniform on it: the area cancels, leaving
// P(emissive) x weight / total x d^2 / cos.
double LightSet::pdfEmissive(double emissiveLuminance, double distance, double cosAtLight) const {
  if (emissiveChoice_ <= 0 || triangleChoice_.total() <= 0 || cosAtLight <= 1e-12) return 0.0;
  return emissiveChoice_ * emissiveLuminance / triangleChoice_.total() * distance * distance / cosAtLight;
}

}  // namespace dynbench::render
