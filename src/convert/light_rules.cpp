#include "convert/light_rules.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "core/files.h"

namespace dynbench::convert {

const LightRule& LightRules::rule(const std::string& modelType) const {
  static const LightRule plain;
  auto it = byModelType.find(modelType);
  return it == byModelType.end() ? plain : it->second;
}

LightRules defaultLightRules() {
  LightRules rules;
  rules.byModelType["flash"] = LightRule{4.0, 3, 0, 0.5};
  rules.byModelType["bouncer"] = LightRule{1.0, 0, 6, 0.5};
  rules.byModelType["rocket"] = LightRule{};
  return rules;
}

Expected<LightRules> readLightRules(const std::filesystem::path& file) {
  auto text = readWholeFile(file);
  if (!text) return std::unexpected(text.error());
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(*text);
  } catch (const nlohmann::json::parse_error& e) {
    return fail(ErrorCode::kParse, "{}: invalid JSON: {}", file.string(), e.what());
  }
  const std::string name = file.string();
  if (!j.is_object()) return fail(ErrorCode::kInvalidData, "{}: /: expected an object", name);
  LightRules rules = defaultLightRules();
  auto number = [&](const nlohmann::json& o, const char* key, const std::string& pointer, double fallback,
                    double minimum) -> Expected<double> {
    if (!o.contains(key)) return fallback;
    const auto& v = o[key];
    if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < minimum)
      return fail(ErrorCode::kInvalidData, "{}: {}/{}: expected a number >= {}, got {}", name, pointer, key, minimum, v.dump());
    return v.get<double>();
  };
  for (const auto& [key, value] : j.items())
    if (key != "candela_per_unit" && key != "lux_per_unit" && key != "types")
      return fail(ErrorCode::kInvalidData, "{}: /{}: unknown key; expected candela_per_unit, lux_per_unit or types", name, key);
  auto candela = number(j, "candela_per_unit", "", rules.candelaPerUnit, 0.0);
  if (!candela) return std::unexpected(candela.error());
  rules.candelaPerUnit = *candela;
  if (j.contains("lux_per_unit")) {
    auto lux = number(j, "lux_per_unit", "", 0.0, 0.0);
    if (!lux) return std::unexpected(lux.error());
    if (!(*lux > 0)) return fail(ErrorCode::kInvalidData, "{}: /lux_per_unit: expected a positive number", file.string());
    rules.luxPerUnit = *lux;
  }
  if (j.contains("types")) {
    if (!j["types"].is_object()) return fail(ErrorCode::kInvalidData, "{}: /types: expected an object", name);
    for (const auto& [type, r] : j["types"].items()) {
      const std::string pointer = "/types/" + type;
      if (!r.is_object()) return fail(ErrorCode::kInvalidData, "{}: {}: expected an object", name, pointer);
      for (const auto& [key, value] : r.items())
        if (key != "intensity_scale" && key != "extra_frames" && key != "ring_lights" && key != "ring_radius_m")
          return fail(ErrorCode::kInvalidData, "{}: {}/{}: unknown key; expected intensity_scale, extra_frames, ring_lights or ring_radius_m",
                      name, pointer, key);
      LightRule rule;
      auto scale = number(r, "intensity_scale", pointer, 1.0, 0.0);
      auto extra = number(r, "extra_frames", pointer, 0.0, 0.0);
      auto ring = number(r, "ring_lights", pointer, 0.0, 0.0);
      auto radius = number(r, "ring_radius_m", pointer, 0.5, 0.0);
      for (const auto* e : {&scale, &extra, &ring, &radius})
        if (!*e) return std::unexpected(e->error());
      if (*ring != 0 && *ring != 6) return fail(ErrorCode::kInvalidData, "{}: {}/ring_lights: expected 0 or 6", name, pointer);
      rule.intensityScale = *scale;
      rule.extraFrames = static_cast<int>(*extra);
      rule.ringLights = static_cast<int>(*ring);
      rule.ringRadiusMetres = *radius;
      rules.byModelType[type] = rule;
    }
  }
  return rules;
}

}  // namespace dynbench::convert
