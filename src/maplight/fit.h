#pragma once
// An id Tech 3 map's static lighting as q3map2 made it, recovered for a physically based renderer.
//
// q3map2 bakes the map's lights into lightmaps and, unless worldspawn sets _keepLights, deletes the
// light entities from the BSP (writebsp.c), so most shipped maps keep none. What is left: the
// lightmaps, which hold what the lights did, and the emitters the BSP still names (surface lights
// of its shaders, a sky shader's sun, the light entities of the maps that keep them). This module
//   1. reads the lightmap texels as samples (position, normal, linear value): lightmap_samples.h,
//   2. predicts the known emitters' light at them with q3map2's own model (light.c,
//      LightContributionToSample), with its own tracer for visibility: known_emitters.h,
//      q3map2_model.h, fit_visibility.h,
//   3. fits what is left with non-negative point lights: candidates on a lattice in open space and
//      along the normals of the residual's hot spots (fit_candidates.h), chosen greedily, weighted
//      by non-negative least squares, plus a constant term that absorbs bounced light and ambient
//      and is then dropped (the path tracer makes its own indirect light): light_solver.h,
//   4. judges the lights on held-out texels and on the map's light grid, which the fit never sees:
//      fit_judge.h.
// fit.cpp runs the steps in that order; the step headers are the maplight stage's own.
// The result is deterministic: the same map gives the same lights, byte for byte.
#include <array>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "maplight/bsp.h"
#include "maplight/pak.h"
#include "maplight/shaders.h"

