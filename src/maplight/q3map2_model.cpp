#include "maplight/q3map2_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <tbb/parallel_for.h>

namespace dynbench::maplight {

namespace {

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

}  // namespace

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

double inverseSquareEnvelope(double value) { return std::sqrt(value * kPointScale / kFalloffTolerance); }

double lightEnvelope(const MapLight& light) {
  if (light.kind == MapLightKind::kSun) return std::numeric_limits<double>::infinity();
  if (light.linear) return std::max(0.0, light.value * kPointScale * kLinearScale - kFalloffTolerance) / light.fade;
  return inverseSquareEnvelope(light.value);
}

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
  if (!light.linear) {
    if (light.range > 0) {  // the dataset's end: KHR_lights_punctual's window on the true distance
      const double x = d / light.range;
      add *= std::clamp(1.0 - x * x * x * x, 0.0, 1.0);
    } else if (dist >= lightEnvelope(light)) {
      return 0.0;  // q3map2's: nothing from the envelope on
    }
  }
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

Column candidateColumn(const glm::dvec3& position, const std::vector<Sample>& samples, const Occluders& occluders, double range) {
  Column c;
  MapLight light;
  light.position = position;
  light.value = 1.0;
  light.range = range;
  std::uint32_t lastBlocker = TriangleBvh::kNoBlocker;  // neighbouring texels' rays are often blocked alike
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    const glm::dvec3 normal = receivingNormal(s, position);
    const double add = lightContribution(light, s.position, normal) * directedShare(s, normal);
    // below 1/4 of a byte for the brightest entity lights q3map2 maps use (V ~ 1000): nothing
    if (add * 1000.0 < 0.25) continue;
    if (!occluders.visible(s.position, position, s.inhibit, lastBlocker)) continue;
    c.rows.push_back(static_cast<std::uint32_t>(i));
    c.values.push_back(static_cast<float>(add));
    c.norm2 += add * add;
  }
  return c;
}

}  // namespace dynbench::maplight
