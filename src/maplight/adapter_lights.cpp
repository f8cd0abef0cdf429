#include <set>
#include <sstream>

#include <fmt/format.h>

#include "core/files.h"
#include "maplight/fit.h"

namespace dynbench::maplight {

Expected<void> writeAdapterLights(const std::filesystem::path& file, const MapLighting& lighting) {
  // In the engine's full light (kFullLight lightmap units), as the capture format counts light.
  std::ostringstream out;
  out << "# dynbench map lights of " << lighting.map << " (src/maplight/fit.h): game axes and units, colours in full-light units\n";
  for (const MapLight& l : lighting.lights) {
    if (l.kind == MapLightKind::kSun) {
      const glm::dvec3 rgb = l.color * l.value / kFullLight;  // V cos lightmap units on a surface facing it
      out << fmt::format("sun {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g}\n", l.towardsSun.x, l.towardsSun.y, l.towardsSun.z, rgb.r, rgb.g, rgb.b);
    } else {
      // V pointScale / d^2 lightmap units is full light at d = sqrt(V pointScale / kFullLight). Spots
      // and linear lights are written as the inverse-square point light of the same value.
      // It ends at its range (MapLight::range), or, for a light the fit did not end, at the envelope
      // of that inverse-square light.
      const double fullLightDistance = std::sqrt(l.value * kPointScale / kFullLight);
      const double range = l.range > 0 ? l.range : inverseSquareEnvelope(l.value);
      out << fmt::format("point {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g} {:.6g}\n", l.position.x, l.position.y, l.position.z, l.color.r,
                         l.color.g, l.color.b, fullLightDistance, range);
    }
  }
  std::set<int> shaders;
  for (const SurfaceEmitter& e : lighting.surfaceLights)
    if (shaders.insert(e.shader).second) {
      // radiance formFactorValueScale areaScale V / pi lightmap units: a surface facing it closely
      // gets formFactorValueScale areaScale V, the emission (full-light units) it is given
      const glm::dvec3 emission = e.color * kFormFactorValueScale * kAreaScale * e.value / kFullLight;
      out << fmt::format("surface {} {:.6g} {:.6g} {:.6g}\n", e.shaderName, emission.r, emission.g, emission.b);
    }
  return writeFileAtomic(file, out.str());
}

}  // namespace dynbench::maplight
