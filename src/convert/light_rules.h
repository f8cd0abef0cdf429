#pragma once
// How captured lights become KHR_lights_punctual lights (thesis §5.4), per engine model type.
// Defaults are documented in docs/dataset.md; `--light-rules FILE` (JSON) overrides them.
#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include "core/error.h"

namespace dynbench::convert {

struct LightRule {
  double intensityScale = 1.0;  // multiplies the light's intensity
  int extraFrames = 0;          // frames the light stays on after its last record
  int ringLights = 0;           // 0: one light; n: n lights around the position (6: +-X, +-Y, +-Z)
  double ringRadiusMetres = 0.5;
};

struct LightRules {
  // Candela of a captured colour whose largest channel is 1. Captured colours are linear RGB; the
  // light's glTF colour is the captured colour divided by its largest channel.
  double candelaPerUnit = 100.0;
  // Lights with a range (an engine's radius): illuminance, lux, of the engine's full light (a
  // captured colour of 1 at the light). Unset: calibrated against the dataset's sky from the map's
  // lighting (docs/dataset.md, "Lights").
  std::optional<double> luxPerUnit;
  std::map<std::string, LightRule> byModelType;  // "flash", "bouncer", "rocket", ...
  const LightRule& rule(const std::string& modelType) const;
};

// The thesis's rules: a flash is amplified (x4) and kept 3 frames longer; a bouncer becomes six
// lights around it; a rocket is kept as is.
LightRules defaultLightRules();

// Reads a rules file: {"candela_per_unit": 100, "types": {"flash": {"intensity_scale": 4,
// "extra_frames": 3}, "bouncer": {"ring_lights": 6, "ring_radius_m": 0.5}}}. Types it names replace
// the defaults for those types; errors name the JSON pointer.
Expected<LightRules> readLightRules(const std::filesystem::path& file);

}  // namespace dynbench::convert
