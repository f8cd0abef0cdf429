#include "convert/converter.h"

namespace dynbench::convert::detail {

namespace {
// Flux-matching factors k in I = E_u c R^2 k (docs/dataset.md, "Lights"). Within its range R the
// engine's light of colour c gives a surface facing it E_u c f(d/R) (E_u: lux of the engine's full
// light), with f(x) = 1 - x (linear) or 1 - x^2 (quadratic); its flux is the integral of that over
// spheres, 4 pi E_u c R^3 (1/3 - 1/4) = pi E_u c R^3 / 3 (linear) or 4 pi E_u c R^3 (1/3 - 1/5)
// = 8 pi E_u c R^3 / 15 (quadratic). A KHR_lights_punctual light of intensity I with range R
// gives I (1 - (d/R)^4) / d^2, flux 4 pi I (R - R/5) = 16 pi I R / 5. Equal fluxes:
// k = 5/48 (linear), 1/6 (quadratic).
double fluxFactor(LightFalloff falloff) { return falloff == LightFalloff::kQuadratic ? 1.0 / 6.0 : 5.0 / 48.0; }
}  // namespace

Expected<void> Converter::calibrateLighting() {
  const auto& lighting = reader_->settings().lighting;
  skyParameters_ = options_.sky;
  if (options_.sunFromCapture && lighting) {
    if (lighting->hasSun()) {
      const auto [elevation, azimuth] = sunAngles(lighting->sunDirection);
      skyParameters_.sunElevationDegrees = std::clamp(elevation, 0.0, 90.0);
      skyParameters_.sunAzimuthDegrees = azimuth;
    } else {
      skyParameters_.sunDisc = false;  // the engine lights this map without a sun
    }
  }
  if (!options_.environment) sky_ = preethamSky(skyParameters_);
  calibration_ = json::object();
  if (options_.lightRules.luxPerUnit) {
    luxPerUnit_ = *options_.lightRules.luxPerUnit;
    calibration_["source"] = "light rules (lux_per_unit)";
  } else if (sky_ && lighting && lighting->hasSun()) {
    // The map's sun and its lights are in the same units: the engine's sun of colour s gives a
    // surface facing it s, the sky's sun its direct normal illuminance.
    const double sun = std::max({lighting->sun.r, lighting->sun.g, lighting->sun.b});
    luxPerUnit_ = sky_->sunIlluminanceLux / sun;
    calibration_ = {{"source", "map sun"}, {"engine_sun", sun}, {"sky_sun_lux", sky_->sunIlluminanceLux}};
  } else {
    // No sun: the sky dome's illuminance on an open horizontal surface is the least light the
    // engine gives a surface open to the sky: its sky light, or its ambient floor (Cube 2's
    // lightmaps never go below `ambient`, and under the sky rise to `skylight`: lightmap.cpp), or,
    // without either, the engine's full light.
    double dome = 0.0;
    if (sky_) {
      dome = horizontalIlluminance(sky_->rgb, sky_->width, sky_->height, skyParameters_.sunDisc ? sky_->sunDirection : glm::dvec3(0.0),
                                   skyParameters_.sunDisc ? radians(2.0) : 0.0);
    } else {
      auto image = readImage(*options_.environment);
      if (!image || image->channels < 3)
        return fail(ErrorCode::kInvalidData, "--env {}: cannot read it as an RGB image", options_.environment->string());
      std::vector<float> rgb(static_cast<std::size_t>(image->width) * image->height * 3);
      for (std::size_t i = 0; i < rgb.size() / 3; ++i)
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = image->pixels[i * static_cast<std::size_t>(image->channels) + c];
      dome = horizontalIlluminance(rgb, image->width, image->height);
    }
    const double sky = lighting ? std::max({lighting->sky.r, lighting->sky.g, lighting->sky.b}) : 0.0;
    const double ambient = lighting ? std::max({lighting->ambient.r, lighting->ambient.g, lighting->ambient.b}) : 0.0;
    const double floor = std::max(sky, ambient);
    luxPerUnit_ = floor > 0 ? dome / floor : dome;
    calibration_ = {{"source", floor <= 0 ? "sky dome = full light" : sky >= ambient ? "map sky light" : "map ambient"},
                    {"engine_sky_light", floor > 0 ? floor : 1.0},
                    {"sky_dome_lux", dome}};
  }
  calibration_["lux_per_unit"] = luxPerUnit_;
  // An engine that records its lighting with neither a sky light nor an ambient floor says its sky
  // gives no light but its sun (id Tech 3 with dynbench's map lights: q3map2 lights a map from the
  // sky only through q3map_sun, q3map_skylight and sky surface lights, which the capture's lights
  // and sun carry). The dataset's sky then keeps only its sun disc, E_u as calibrated above: a
  // daylight dome would light a space map's platforms the game shows against a starfield.
  if (sky_ && lighting && std::max({lighting->sky.r, lighting->sky.g, lighting->sky.b}) <= 0 &&
      std::max({lighting->ambient.r, lighting->ambient.g, lighting->ambient.b}) <= 0) {
    skyParameters_.dome = false;
    sky_ = preethamSky(skyParameters_);
    calibration_["sky_dome"] = "none: the engine's sky gives no light but its sun (no sky light, no ambient)";
  }
  return {};
}

std::pair<glm::dvec3, double> Converter::lightColorIntensity(const glm::dvec3& capturedColor, double range, LightFalloff falloff,
                                                            const std::string& modelType, double share, double constantAt) const {
  // Engines have negative lights that darken (Cube 2 does); glTF lights only add light, and
  // KHR_lights_punctual colours are in [0, 1]: negative channels become 0.
  const glm::dvec3 captured = glm::max(capturedColor, glm::dvec3(0.0));
  const double peak = std::max({captured.r, captured.g, captured.b});
  const LightRule& rule = options_.lightRules.rule(modelType);
  const glm::dvec3 color = peak > 0 ? captured / peak : glm::dvec3(1.0);
  // An inverse-square light is a physical point light already: E_u c (R/d)^2 is I / d^2 with I = E_u c R^2
  // (windowed: KHR's point light with range R, the window the same on both sides).
  const bool inverseSquare = falloff == LightFalloff::kInverseSquare || falloff == LightFalloff::kWindowedInverseSquare;
  const double perUnit = constantAt > 0      ? luxPerUnit_ * constantAt * constantAt
                         : inverseSquare     ? luxPerUnit_ * range * range
                         : range > 0                              ? luxPerUnit_ * range * range * fluxFactor(falloff)
                                                                  : options_.lightRules.candelaPerUnit;
  return {color, perUnit * peak * rule.intensityScale * share};
}

bool Converter::hasConstantIrradiance(const LightRecord& l) {
  return !l.dynamic && l.type == LightType::kPoint && l.range <= 0 && l.falloff == LightFalloff::kNone;
}

double Converter::distanceToMapCentre(const glm::dvec3& position) const {
  const auto& settings = reader_->settings();
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
  if (int model = reader_->modelIndex(settings.mapName); !settings.mapName.empty() && model >= 0)
    for (const auto& mesh : reader_->models()[static_cast<std::size_t>(model)].meshes)
      for (const auto& p : mesh.positions) {
        lo = glm::min(lo, glm::dvec3(p) + settings.mapOffset);
        hi = glm::max(hi, glm::dvec3(p) + settings.mapOffset);
      }
  // Without map geometry: one capture unit, the irradiance the engine's light has there.
  return lo.x <= hi.x ? std::max(glm::length((lo + hi) * 0.5 - position), 1.0) : 1.0;
}

int Converter::lightDefinition(const LightRecord& l, double share) {
  const auto [color, intensity] = lightColorIntensity(l.color, l.range, l.falloff, l.modelType, share,
                                                      hasConstantIrradiance(l) ? distanceToMapCentre(l.position) : 0.0);
  json light = {{"type", l.type == LightType::kSpot ? "spot" : l.type == LightType::kDirectional ? "directional" : "point"},
                {"color", vec(color)},
                {"intensity", intensity},
                {"name", l.modelType}};
  if (l.range > 0 && l.type != LightType::kDirectional && l.falloff != LightFalloff::kInverseSquare) light["range"] = l.range;
  if (l.type == LightType::kSpot) light["spot"] = {{"outerConeAngle", 0.7853981633974483}};
  lights_.push_back(light);
  ++report_.lights;
  return static_cast<int>(lights_.size()) - 1;
}

// A light capturable: one light, or (ring rule) six around its node.
void Converter::lightNodes(Track& t, int node) {
  const LightRule& rule = options_.lightRules.rule(t.light.modelType);
  if (rule.ringLights == 6) {
    t.lightShare = 1.0 / 6;
    const int def = lightDefinition(t.light, t.lightShare);
    t.lightDefinition = def;
    const double r = rule.ringRadiusMetres / reader_->settings().metresPerUnit;
    for (const glm::dvec3 axis : {glm::dvec3(1, 0, 0), glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0),
                                  glm::dvec3(0, 0, 1), glm::dvec3(0, 0, -1)})
      addNode({{"name", fmt::format("light_{}_ring", t.id)}, {"translation", vec(axis * r)},
               {"extensions", {{"KHR_lights_punctual", {{"light", def}}}}}},
              node);
  } else {
    t.lightShare = 1.0;
    t.lightDefinition = lightDefinition(t.light, t.lightShare);
    doc_["nodes"][static_cast<std::size_t>(node)]["extensions"]["KHR_lights_punctual"] = {{"light", t.lightDefinition}};
  }
}
}  // namespace dynbench::convert::detail