namespace dynbench::maplight {

// q3map2's constants (q3map2.h): a point light of value V gives V pointScale cos / max(d, 16)^2
// lightmap units; a surface light of value V is a Lambertian emitter of radiance areaScale
// formFactorValueScale V / pi. The engine shows lightmap byte b as b x 4 (overbright bits), so
// 63.75 is the full light under which a surface shows its texture as it is.
inline constexpr double kPointScale = 7500.0;
inline constexpr double kLinearScale = 1.0 / 8000.0;
inline constexpr double kAreaScale = 0.25, kFormFactorValueScale = 3.0;
inline constexpr double kMinimumDistance = 16.0;  // q3map2 clamps a point light's distance to it
inline constexpr double kFullLight = 63.75;       // lightmap units of the engine's full light
inline constexpr double kDefaultLightSubdivide = 999.0;  // q3map2.h's defaultLightSubdivide, units
inline constexpr double kShownLightmapUnits = 1.0;  // a hidden light shows in the lightmaps where its model gives a texel this much
inline constexpr double kRecoveryRadius = 64.0;   // units: a hidden light counts as found with a fitted light this near
// q3map2's falloffTolerance (light.c, SetupEnvelopes): a light's envelope ends where it would add
// less than this many lightmap units; an inverse-square light's is sqrt(V pointScale / tolerance).
inline constexpr double kFalloffTolerance = 1.0;

enum class MapLightKind { kPoint, kSpot, kSun };

// A light in q3map2's terms (game axes, game units).
struct MapLight {
  MapLightKind kind = MapLightKind::kPoint;
  glm::dvec3 position{0.0};
  glm::dvec3 color{1.0};  // largest channel 1 (ColorNormalize); a sun's is unit length (VectorNormalize)
  double value = 0.0;     // the entity's light value V (photons / pointScale); a sun's intensity
  bool linear = false;    // spawnflags 1: V pointScale linearScale cos - d fade, not the inverse square
  double fade = 1.0;
  bool angleAttenuation = true;  // spawnflags 2 clears it
  glm::dvec3 spotAxis{0.0};      // a spot's unit axis (towards its target)
  double spotRadiusByDist = 0.0;  // (radius + 16) / distance to the target: the cone's radius per unit along the axis
  glm::dvec3 towardsSun{0.0};     // a sun's unit direction towards it
  // Where the light ends, as the dataset has it: KHR_lights_punctual's window
  // max(0, 1 - (d/range)^4) on the inverse square, range = lightEnvelope(*this). 0: q3map2's own
  // cut, nothing from the envelope on (known lights, as the lightmaps were baked). The window never
  // takes more than the tolerance from the hard cut's light (docs/dataset.md), and the fit models it
  // for the lights it fits, so that they reproduce the lightmaps as the dataset renders them.
  double range = 0.0;
  std::string source;             // "entity 12", "shader textures/sky/x", "fitted"
};

// q3map2's envelope of a point or spot light (SetupEnvelopes): sqrt(V pointScale / falloffTolerance)
// units for the inverse square, (V pointScale linearScale - falloffTolerance) / fade for a linear
// light; infinite for a sun.
double lightEnvelope(const MapLight& light);
// The envelope of the inverse-square light of value V, sqrt(V pointScale / falloffTolerance): the
// range the dataset ends every point light at, a linear one's too (it is written as the inverse
// square of its value: writeAdapterLights).
double inverseSquareEnvelope(double value);

// One of a surface light's area lights as q3map2 makes them (light_bounce.c,
// RadSubdivideDiffuseLight): a triangle of the surface, halved at the mid-plane of its bounds along
// the first axis they exceed the shader's q3map_lightSubdivide on (kDefaultLightSubdivide unless
// set), until none does.
struct SurfaceEmitter {
  std::vector<glm::dvec3> winding;  // a convex polygon
  glm::dvec3 normal{0.0};  // unit, the side it lights
  glm::dvec3 origin{0.0};  // its bounds' centre 1 unit in front: the one point q3map2 traces visibility to
  glm::dvec3 color{1.0};   // largest channel 1
  double value = 0.0;      // q3map_surfacelight
  bool twoSided = false;   // the shader's cull none: it lights both sides (LIGHT_TWOSIDED)
  // q3map2 puts a point light in front of a triangle that was not subdivided (none for the pieces)
  double backsplashFraction = 0.0, backsplashDistance = 0.0;
  int shader = -1;         // the BSP's shader index
  std::string shaderName;
};

// When the light grid (BSP lump 15) joins the lightmap texels as fit data, on the lattice's even
// points (the odd ones then judge the lights). Its directed light has no floor and each point says
// where its light mainly comes from, so it shows lights that a map's lightmap floor (_minlight)
// hides; where nothing is floored the lightmaps alone fit better.
enum class GridFit {
  kWhereFloored,  // where the floor hides most of the map's texels (oa_ctf2 of the stock maps)
  kNever,
  kAlways,
};

struct MapLightFitOptions {
  // Leave the map's light entities out of the known emitters: how the fit's recovery is measured on
  // the maps that keep them.
  bool hideEntityLights = false;
  int maxLights = 256;         // fitted point lights at most
  int fitSamples = 30000;      // lightmap texels fitted (a regular subset of them)
  int maxCandidates = 12000;   // lattice points in open space
  int hotSpotPeaks = 600;      // residual peaks that add candidates along their normals (0: the lattice alone)
  double minimumGain = 0.0001; // stop when a light lowers the residual by less than this share of the signal
  bool refine = true;          // move each fitted light off the lattice where that fits better
  // Judge the lights on the held-out texels (the report's held-out figures; about a fifth of the
  // fit's time). The lights do not depend on it: a capture's cached fit leaves it out.
  bool judgeOnHeldOut = true;
  int gridSamples = 8000;  // light grid points the lights are judged on at most (a regular subset)
  GridFit gridFit = GridFit::kWhereFloored;
  int gridFitSamples = 8000;  // grid points fitted at most
};

struct MapLightFitReport {
  std::size_t texels = 0, clippedTexels = 0;  // lit lightmap texels of drawn surfaces; those clipped, at 254 or 255 (left out)
  // Those at the map's floor (worldspawn _minlight: q3map2 raises every texel to it; fitted as they
  // read), and the floor in lightmap bytes per channel (0: none).
  std::size_t flooredTexels = 0;
  glm::dvec3 floorBytes{0.0};
  std::size_t fitSamples = 0, heldOutSamples = 0;
  std::size_t candidates = 0, latticeCandidates = 0, latticeSpacing = 0;  // all candidates; those on the lattice
  std::size_t entityLights = 0, surfaceEmitters = 0, suns = 0, fittedLights = 0;
  std::size_t refinedLights = 0;  // fitted lights moved off the lattice by the refinement
  double gamma = 1.0;  // the map's -gamma (from _q3map2_cmdline), undone
  glm::dvec3 constant{0.0};  // the fit's constant term, lightmap units (dropped)
  // Luminance correlation between the lightmap texels and q3map2's model of the static emitters
  // (known and fitted) on held-out texels; the same for the known emitters alone. This and the
  // explained shares below stay 0 without judgeOnHeldOut.
  double heldOutCorrelation = 0.0, knownCorrelation = 0.0;
  // The share of the texels' luminance variance explained (1 - residual / total), known emitters
  // alone as q3map2 gives them (no constant), and the dataset's lights with the constant, on held-out texels.
  double knownExplained = 0.0, totalExplained = 0.0;
  // The same correlation on the map's light grid (Bsp::lightGrid), an independent record of the
  // lights that the fit never sees: q3map2's light from every direction at points of open space,
  // against its model of the dataset's lights and of the known emitters alone there. 0 where the
  // map has no usable grid points (gridPoints: those judged).
  std::size_t gridPoints = 0, gridFitPoints = 0;  // grid points judged on; fitted
  bool gridFitted = false;                        // whether the grid was fit data (MapLightFitOptions::gridFit)
  double gridCorrelation = 0.0, gridKnownCorrelation = 0.0;
  std::size_t skyLightShaders = 0;  // shaders with q3map_skylight (not modelled)
  // With the entity lights hidden: their total value (suns left out), and the share of it whose
  // light has a fitted light within kRecoveryRadius.
  double hiddenLightValue = 0.0, recoveredShare = 0.0;
  // The same for the hidden lights the lightmaps show (q3map2's model of the light gives at least
  // kShownLightmapUnits on a fitted texel neither clipped nor at the floor): a light whose every
  // texel reads the floor or the clip leaves nothing to recover it from.
  double shownLightValue = 0.0, recoveredShownShare = 0.0;
  // Each known group's weight (a light entity, a sun, a surface-light shader): 1 where the
  // lightmaps agree with q3map2's model of it; the dataset's emitter is the model times it.
  std::vector<std::pair<std::string, double>> groupWeights;
};

struct MapLighting {
  std::string map;
  std::vector<MapLight> lights;             // kept entities, suns, fitted lights, in that order
  std::vector<SurfaceEmitter> surfaceLights;  // the surface lights' pieces
  MapLightFitReport report;
};

using MapLightProgress = std::function<void(const std::string& step, std::size_t done, std::size_t total)>;

// The map's lightmap floor in bytes per channel (worldspawn `_minlight` times `_color`, through
// q3map2's ColorToBytes with the map's -gamma); 0 where it sets none.
glm::dvec3 minimumLightBytes(const Bsp& bsp, double gamma);

Expected<MapLighting> fitMapLighting(const GameFiles& files, const std::string& map, const MapLightFitOptions& options = {},
                                     const MapLightProgress& progress = {});

// A light grid point's light from every direction (the sum of what each light gives it, q3map2's
// LightContributionToPoint), linear lightmap units per channel, from its directed and ambient bytes.
glm::dvec3 gridPointLight(const LightGridPoint& point, double gamma);

// q3map2's light at a point without visibility: lightmap units of luminance per unit colour
// (LightContributionToSample's `add`, before it is multiplied by the light's colour).
double lightContribution(const MapLight& light, const glm::dvec3& point, const glm::dvec3& normal);
// A surface emitter's light at a point (its exact point-to-polygon form factor times
// formFactorValueScale areaScale V), without visibility or its backsplash. A two-sided emitter
// (LIGHT_TWOSIDED) gives the form factor's magnitude wherever q3map2's signed one is negative, and
// `fromBack` (if given) then says so: q3map2 traces that light to its origin pushed 2 units behind.
double surfaceContribution(const SurfaceEmitter& emitter, const glm::dvec3& point, const glm::dvec3& normal, bool* fromBack = nullptr);
// A convex winding halved at the mid-plane of its bounds along the first axis on which they exceed
// `size`, until none does (q3map2's RadSubdivideDiffuseLight); `split` says whether it was halved.
std::vector<std::vector<glm::dvec3>> subdivideWinding(const std::vector<glm::dvec3>& winding, double size, bool* split = nullptr);
// The projected solid angle of a convex polygon seen from `point` with normal `normal`, over pi
// (Lambert's polygon formula; q3map2's PointToPolygonFormFactor): 1 for a polygon filling the
// hemisphere. Either winding gives the same value.
double formFactor(const std::vector<glm::dvec3>& polygon, const glm::dvec3& point, const glm::dvec3& normal);

// The map's light entities (classname light*) as q3map2 reads them (light.c, CreateEntityLights):
// spots aimed at their target, suns (_sun 1) made directional.
std::vector<MapLight> entityLights(const Bsp& bsp);

// The lights file the OpenArena capture adapter reads (DYNBENCH_CAPTURE_MAP_LIGHTS,
// integrations/openarena): game axes and units, light in the capture format's full-light units, one
// light per line (adapter_lights.cpp): "point X Y Z R G B D E" (an inverse-square light giving R G B at D units,
// ended by KHR's window at E units: MapLight::range), "sun DX
// DY DZ R G B" (towards the sun), "surface SHADER R G B" (the emission of a light-emitting shader's
// surfaces). Written to a temporary name and renamed.
Expected<void> writeAdapterLights(const std::filesystem::path& file, const MapLighting& lighting);

}  // namespace dynbench::maplight
