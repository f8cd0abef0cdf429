#pragma once
// The light sources a frame is lit by, and how next event estimation picks one.
//
// Units: dynbench renders radiance in the dataset's photometric units. A KHR_lights_punctual point
// or spot light of intensity I (candela) and colour c gives a surface at distance d the
// illuminance I c cos(theta) / d^2 (times KHR's range window and spot cone falloff); a directional
// light gives E c cos(theta) (lux); the environment image holds radiance (cd/m2) times its
// intensity; an emissive surface emits emissiveFactor (times emissiveStrength and the emissive
// texture) as radiance. docs/feature-buffers.md repeats this.
#include <array>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "render/light_tree.h"
#include "render/raytracing_scene.h"
#include "render/sampling.h"
#include "scene/scene.h"

namespace dynbench::render {

class EquirectBatch;

// An equirectangular environment (core/math.h's mapping), importance-sampled by pixel luminance
// times the pixel's solid angle. Radiance is looked up at the nearest pixel, so the sampled
// density and the looked-up radiance are the same piecewise-constant function.
class EnvironmentLight {
 public:
  static Expected<EnvironmentLight> load(const scene::Environment& environment);
  // The same radiance from every direction (white furnace tests, `--env-constant`).
  static EnvironmentLight constant(const glm::dvec3& radiance);

  glm::dvec3 radiance(const glm::dvec3& direction) const;
  // Radiance and solid-angle density in one lookup (a path that escapes needs both).
  glm::dvec3 radiance(const glm::dvec3& direction, double* pdf) const;
  // The same at image point uv = equirectCoordinates(direction, &sinTheta), computed by the caller.
  glm::dvec3 radianceAt(glm::dvec2 uv, double sinTheta, double* pdf) const;
  // A direction towards the environment with its solid-angle density and, when asked, the
  // radiance from it (the sampled pixel's, without mapping the direction back).
  glm::dvec3 sample(glm::dvec2 u, double* pdf, glm::dvec3* radiance = nullptr) const;
  // sample() in steps, so the batched path tracer can prefetch between them: the image point and
  // pixel index for u (reads the sampling tables), then the direction, density and radiance there
  // (reads the pixel). The first step itself splits in two: the row (starting to load the column
  // table entry the point is read from), then the point.
  Distribution2D::RowSample sampleRow(glm::dvec2 u) const;
  glm::dvec2 samplePoint(const Distribution2D::RowSample& row, glm::dvec2 u, std::size_t* pixel) const;
  glm::dvec3 sampleAt(glm::dvec2 point, std::size_t pixel, double* pdf, glm::dvec3* radiance = nullptr) const;
  // Whether sampleAt's direction is the image point's (equirectDirection): then a caller that has
  // mapped the point itself (EquirectBatch, for many at once) finishes with sampleMapped. Not for
  // a constant environment, which samples the sphere uniformly instead.
  bool mapsImagePoints() const { return !distribution_.empty() && height_ > 1; }
  // sampleAt's density and radiance for a point already mapped to `direction` (unit) with
  // sin(theta) = sinTheta; returns the direction.
  glm::dvec3 sampleMapped(const glm::dvec3& direction, double sinTheta, std::size_t pixel, double* pdf, glm::dvec3* radiance = nullptr) const;
  double pdf(const glm::dvec3& direction) const;
  // Memory prefetches for the batched path tracer: the pixel radianceAt(uv) reads; the pixel a
  // sample picked.
  void prefetchPixel(glm::dvec2 uv) const;
  void prefetchPixel(std::size_t pixel) const { prefetchLine(&pixels_[pixel]); }
  // Mean radiance over the sphere (luminance), for choosing between lights.
  double meanLuminance() const { return meanLuminance_; }

 private:
  int width_ = 0, height_ = 0;
  // Per pixel: radiance (intensity applied) and, in w, the pixel's density over the image square
  // (Distribution2D's), so a lookup and its pdf touch one cache line.
  std::vector<glm::vec4> pixels_;
  Distribution2D distribution_;
  double meanLuminance_ = 0.0;

