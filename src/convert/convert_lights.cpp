#include "convert/converter.h"

namespace dynbench::convert::detail {

std::pair<glm::dvec3, double> Converter::lightColorIntensity(const glm::dvec3& capturedColor, const std::string& modelType,
                                                            double share) const {
  // Engines have negative lights that darken (Cube 2 does); glTF lights only add light, and
  // KHR_lights_punctual colours are in [0, 1]: negative channels become 0.
  const glm::dvec3 captured = glm::max(capturedColor, glm::dvec3(0.0));
  const double peak = std::max({captured.r, captured.g, captured.b});
  const LightRule& rule = options_.lightRules.rule(modelType);
  const glm::dvec3 color = peak > 0 ? captured / peak : glm::dvec3(1.0);
  return {color, options_.lightRules.candelaPerUnit * peak * rule.intensityScale * share};
}

int Converter::lightDefinition(const LightRecord& l, double share) {
  const auto [color, intensity] = lightColorIntensity(l.color, l.modelType, share);
  json light = {{"type", l.type == LightType::kSpot ? "spot" : l.type == LightType::kDirectional ? "directional" : "point"},
                {"color", vec(color)},
                {"intensity", intensity},
                {"name", l.modelType}};
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