  std::size_t pixelAt(glm::dvec2 uv) const;
  // Solid-angle density at polar angle theta (sinTheta = sin(pi v)) of a pixel whose density
  // over the image square is `density`.
  static double solidAngleDensity(double density, double sinTheta);
};

struct LightSample {
  glm::dvec3 direction{0.0};  // unit, from the shaded point towards the light
  double distance = 0.0;      // to the light; infinity for the environment and directional lights
  glm::dvec3 radiance{0.0};   // arriving radiance, or for a delta light the irradiance it gives a surface facing it
  double pdf = 0.0;           // selection probability times the solid-angle density (delta: selection only)
  bool delta = false;         // punctual light: no other strategy can hit it, no MIS
};

// Emission of an emissive surface at a point of a triangle (the integrator evaluates the material).
using EmissionFunction = std::function<glm::dvec3(int node, int primitive, unsigned triangle, glm::dvec2 barycentric)>;

class LightSet {
 public:
  // Gathers the frame's lights: punctual lights at their nodes' world transforms (from the
  // ray-tracing scene's pose; hidden nodes are off), every visible emissive triangle, and the
  // environment. `sceneRadius` sizes the power estimate of environment light.
  [[nodiscard]] Expected<void> build(const scene::Scene& scene, const RayTracingScene& rayTracing, const EnvironmentLight* environment,
                                     double sceneRadius, EmissionFunction emission);

  // The punctual lights to evaluate at a shading point (a shadow ray each), with the probability
  // of each having been selected: every directional light (probability 1), and the point and spot
  // lights the light tree selects for the point (LightTree::select: at most maxLights of them,
  // unbiased, none ever skipped; where no more than maxLights can reach the point, all of them
  // with probability 1, so a scene lit by few lights renders without noise from them). u: one
  // uniform number. maxLights 0: every light that can reach the point, without the tree (exact and
  // slow: the independent estimator the tests compare the tree with).
  // `guide`: LightTree::select's (what the point's cell learned; every light in reach where at
  // most guide.everyLightUpTo can reach the point). `seen` (tree light indices;
  // LightVisibility::Cell::seen, with guide.factors zero on every node whose lights are all seen):
  // lights evaluated wherever they reach the point, with probability 1, beside the tree's
  // selection among the others (not where the tree took every light in reach: they are among them).
  void selectPunctual(const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights,
                      std::vector<LightTree::Selected>& selected, const LightTree::Guide& guide = {},
                      std::span<const std::uint32_t> seen = {}) const;
  // The light tree over the point and spot lights, and its light k's index among punctual lights
  // (LightVisibility learns on it).
  const LightTree& punctualTree() const { return tree_; }
  std::uint32_t treeLight(std::size_t k) const { return treeLight_[k]; }
  // Light `light` at `point`, into `sample` (every field, as sample() below; pdf 1); false where
  // it gives none.
  bool samplePunctual(std::size_t light, const glm::dvec3& point, LightSample& sample) const;
  // Whether any light of the frame lights a surface at `point` whose side facing the viewer has the
  // normal `normal`, with no Monte Carlo sampling: the limit of "a path from here found direct
  // light" as paths grow (`dynbench fidelity`'s share of pixels without direct light, which counted
  // paths and fell with their number: 10.0 % at 16 and 7.2 % at 64 on one OpenArena frame). A directional
  // or punctual light counts where it gives light there (range, spot cone) along an unoccluded
  // line; an emissive triangle where one of a fixed set of its points that emits is seen (its
  // centroid, then points towards its corners); the environment where one of 256 fixed directions
  // (a spherical Fibonacci set) above the surface sees radiance. `visible(direction, distance)`
  // traces the shadow ray (distance infinite for directional light and the environment).
  using Visibility = std::function<bool(const glm::dvec3& direction, double distance)>;
  bool anyLightReaches(const glm::dvec3& point, const glm::dvec3& normal, const Visibility& visible) const;
  std::size_t punctualCount() const { return punctual_.size(); }
  // Whether selectPunctual uses its random number (there are point or spot lights).
  bool hasPunctualTree() const { return !tree_.empty(); }

  bool empty() const { return choice_.empty(); }
  // The environment or an emissive triangle, picked by estimated power, then a point on it (next
  // event estimation; Monte Carlo, weighted against BSDF sampling by the integrator), in two
  // steps: what does not depend on the point (which light, which environment pixel or triangle;
  // reads the light tables and prefetches the pixel or triangle), then the sample from the point.
  struct Choice {
    enum class Kind { kNone, kEnvironment, kTriangle } kind = Kind::kNone;
    double probability = 0.0;  // of choosing the light (and for a triangle, that triangle)
    std::size_t index = 0;     // environment pixel or triangle
    glm::dvec2 point{0.0};     // environment image point, or the triangle's (remapped u.x, u.y)
    // Between startChoice and finishChoice: the random numbers, and the environment's row.
    glm::dvec2 u{0.0};
    Distribution2D::RowSample row;
    // An environment choice's direction and sin(theta), when mapDirections has mapped `point`.
    glm::dvec3 direction{0.0};
    double sinTheta = 0.0;
    bool mapped = false;
  };
  // Choosing takes two steps, for the batched path tracer: which light and (for the environment)
  // which row, from tables small enough to stay cached, starting to load the table entry the
  // second step reads; then the pixel or triangle, starting to load it. Each table is read once.
  // The choice is written in place: returned by value, GCC copied it with loads that waited on the
  // stores just made (perf: an eighth of the batch loop's own time on one such copy).
  void startChoice(double uChoice, glm::dvec2 u, Choice& choice) const;
  void finishChoice(Choice& choice) const;
  // Optionally, after finishChoice: the directions of a batch's environment choices (any others are
  // left as they are), mapped several per SIMD instruction in `scratch`. sample() maps a choice
  // this has not.
  void mapDirections(std::span<Choice* const> choices, EquirectBatch& scratch) const;
  // The sample from `point`, into `sample` (every field; written in place, as startChoice's
  // choice); false where there is none.
  bool sample(const glm::dvec3& point, const Choice& choice, LightSample& sample) const;
  // When a BSDF-sampled ray reaches the environment: its radiance and, in *pdf, this strategy's
  // density for MIS (choice x solid-angle density), in one lookup; uv = equirectCoordinates of
  // the ray's direction, with its sinTheta, which the caller has computed.
  glm::dvec3 environmentRadianceAt(glm::dvec2 uv, double sinTheta, double* pdf) const;
  void prefetchEnvironment(glm::dvec2 uv) const {
    if (environment_) environment_->prefetchPixel(uv);
  }
  // The same density when a BSDF-sampled ray reaches an emissive triangle (whose emissive factor
  // luminance is `emissiveLuminance`).
  double pdfEmissive(double emissiveLuminance, double distance, double cosAtLight) const;
  // Luminance of an emissive factor as used for the triangle choice.
  static double emissiveWeight(const glm::dvec3& emissiveFactor) { return luminance(emissiveFactor); }

 private:
  friend class PairLights;
  struct Punctual {
    scene::Light::Type type;
    glm::dvec3 position{0.0}, direction{0.0, 0.0, -1.0};  // direction the light shines along
    glm::dvec3 intensity{0.0};                            // colour x intensity
    double range = 0.0, cosOuter = -1.0, cosInner = 1.0;
  };
  struct Triangle {
    glm::dvec3 p0, p1, p2;
    int node, primitive;
    unsigned index;
  };
  // Whether point or spot light `light` can light `point` on a surface facing `normal`: in front
  // of the surface and inside its range.
  bool reaches(std::uint32_t light, const glm::dvec3& point, const glm::dvec3& normal) const;
  // A point or spot light as the light tree sees it (its position, luminous power and range).
  static LightTree::Light treeLightOf(const Punctual& p);
  std::vector<Punctual> punctual_;
  std::vector<std::uint32_t> directional_;  // evaluated everywhere
  std::vector<std::uint32_t> treeLight_;    // light k of the tree -> punctual light
  LightTree tree_;
  std::vector<Triangle> triangles_;
  Distribution1D triangleChoice_;
  const EnvironmentLight* environment_ = nullptr;
  EmissionFunction emission_;
  Distribution1D choice_;  // the environment (0) or the emissive triangles (1)
  double environmentChoice_ = 0.0, emissiveChoice_ = 0.0;
};

// The punctual lights of a radiance-change pair's two halves (PathTracer::renderChanges). A point
// or spot light identical in both frames goes into one light tree that both halves select from with
// the same random number, so where the shading point did not move they pick the same lights and the
// lights' share of D = Y_t - Y_{t-1} cancels exactly, as it does with every light evaluated (common
// random numbers). A light that moved, changed or is in one frame only is evaluated wherever it
// reaches, in its own frame's half. Each half stays unbiased (LightTree::select over the shared
// lights, the others exactly). Why not every light in reach, as before: a map lit by hundreds of
// lights without a range (OpenArena's fitted lights) then cost hundreds of shadow rays a vertex,
// two thirds of a reference frame's time on oa_dm1.
class PairLights {
 public:
  void build(const LightSet& now, const LightSet& before);
  // As LightSet::selectPunctual, for half 0 (`now`) or 1 (`before`): indices into that half's
  // lights. maxLights 0: every light in reach, shared or not.
  void select(int half, const glm::dvec3& point, const glm::dvec3& normal, double u, int maxLights,
              std::vector<LightTree::Selected>& selected, int everyLightUpTo = 0) const;

 private:
  std::array<const LightSet*, 2> halves_{nullptr, nullptr};
  LightTree shared_;
  std::array<std::vector<std::uint32_t>, 2> sharedLight_;  // shared tree light k -> each half's punctual light
  std::array<std::vector<std::uint32_t>, 2> changed_;      // each half's point and spot lights not shared
};

}  // namespace dynbench::render
